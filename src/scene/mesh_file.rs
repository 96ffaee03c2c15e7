//! Triangle meshes for obstacles: Wavefront OBJ (`v` and `f` lines) and ASCII STL.

use crate::Real;
use nalgebra::Vector3;
use std::path::Path;

/// A triangle mesh read from a file: vertices (m) and 0-based triangles.
pub(crate) type Mesh = (Vec<Vector3<Real>>, Vec<[usize; 3]>);

/// Read an OBJ (`.obj`) or ASCII STL (`.stl`) file. Errors name the file and line and say what
/// to do.
pub(crate) fn read_mesh(path: &Path) -> Result<Mesh, String> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        format!(
            "{}: cannot read the mesh file: {e} (an OBJ or ASCII STL file, relative to the scene file)",
            path.display()
        )
    })?;
    let at = |line: usize, m: String| format!("{}:{line}: {m}", path.display());
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    let number = |line: usize, s: &str| -> Result<Real, String> {
        s.parse::<Real>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| at(line, format!("{s:?} is not a finite number")))
    };
    let mut vertices: Vec<Vector3<Real>> = Vec::new();
    let mut triangles = Vec::new();
    match extension.as_str() {
        "obj" => {
            for (i, raw) in text.lines().enumerate() {
                let line = i + 1;
                let mut words = raw.split('#').next().unwrap_or("").split_whitespace();
                match words.next() {
                    Some("v") => {
                        let c: Vec<&str> = words.collect();
                        if c.len() < 3 {
                            return Err(at(line, "a vertex needs x y z".to_string()));
                        }
                        vertices.push(Vector3::new(
                            number(line, c[0])?,
                            number(line, c[1])?,
                            number(line, c[2])?,
                        ));
                    }
                    Some("f") => {
                        let mut corners = Vec::new();
                        for w in words {
                            let index = w.split('/').next().unwrap_or("");
                            let k: i64 = index
                                .parse()
                                .map_err(|_| at(line, format!("{w:?} is not a vertex number")))?;
                            let k = if k < 0 {
                                vertices.len() as i64 + k
                            } else {
                                k - 1
                            };
                            if k < 0 || k as usize >= vertices.len() {
                                return Err(at(
                                    line,
                                    format!(
                                        "face names vertex {w}, but only {} are defined above it",
                                        vertices.len()
                                    ),
                                ));
                            }
                            corners.push(k as usize);
                        }
                        if corners.len() < 3 {
                            return Err(at(line, "a face needs 3 or more vertices".to_string()));
                        }
                        for j in 1..corners.len() - 1 {
                            triangles.push([corners[0], corners[j], corners[j + 1]]);
                        }
                    }
                    _ => {}
                }
            }
        }
        "stl" => {
            let mut corners = Vec::new();
            for (i, raw) in text.lines().enumerate() {
                let line = i + 1;
                let mut words = raw.split_whitespace();
                if words.next() == Some("vertex") {
                    let c: Vec<&str> = words.collect();
                    if c.len() < 3 {
                        return Err(at(line, "a vertex needs x y z".to_string()));
                    }
                    let p = Vector3::new(
                        number(line, c[0])?,
                        number(line, c[1])?,
                        number(line, c[2])?,
                    );
                    // Facets repeat their corners: merge equal points.
                    let k = match vertices.iter().position(|q| *q == p) {
                        Some(k) => k,
                        None => {
                            vertices.push(p);
                            vertices.len() - 1
                        }
                    };
                    corners.push(k);
                    if corners.len() == 3 {
                        triangles.push([corners[0], corners[1], corners[2]]);
                        corners.clear();
                    }
                }
            }
            if text.trim_start().starts_with("solid") && triangles.is_empty() {
                return Err(at(1, "no facets found".to_string()));
            }
        }
        _ => {
            return Err(format!(
                "{}: a mesh obstacle reads .obj or ASCII .stl files",
                path.display()
            ))
        }
    }
    if triangles.is_empty() {
        return Err(format!(
            "{}: the file has no triangles (OBJ `f` lines or STL facets)",
            path.display()
        ));
    }
    Ok((vertices, triangles))
}
