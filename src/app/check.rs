//! `sortsim check`: validates spec files, traces and calibration specs, one line each. Never
//! simulates.

use std::path::{Path, PathBuf};

use super::{Context, Failure};
use crate::spec::{check::check, SpecKind};

pub(super) fn run(ctx: &Context, files: &[PathBuf]) -> Result<(), Failure> {
    let mut first_error = None;
    for given in files {
        match check_file(ctx, &ctx.input(given)) {
            Ok(summary) => println!("OK   {}: {summary}", given.display()),
            Err(e) => {
                println!("FAIL {}", given.display());
                first_error.get_or_insert(e);
            }
        }
    }
    first_error.map_or(Ok(()), Err)
}

/// One file: a trace (by its magic bytes), a calibration spec, or any other spec.
fn check_file(ctx: &Context, file: &Path) -> Result<String, Failure> {
    let head = std::fs::File::open(file).and_then(|mut f| {
        let mut head = [0u8; 8];
        std::io::Read::read(&mut f, &mut head).map(|n| head[..n].to_vec())
    });
    if head.is_ok_and(|h| h == crate::trace::format::MAGIC) {
        let trace = crate::trace::read_trace(file).map_err(|e| Failure::BadInput(e.to_string()))?;
        let m = trace.meta();
        return Ok(format!(
            "trace of frame {} ({}x{}, {} primitives{}): {} fragments",
            m.frame,
            m.width,
            m.height,
            m.primitives,
            if m.culled { ", back faces culled" } else { "" },
            trace.len()
        ));
    }
    match SpecKind::detect(file)? {
        SpecKind::Calibration => crate::calibrate::check(file, &ctx.root.path)
            .map_err(|e| Failure::BadInput(e.to_string())),
        SpecKind::Paper => paper_rows(ctx, file),
        _ => Ok(check(file)?),
    }
}

/// A paper's rows: the tally by role, as `sortsim paper` counts them.
fn paper_rows(ctx: &Context, file: &Path) -> Result<String, Failure> {
    use crate::paper::data::{load_file, Role};
    let data =
        load_file(&ctx.root.path, file, None).map_err(|e| Failure::BadInput(e.to_string()))?;
    let roles: Vec<String> = Role::ALL
        .iter()
        .map(|&role| {
            let n = data.rows.iter().filter(|r| r.role == role).count();
            format!("{n} {}", role.label())
        })
        .collect();
    Ok(format!(
        "paper {} ({}): {} rows: {}",
        data.paper,
        data.title,
        data.rows.len(),
        roles.join(", ")
    ))
}
