//! The report of `sortsim validate`: network.json and raster.json (what was compared and how
//! far apart the answers are; byte-identical for identical inputs and tool versions),
//! cost.json (both programs' wall time per case) and validate.md (the tables, wall times
//! beside them), and the text the command prints.
//!
//! Must never run a comparison, and never put a wall time into network.json or raster.json.

use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use crate::output::plot::PlotError;
use crate::output::{to_json, write_text};
use crate::validate::{network, raster};

/// What one `sortsim validate` ran: either part may be absent.
#[derive(Default)]
pub struct Validation {
    pub network: Option<(network::NetworkValidation, Vec<network::CaseCost>)>,
    pub raster: Option<(raster::RasterValidation, Vec<raster::CaseCost>)>,
}

#[derive(Serialize)]
struct Costs<'a> {
    network: Option<&'a [network::CaseCost]>,
    raster: Option<&'a [raster::CaseCost]>,
}

pub fn write(dir: &Path, v: &Validation) -> Result<(), PlotError> {
    if let Some((n, _)) = &v.network {
        write_text(dir, "network.json", &to_json(n))?;
    }
    if let Some((r, _)) = &v.raster {
        write_text(dir, "raster.json", &to_json(r))?;
    }
    let costs = Costs {
        network: v.network.as_ref().map(|(_, c)| c.as_slice()),
        raster: v.raster.as_ref().map(|(_, c)| c.as_slice()),
    };
    write_text(dir, "cost.json", &to_json(&costs))?;
    write_text(dir, "validate.md", &markdown(v))
}

/// The tables and verdicts, as printed and as validate.md.
pub fn markdown(v: &Validation) -> String {
    let mut s = String::new();
    if let Some((n, costs)) = &v.network {
        network_table(&mut s, n, costs);
    }
    if let Some((r, costs)) = &v.raster {
        raster_table(&mut s, r, costs);
    }
    s
}

fn network_table(s: &mut String, n: &network::NetworkValidation, costs: &[network::CaseCost]) {
    let _ = writeln!(
        s,
        "## Network: sortsim `flow` against {}\n\nLinks of {}. Meshes and tori: routes given to SimGrid as sortsim computed them. \
         Fat-trees and dragonflies: SimGrid builds its own cluster zone and routes by its own rules; every ordered pair's route \
         is compared with sortsim's link for link (routes), and the times are measured on SimGrid's zone (on sortsim's routes \
         where SimGrid's rule gives some pair a route that is not a path). Difference: |SimGrid - sortsim| / sortsim over each \
         message's transfer time (completion - start).\n",
        n.model, n.link_bandwidth
    );
    let _ = writeln!(
        s,
        "| case | topology | messages | contended | routes equal | makespan (s) | largest difference | mean difference | sortsim wall (s) | SimGrid wall (s) |"
    );
    let _ = writeln!(
        s,
        "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
    );
    for (c, cost) in n.cases.iter().zip(costs) {
        let routes = match (c.routes_compared, c.simgrid_routes_not_paths) {
            (0, _) => "given".to_string(),
            (all, 0) => format!("{} of {all}", all - c.routes_differing),
            (all, bad) => format!(
                "{} of {} ({bad} of SimGrid's not a path)",
                all - bad - c.routes_differing,
                all - bad
            ),
        };
        let _ = writeln!(
            s,
            "| {} | {} {} | {} | {} | {} | {:.6} | {:.2e} | {:.2e} | {:.3} | {:.3} |",
            c.name,
            c.topology,
            c.shape,
            c.messages,
            c.contended,
            routes,
            c.makespan_s,
            c.max_rel_diff,
            c.mean_rel_diff,
            cost.sortsim_wall_s,
            cost.simgrid_wall_s
        );
    }
    let _ = writeln!(
        s,
        "\nLargest difference over all messages: {:.2e} (tolerance {:.0e}); routes of SimGrid's zones differing from sortsim's: {} (target 0): {}\n",
        n.max_rel_diff,
        n.tolerance,
        n.routes_differing,
        verdict(n.pass)
    );
}

fn raster_table(s: &mut String, r: &raster::RasterValidation, costs: &[raster::CaseCost]) {
    let _ = writeln!(
        s,
        "## Rasterizer: sortsim against {}\n\nThe same snapped triangles, one flat id each, 512x512, {}. \
         A depth tie: both triangles cover the pixel centre and their depths there differ by at most {} (sortsim's 32-bit units). \
         \"Other y convention\": pixels that would differ with GL's window y running up instead.\n",
        r.renderer, r.convention.describe(), r.depth_tie
    );
    let _ = writeln!(
        s,
        "| case | triangles | crossing the border | clipped by GL | pixels covered | coverage differences | depth ties | largest tie gap | other y convention | llvmpipe wall (s) |"
    );
    let _ = writeln!(
        s,
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
    );
    for (c, cost) in r.cases.iter().zip(costs) {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.3} |",
            c.name,
            c.triangles,
            c.crossing_border,
            c.gl_clipped,
            c.covered,
            c.coverage_differences,
            c.depth_ties,
            c.largest_tie_gap,
            c.other_convention_differences,
            cost.llvmpipe_wall_s
        );
    }
    let _ = writeln!(
        s,
        "\nCoverage differences over the cases GL draws unclipped: {} (target 0): {}\n",
        r.coverage_differences,
        verdict(r.pass)
    );
    for c in r.cases.iter().filter(|c| c.gl_clipped > 0) {
        let _ = writeln!(
            s,
            "{}: GL clips {} triangles, and its clipped polygons' float vertices move their \
             edges: {} pixels differ from sortsim, which draws them with their own snapped edges \
             and matches an exact referee there (tests/raster_far.rs).\n",
            c.name, c.gl_clipped, c.coverage_differences
        );
    }
}

fn verdict(pass: bool) -> &'static str {
    if pass {
        "agrees"
    } else {
        "DIFFERS"
    }
}
