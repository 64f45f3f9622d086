//! OBJ import (tobj): triangulates polygons (fan), keeps `v x y z r g b` vertex colours and
//! `vn` normals when present and tolerates their absence. Before tobj sees a file it is
//! scanned line by line, so a NaN or infinite coordinate, a face index out of range or a face
//! with fewer than three corners is reported with the file and line (tobj reports neither).
//!
//! Owns reading OBJ files into a `Mesh`. Must never place, light or project.

use std::path::Path;

use glam::Vec3;

use super::mesh::Mesh;
use super::SceneError;

/// Loads `path` as one mesh (all its objects and groups together, one part).
pub fn load(path: &Path) -> Result<Mesh, SceneError> {
    let text = crate::spec::read_input(path).map_err(|e| SceneError::ObjRead {
        file: path.to_path_buf(),
        message: e.to_string(),
    })?;
    parse(path, &text)
}

/// Reads OBJ `text` as one mesh; `path` names the file in errors.
pub fn parse(path: &Path, text: &str) -> Result<Mesh, SceneError> {
    scan(path, text)?;
    let options = tobj::LoadOptions {
        single_index: true,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let mut reader = std::io::BufReader::new(text.as_bytes());
    // Materials do not matter to sortsim: any mtllib is answered with an empty library.
    let (models, _) = tobj::load_obj_buf(&mut reader, &options, |_| Ok(Default::default()))
        .map_err(|e| SceneError::ObjRead {
            file: path.to_path_buf(),
            message: e.to_string(),
        })?;
    let mut mesh = Mesh::new();
    for model in models {
        mesh.append(convert(&model.mesh));
    }
    mesh.part.iter_mut().for_each(|p| *p = 0);
    if mesh.triangles.is_empty() {
        return Err(SceneError::Obj {
            file: path.to_path_buf(),
            line: 0,
            message: "no faces: an OBJ scene object needs at least one `f` line".into(),
        });
    }
    Ok(mesh)
}

fn convert(m: &tobj::Mesh) -> Mesh {
    let n = m.positions.len() / 3;
    let v3 = |a: &[f32], i: usize| Vec3::new(a[3 * i], a[3 * i + 1], a[3 * i + 2]);
    let mut mesh = Mesh::new();
    mesh.positions = (0..n).map(|i| v3(&m.positions, i)).collect();
    mesh.part = vec![0; n];
    if m.vertex_color.len() == m.positions.len() {
        mesh.colors = Some(
            (0..n)
                .map(|i| v3(&m.vertex_color, i).clamp(Vec3::ZERO, Vec3::ONE))
                .collect(),
        );
    }
    if m.normals.len() == m.positions.len() {
        mesh.normals = Some(
            (0..n)
                .map(|i| v3(&m.normals, i).normalize_or(Vec3::Y))
                .collect(),
        );
    }
    mesh.triangles = m
        .indices
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect();
    mesh
}

/// Checks what tobj would accept silently or report without a line number.
fn scan(path: &Path, text: &str) -> Result<(), SceneError> {
    let err = |line: usize, message: String| {
        Err(SceneError::Obj {
            file: path.to_path_buf(),
            line,
            message,
        })
    };
    let total = |kind: &str| {
        text.lines()
            .filter(|l| l.split_whitespace().next() == Some(kind))
            .count() as i64
    };
    let (vertex_total, texcoord_total, normal_total) = (total("v"), total("vt"), total("vn"));
    let mut vertices_so_far = 0i64;
    let (mut texcoords_so_far, mut normals_so_far) = (0i64, 0i64);
    for (k, raw) in text.lines().enumerate() {
        let line = k + 1;
        let mut words = raw.split('#').next().unwrap_or("").split_whitespace();
        match words.next() {
            Some("v") => {
                vertices_so_far += 1;
                let values: Vec<&str> = words.collect();
                if values.len() != 3 && values.len() != 4 && values.len() != 6 {
                    return err(
                        line,
                        format!(
                            "a vertex needs 3 coordinates (or x y z r g b), found {} values",
                            values.len()
                        ),
                    );
                }
                if let Err(m) = finite_values("vertex", &values) {
                    return err(line, m);
                }
            }
            Some(kind @ ("vt" | "vn")) => {
                let (name, counts) = if kind == "vt" {
                    texcoords_so_far += 1;
                    ("texture coordinate", 1..=3)
                } else {
                    normals_so_far += 1;
                    ("normal", 3..=3)
                };
                let values: Vec<&str> = words.collect();
                if !counts.contains(&values.len()) {
                    return err(
                        line,
                        format!(
                            "a {name} (`{kind}`) needs {counts:?} values, found {}",
                            values.len()
                        ),
                    );
                }
                if let Err(m) = finite_values(name, &values) {
                    return err(line, m);
                }
            }
            Some("f") => {
                let corners: Vec<&str> = words.collect();
                if corners.len() < 3 {
                    return err(
                        line,
                        format!("a face needs at least 3 corners, found {}", corners.len()),
                    );
                }
                for c in corners {
                    let first = c.split('/').next().unwrap_or("");
                    let Ok(i) = first.parse::<i64>() else {
                        return err(
                            line,
                            format!("face corner `{c}` does not start with a vertex index"),
                        );
                    };
                    if !index_exists(i, vertices_so_far, vertex_total) {
                        return err(line, format!("face index {i} is out of range: the file has {vertex_total} vertices (valid 1..={vertex_total}, or -1..=-{vertices_so_far} relative)"));
                    }
                    // v/vt/vn: the texture and normal indices, when given, must exist too.
                    let mut rest = c.split('/').skip(1);
                    for (what, total, so_far) in [
                        ("texture coordinate", texcoord_total, texcoords_so_far),
                        ("normal", normal_total, normals_so_far),
                    ] {
                        let Some(text) = rest.next().filter(|t| !t.is_empty()) else {
                            continue;
                        };
                        let Ok(j) = text.parse::<i64>() else {
                            return err(line, format!("face corner `{c}`: {what} index `{text}` is not a whole number"));
                        };
                        if !index_exists(j, so_far, total) {
                            return err(line, format!("face corner `{c}`: {what} index {j} is out of range: the file has {total} (valid 1..={total}, or -1..=-{so_far} relative)"));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// Every value a number and finite; the message names the kind of value ("vertex",
/// "normal", "texture coordinate").
fn finite_values(name: &str, values: &[&str]) -> Result<(), String> {
    for v in values {
        match v.parse::<f32>() {
            Ok(x) if x.is_finite() => {}
            Ok(_) => {
                return Err(format!(
                    "{name} value `{v}` is not finite (NaN or infinity)"
                ))
            }
            Err(_) => return Err(format!("{name} value `{v}` is not a number")),
        }
    }
    Ok(())
}

/// Whether OBJ index `i` names one of `total` elements: 1-based, or negative to count back
/// from the `so_far` read before the face.
fn index_exists(i: i64, so_far: i64, total: i64) -> bool {
    let resolved = if i < 0 { so_far + 1 + i } else { i };
    (1..=total).contains(&resolved)
}
