//! `sortsim paper` and `sortsim calibrate`: the papers' experiments with their rows, and the
//! fits of machines to them.

use super::cli::{CalibrateArgs, PaperArgs};
use super::{jobs, out_dir, writable_folder, Context, Failure};
use crate::output::cost::Stopwatch;

/// `sortsim paper`: runs each paper's experiments, writes its folder, prints its headline.
pub(super) fn paper(ctx: &Context, args: &PaperArgs) -> Result<(), Failure> {
    use crate::paper::{run_paper, PaperId, PaperOptions};
    use crate::report::paper::{write_overview, write_paper};
    let ids: Vec<PaperId> = match PaperId::from_id(&args.paper) {
        Some(id) => vec![id],
        None => PaperId::ALL.to_vec(),
    };
    writable_folder(&args.out)?;
    let options = PaperOptions {
        quick: args.quick,
        jobs: jobs(args.jobs),
        root: ctx.root.path.clone(),
        machines: None,
        scenes: None,
    };
    let mut reports = Vec::new();
    for id in ids {
        let clock = Stopwatch::start();
        let report = run_paper(id, &options).map_err(|e| match e {
            // A data file or machine the user edited into disagreement: bad input.
            crate::paper::PaperError::Data { .. } => Failure::BadInput(e.to_string()),
            _ => Failure::Internal(e.to_string()),
        })?;
        let dir = args.out.join(id.id());
        write_paper(&report, &dir)?;
        println!(
            "paper {}: {} ({:.1} s) -> {}",
            id.id(),
            report.headline(),
            clock.cost(0).wall_s,
            dir.join("index.html").display()
        );
        reports.push(report);
    }
    write_overview(&reports, &args.out)?;
    println!("overview: {}", args.out.join("index.html").display());
    Ok(())
}

/// `sortsim calibrate`: fits, writes the fitted machine or scene and the residual table,
/// prints it.
pub(super) fn calibrate(ctx: &Context, args: &CalibrateArgs) -> Result<(), Failure> {
    use crate::calibrate::{calibrate, load_spec, CalibrationError};
    let to_failure = |e: CalibrationError| match e {
        CalibrationError::Spec { .. } => Failure::BadInput(e.to_string()),
        CalibrationError::Failed(_) => Failure::Internal(e.to_string()),
    };
    let spec_file = ctx.input(&args.spec);
    let spec = load_spec(&spec_file).map_err(to_failure)?;
    let root = &ctx.root.path;
    let options = crate::calibrate::FitOptions {
        jobs: jobs(args.jobs),
        hold_out: args.hold_out.clone(),
        allow_predicted: args.allow_predicted,
    };
    crate::calibrate::validate(&spec, &spec_file, root, &options).map_err(to_failure)?;
    let out = out_dir(&args.out, &args.spec, "reports/calibrate-");
    writable_folder(&out)?;
    let result = calibrate(&spec, &spec_file, root, &options).map_err(to_failure)?;
    crate::report::calibration::write(&out, &result)?;
    print!("{}", crate::report::calibration::markdown(&result));
    println!(
        "\nfitted {}: {}; page: {}",
        result.subject,
        out.join(&result.file).display(),
        out.join("index.html").display()
    );
    Ok(())
}
