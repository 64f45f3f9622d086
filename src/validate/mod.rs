//! Checks against independent programs: the `flow` fidelity against SimGrid's max-min network
//! model (CM02), and the rasterizer against Mesa's llvmpipe through OpenGL. Backs
//! `sortsim validate`.
//!
//! Owns the validation cases, the comparisons and the running of the two small reference
//! scripts (`scripts/validate/*.py`, built into the binary, run by the system's Python 3 with
//! Debian's python3-simgrid and python3-moderngl). Must never compare anything but what the
//! simulator itself computes: it calls the same `run_pattern`, `setup_mesh` and
//! `draw_screen_triangles` every algorithm uses, and never adjusts either side's answer.

pub mod network;
mod python;
pub mod raster;

pub use python::ToolError;
