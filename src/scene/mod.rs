//! Scenes: geometry (generators, OBJ files), cameras, animation, lighting; one frame's
//! clip-space vertices at a time.
//!
//! Must never rasterize or know about simulated machines.
