//! Triangle meshes for obstacles: Wavefront OBJ (`v` and `f` lines), ASCII STL and binary STL.

use crate::Real;
use nalgebra::Vector3;
use std::collections::HashMap;
use std::path::Path;

/// A triangle mesh read from a file: vertices (m) and 0-based triangles.
pub(crate) type Mesh = (Vec<Vector3<Real>>, Vec<[usize; 3]>);

/// Size of a binary STL's header (80 bytes of free text, then the triangle count as a
/// little-endian `u32`), bytes.
const STL_HEADER: usize = 84;

/// Size of one binary STL triangle record: normal and three corners as 12 `f32`, then a `u16`
/// attribute, bytes.
const STL_RECORD: usize = 50;

/// Read an OBJ (`.obj`) or STL (`.stl`, ASCII or binary) file. Errors name the file and line
/// (or triangle) and say what to do.
pub(crate) fn read_mesh(path: &Path) -> Result<Mesh, String> {
    let bytes = std::fs::read(path).map_err(|e| {
        format!(
            "{}: cannot read the mesh file: {e} (an OBJ or STL file, relative to the scene file)",
            path.display()
        )
    })?;
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    if extension == "stl" {
        if let Some(count) = binary_stl_count(&bytes) {
            return read_binary_stl(path, &bytes, count);
        }
        // Not binary by its size: ASCII if it reads as text starting with `solid`.
        let ascii = std::str::from_utf8(&bytes)
            .ok()
            .filter(|t| t.trim_start().starts_with("solid"));
        let Some(text) = ascii else {
            return Err(binary_stl_size_error(path, &bytes));
        };
        return read_text_mesh(path, text, "stl").map_err(|e| {
            if bytes.len() >= STL_HEADER && !text.contains("facet") {
                // No facet at all: perhaps a cut-short binary file whose header says `solid`.
                format!(
                    "{e} (read as ASCII STL; {})",
                    binary_stl_size_error(path, &bytes)
                )
            } else {
                e
            }
        });
    }
    let text = std::str::from_utf8(&bytes).map_err(|e| {
        format!(
            "{}: the mesh file is not text: {e} (an OBJ file is text; a binary mesh must be an .stl file)",
            path.display()
        )
    })?;
    read_text_mesh(path, text, &extension)
}

/// The triangle count of a binary STL if `bytes` has exactly the size it announces
/// (84 + 50 n bytes). The size decides, not the first word: binary files often begin their
/// header with `solid` too.
fn binary_stl_count(bytes: &[u8]) -> Option<usize> {
    let count = u32::from_le_bytes(bytes.get(80..STL_HEADER)?.try_into().ok()?) as usize;
    let expected = count.checked_mul(STL_RECORD)?.checked_add(STL_HEADER)?;
    (expected == bytes.len()).then_some(count)
}

/// What is wrong with the size of a file read as a binary STL.
fn binary_stl_size_error(path: &Path, bytes: &[u8]) -> String {
    let file = path.display();
    let len = bytes.len();
    let Some(count) = bytes
        .get(80..STL_HEADER)
        .and_then(|b| b.try_into().ok())
        .map(|b| u32::from_le_bytes(b) as u64)
    else {
        return format!(
            "{file}: {len} bytes: neither an ASCII STL (text starting with `solid`) nor a binary STL (an 80-byte header and a 4-byte triangle count, then 50 bytes per triangle): the file is cut short or not an STL file"
        );
    };
    let expected = STL_HEADER as u64 + STL_RECORD as u64 * count;
    let len = len as u64;
    if len < expected {
        let whole = (len - STL_HEADER as u64) / STL_RECORD as u64;
        format!(
            "{file}: binary STL cut short: its header counts {count} triangles, which need 84 + 50 × {count} = {expected} bytes, but the file has {len} bytes: triangle {} (of {count}) is incomplete; write the file again or re-export it",
            whole + 1
        )
    } else {
        format!(
            "{file}: binary STL of the wrong size: its header counts {count} triangles, which need 84 + 50 × {count} = {expected} bytes, but the file has {len} bytes ({} too many): the count in bytes 81-84 does not match the triangles; re-export the file",
            len - expected
        )
    }
}

/// Read a binary STL of `count` triangles (its size checked): corners as `f32`, equal corners
/// merged. Normals and attributes are ignored (the corners' order gives the outward side).
fn read_binary_stl(path: &Path, bytes: &[u8], count: usize) -> Result<Mesh, String> {
    let mut vertices = Vec::new();
    let mut merged = HashMap::new();
    let mut triangles = Vec::with_capacity(count);
    for t in 0..count {
        let record = &bytes[STL_HEADER + t * STL_RECORD..STL_HEADER + (t + 1) * STL_RECORD];
        let value = |k: usize| {
            let b = [
                record[4 * k],
                record[4 * k + 1],
                record[4 * k + 2],
                record[4 * k + 3],
            ];
            Real::from(f32::from_le_bytes(b))
        };
        let mut corners = [0; 3];
        for (c, corner) in corners.iter_mut().enumerate() {
            // Floats 0-2 are the normal, then three per corner.
            let p = Vector3::new(value(3 + 3 * c), value(4 + 3 * c), value(5 + 3 * c));
            if !p.iter().all(|x| x.is_finite()) {
                return Err(format!(
                    "{}: binary STL triangle {} (of {count}), corner {}: coordinates {:?} are not finite numbers; re-export the file",
                    path.display(),
                    t + 1,
                    c + 1,
                    [p.x, p.y, p.z]
                ));
            }
            *corner = merge_vertex(&mut vertices, &mut merged, p);
        }
        triangles.push(corners);
    }
    if triangles.is_empty() {
        return Err(format!(
            "{}: the binary STL has no triangles (its header counts 0)",
            path.display()
        ));
    }
    Ok((vertices, triangles))
}

