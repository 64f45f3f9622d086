//! `sortsim render` and `sortsim scene-stats`: a scene drawn by the sequential reference, and
//! its statistics.

use super::cli::{RenderArgs, SceneStatsArgs};
use super::{write_bytes, Context, Failure};
use crate::algo::reference;
use crate::output::to_json;
use crate::raster::encode_png;
use crate::scene::Scene;
use crate::spec::run::parse_frames;

pub(super) fn render(ctx: &Context, args: &RenderArgs) -> Result<(), Failure> {
    let scene = Scene::load(&ctx.input(&args.scene))?;
    let geometry = scene.frame(args.frame)?;
    let (image, counters) = reference::render_aa(&geometry, args.aa);
    let png = png_bytes(&image)?;
    let out = &args.out;
    write_bytes(out, &png)?;
    println!(
        "{}",
        to_json(&crate::scene::summary::counters_json(&counters)).trim_end()
    );
    println!(
        "wrote {} ({}x{})",
        out.display(),
        geometry.width,
        geometry.height
    );
    Ok(())
}

pub(super) fn stats(ctx: &Context, args: &SceneStatsArgs) -> Result<(), Failure> {
    use crate::scene::stats::raster_overlap_factor;
    let (path, frames, regions, json) =
        (&args.scene, args.frames.as_deref(), args.regions, args.json);
    let scene = Scene::load(&ctx.input(path))?;
    let frames = parse_frames(Some(frames.unwrap_or("0")), scene.frame_count())
        .map_err(|e| Failure::BadInput(format!("{}: --frames: {e}", path.display())))?;
    for frame in frames {
        let s = crate::scene::summary::summary(&scene, frame)?;
        let (rw, rh) = regions.unwrap_or((s.width.div_ceil(16), s.height.div_ceil(16)));
        let overlap = match regions {
            None => s.overlap_256,
            Some(_) => raster_overlap_factor(&scene.frame(frame)?, rw, rh),
        };
        if !json {
            print!("{s}");
            if regions.is_some() {
                println!("overlap factor for {rw}x{rh} regions: {overlap:.3}");
            }
            continue;
        }
        let value = s.to_json(overlap, (rw, rh));
        println!("{}", serde_json::to_string(&value).expect("JSON"));
    }
    Ok(())
}

fn png_bytes(image: &crate::raster::Framebuffer) -> Result<Vec<u8>, Failure> {
    let mut bytes = Vec::new();
    encode_png(image, &mut bytes).map_err(|e| Failure::Internal(e.to_string()))?;
    Ok(bytes)
}
