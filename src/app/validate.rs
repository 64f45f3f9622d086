//! `sortsim validate`: sortsim against SimGrid and llvmpipe, case by case.

use super::cli::ValidateArgs;
use super::{writable_folder, Failure};

pub(super) fn run(args: &ValidateArgs) -> Result<(), Failure> {
    use crate::report::validate::{markdown, write, Validation};
    use crate::validate::{network, raster, ToolError};
    let to_failure = |e: ToolError| {
        if e.is_missing_tool() {
            Failure::BadInput(e.to_string())
        } else {
            Failure::Internal(e.to_string())
        }
    };
    writable_folder(&args.out)?;
    let work = tempfile::tempdir()
        .map_err(|e| Failure::Internal(format!("cannot make a temporary folder: {e}")))?;
    let mut result = Validation::default();
    if args.what != "raster" {
        let cases = network::cases(args.quick);
        result.network = Some(network::validate(&cases, work.path()).map_err(to_failure)?);
    }
    if args.what != "network" {
        let cases = raster::cases(args.quick);
        result.raster = Some(raster::validate(&cases, work.path()).map_err(to_failure)?);
    }
    write(&args.out, &result)?;
    print!("{}", markdown(&result));
    print!("{}", crate::output::closing_line(&args.out, ""));
    let agrees = result.network.as_ref().is_none_or(|(n, _)| n.pass)
        && result.raster.as_ref().is_none_or(|(r, _)| r.pass);
    if agrees {
        Ok(())
    } else {
        Err(Failure::Internal(
            "sortsim and a reference program disagree beyond the stated tolerance (see the report)"
                .into(),
        ))
    }
}