/// The index of `p` among `vertices`, added if new (STL facets repeat their corners; `-0.0` and
/// `0.0` are the same corner).
fn merge_vertex(
    vertices: &mut Vec<Vector3<Real>>,
    merged: &mut HashMap<[u64; 3], usize>,
    p: Vector3<Real>,
) -> usize {
    let key = [
        (p.x + 0.0).to_bits(),
        (p.y + 0.0).to_bits(),
        (p.z + 0.0).to_bits(),
    ];
    *merged.entry(key).or_insert_with(|| {
        vertices.push(p);
        vertices.len() - 1
    })
}

/// Read an OBJ or ASCII STL text (`extension` says which).
fn read_text_mesh(path: &Path, text: &str, extension: &str) -> Result<Mesh, String> {
    let at = |line: usize, m: String| format!("{}:{line}: {m}", path.display());
    let number = |line: usize, s: &str| -> Result<Real, String> {
        s.parse::<Real>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| at(line, format!("{s:?} is not a finite number")))
    };
    let mut vertices: Vec<Vector3<Real>> = Vec::new();
    let mut triangles = Vec::new();
    match extension {
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
            let mut merged = HashMap::new();
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
                    corners.push(merge_vertex(&mut vertices, &mut merged, p));
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
                "{}: a mesh obstacle reads .obj or .stl (ASCII or binary) files",
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A binary STL of `triangles` (corners in m) whose header begins with `solid`, as many
    /// exporters write it.
    fn binary_stl(triangles: &[[[f32; 3]; 3]]) -> Vec<u8> {
        let mut out = b"solid written by a test".to_vec();
        out.resize(80, b' ');
        out.extend((triangles.len() as u32).to_le_bytes());
        for t in triangles {
            out.extend([0u8; 12]);
            for c in t {
                for x in c {
                    out.extend(x.to_le_bytes());
                }
            }
            out.extend([0u8; 2]);
        }
        out
    }

    fn write(dir: &tempfile::TempDir, name: &str, bytes: &[u8]) -> std::path::PathBuf {
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        path
    }

    const TWO: [[[f32; 3]; 3]; 2] = [
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        [[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
    ];

    #[test]
    fn binary_stl_starting_with_solid_is_read_by_its_size() {
        let dir = tempfile::tempdir().unwrap();
        let path = write(&dir, "two.stl", &binary_stl(&TWO));
        let (vertices, triangles) = read_mesh(&path).unwrap();
        assert_eq!(vertices.len(), 4, "shared corners merged");
        assert_eq!(triangles, vec![[0, 1, 2], [1, 3, 2]]);
        assert_eq!(vertices[3], Vector3::new(1.0, 1.0, 0.0));
    }

    #[test]
    fn cut_short_binary_stl_names_the_triangle_and_sizes() {
        let dir = tempfile::tempdir().unwrap();
        let bytes = binary_stl(&TWO);
        // 84 + 50 + 20: the second triangle is cut.
        let path = write(&dir, "cut.stl", &bytes[..154]);
        let err = read_mesh(&path).unwrap_err();
        for part in [
            "cut.stl",
            "counts 2 triangles",
            "184 bytes",
            "has 154 bytes",
            "triangle 2",
        ] {
            assert!(err.contains(part), "{part:?} in {err}");
        }
        // Too long: the count does not match.
        let mut long = bytes.clone();
        long.extend([0u8; 7]);
        let err = read_mesh(&write(&dir, "long.stl", &long)).unwrap_err();
        assert!(err.contains("7 too many"), "{err}");
        // Shorter than a header.
        let err = read_mesh(&write(&dir, "tiny.stl", &[1, 2, 3])).unwrap_err();
        assert!(
            err.contains("3 bytes") && err.contains("not an STL"),
            "{err}"
        );
    }

    #[test]
    fn non_finite_binary_corner_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let mut t = TWO;
        t[1][2][0] = f32::NAN;
        let err = read_mesh(&write(&dir, "nan.stl", &binary_stl(&t))).unwrap_err();
        assert!(
            err.contains("triangle 2") && err.contains("corner 3"),
            "{err}"
        );
    }

    #[test]
    fn ascii_stl_is_still_read() {
        let dir = tempfile::tempdir().unwrap();
        let text = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
        let (vertices, triangles) = read_mesh(&write(&dir, "a.stl", text.as_bytes())).unwrap();
        assert_eq!((vertices.len(), triangles), (3, vec![[0, 1, 2]]));
    }
}
