//! Paper 003's worst case for distributed snooping (Section 7.1): `n` planes sorted back to
//! front, one per processor, so that every processor's pixels are frontmost when it
//! broadcasts and the bus carries n times the screen. Big triangles covering a 64x48
//! screen; plane k (primitive k, processor k under a round-robin deal) is nearer the eye
//! than plane k - 1.
//!
//! Owns the scene's spec text only. Must never simulate or count anything.

/// The screen the planes cover, in pixels.
pub const PLANES_SCREEN: (u32, u32) = (64, 48);

/// The scene spec (JSON) of `n` back-to-front planes.
pub fn back_to_front_planes(n: u32) -> String {
    let planes: Vec<String> = (0..n)
        .map(|k| {
            format!(
                r#"{{ "generator": {{ "kind": "big-triangle" }}, "color": [{c}, 0.5, 0.5],
                     "transform": {{ "scale": [10, 1, 10], "translate": [0, {y}, 0] }} }}"#,
                c = k as f32 / n as f32,
                y = 0.1 * k as f32
            )
        })
        .collect();
    format!(
        r#"{{ "resolution": [{w}, {h}], "cull_backfaces": false,
             "camera": {{ "kind": "perspective", "eye": [0, 5, 0], "target": [0, 0, 0],
                         "up": [0, 0, -1], "fov_deg": 40, "near": 0.1, "far": 100 }},
             "geometry": [{planes}] }}"#,
        w = PLANES_SCREEN.0,
        h = PLANES_SCREEN.1,
        planes = planes.join(",")
    )
}
