//! Triangle meshes for obstacles: Wavefront OBJ (`v` and `f` lines), ASCII STL and binary STL.
//!
//! Our own reader rather than `tobj` and `stl_io`, on the merits: both crates are well kept but
//! report a malformed file without saying where (`tobj::LoadError` is a bare
//! `PositionParseError` or `FaceParseError`; `stl_io::read_stl` returns an `std::io::Error`),
//! accept non-finite coordinates, and `stl_io` pads or cuts facets whose vertex count is wrong.
//! A user with a 40 000-line export needs the line (or binary triangle) and what to change,
//! and an obstacle needs only positions and triangles, which take a few dozen lines per format.
//! Here every problem names the file and the line: a vertex with a wrong number of
//! coordinates, a token that is not a number, `nan` or `inf`, a coordinate beyond
//! [`MAX_COORDINATE`], a face naming vertex 0 or one not defined above it, an STL facet
//! without exactly three vertices or a line out of place, a zero-area triangle, a file with
//! no triangles; a binary STL names its triangle and, cut short, both sizes.

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
    if let Some((t, why)) = degenerate(&vertices, &triangles) {
        return Err(format!(
            "{}: binary STL triangle {} (of {count}): {why}: a zero-area face has no outward side; remove it or re-export the file",
            path.display(),
            t + 1
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
    let (vertices, triangles) = match extension {
        "obj" => read_obj(text, &at)?,
        "stl" => read_ascii_stl(text, &at)?,
        _ => {
            return Err(format!(
                "{}: a mesh obstacle reads .obj or .stl (ASCII or binary) files",
                path.display()
            ))
        }
    };
    if triangles.is_empty() {
        return Err(format!(
            "{}: the file has no triangles (OBJ `f` lines or STL facets): a mesh obstacle needs a closed surface",
            path.display()
        ));
    }
    let (triangles, lines): (Vec<_>, Vec<_>) = triangles.into_iter().unzip();
    if let Some((t, why)) = degenerate(&vertices, &triangles) {
        return Err(at(
            lines[t],
            format!("{why}: a zero-area face has no outward side; remove it or fix its corners"),
        ));
    }
    Ok((vertices, triangles))
}

/// Parse one coordinate: a finite number of metres within [`MAX_COORDINATE`].
fn coordinate(line: usize, s: &str, at: &dyn Fn(usize, String) -> String) -> Result<Real, String> {
    match s.parse::<Real>() {
        Ok(x) if x.is_finite() && x.abs() <= MAX_COORDINATE => Ok(x),
        Ok(x) if x.is_finite() => Err(at(
            line,
            format!(
                "the coordinate {s} is beyond ±{MAX_COORDINATE:e} m: contact would square it past what f64 holds; give the mesh in metres"
            ),
        )),
        Ok(_) => Err(at(
            line,
            format!("the coordinate {s:?} is not a finite number; re-export the file"),
        )),
        Err(_) => Err(at(line, format!("{s:?} is not a number"))),
    }
}

/// The largest coordinate a mesh vertex may have, m: squares and cross products of such
/// coordinates stay far inside f64 (the same bound as every other length of a scene).
pub(crate) const MAX_COORDINATE: Real = crate::scene::bounds::MAX_LENGTH;

/// Triangles with the line each comes from.
type Lined = Vec<([usize; 3], usize)>;

/// OBJ `v` (x y z, or x y z r g b with vertex colours, which are ignored) and `f` lines (1-based
/// or negative vertex numbers, `v/vt/vn` forms; polygons fanned into triangles). Other lines
/// (`vn`, `vt`, `o`, `g`, `usemtl`, ...) carry nothing a rigid obstacle needs.
fn read_obj(
    text: &str,
    at: &dyn Fn(usize, String) -> String,
) -> Result<(Vec<Vector3<Real>>, Lined), String> {
    let mut vertices: Vec<Vector3<Real>> = Vec::new();
    let mut triangles = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let mut words = raw.split('#').next().unwrap_or("").split_whitespace();
        match words.next() {
            Some("v") => {
                let c: Vec<&str> = words.collect();
                if c.len() != 3 && c.len() != 6 {
                    return Err(at(
                        line,
                        format!(
                            "a vertex has {} numbers: give x y z (or x y z r g b with colours); a weight w is not read",
                            c.len()
                        ),
                    ));
                }
                let mut p = Vector3::zeros();
                for (k, w) in c.iter().enumerate() {
                    let x = coordinate(line, w, at)?;
                    if k < 3 {
                        p[k] = x;
                    }
                }
                vertices.push(p);
            }
            Some("f") => {
                let mut corners = Vec::new();
                for w in words {
                    let index = w.split('/').next().unwrap_or("");
                    let k: i64 = index
                        .parse()
                        .map_err(|_| at(line, format!("{w:?} is not a vertex number")))?;
                    if k == 0 {
                        return Err(at(
                            line,
                            "face names vertex 0: OBJ vertex numbers start at 1 (or count back from -1)".to_string(),
                        ));
                    }
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
                    return Err(at(
                        line,
                        format!("a face has {} vertices: it needs 3 or more", corners.len()),
                    ));
                }
                for j in 1..corners.len() - 1 {
                    triangles.push(([corners[0], corners[j], corners[j + 1]], line));
                }
            }
            _ => {}
        }
    }
    Ok((vertices, triangles))
}

/// ASCII STL: `solid`, then per facet `facet normal nx ny nz`, `outer loop`, three
/// `vertex x y z`, `endloop`, `endfacet`; `endsolid`. A facet with another number of corners,
/// a line out of place or a token too many is an error naming its line.
fn read_ascii_stl(
    text: &str,
    at: &dyn Fn(usize, String) -> String,
) -> Result<(Vec<Vector3<Real>>, Lined), String> {
    let mut vertices = Vec::new();
    let mut merged = HashMap::new();
    let mut triangles = Vec::new();
    // The open facet: its first line and its corners so far.
    let mut facet: Option<(usize, Vec<usize>)> = None;
    let mut in_loop = false;
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let words: Vec<&str> = raw.split_whitespace().collect();
        let Some(&keyword) = words.first() else {
            continue;
        };
        let expect = |n: usize, form: &str| {
            if words.len() == n {
                Ok(())
            } else {
                Err(at(
                    line,
                    format!(
                        "`{}` has {} words: write it as `{form}`",
                        raw.trim(),
                        words.len()
                    ),
                ))
            }
        };
        match (keyword, facet.is_some(), in_loop) {
            ("solid", false, _) | ("endsolid", false, _) => {}
            ("facet", false, _) => {
                expect(5, "facet normal nx ny nz")?;
                if words[1] != "normal" {
                    return Err(at(line, "write `facet normal nx ny nz`".to_string()));
                }
                // The normal is ignored (the corners' order gives the side) but must be numbers.
                for w in &words[2..] {
                    w.parse::<Real>()
                        .map_err(|_| at(line, format!("the normal's {w:?} is not a number")))?;
                }
                facet = Some((line, Vec::new()));
            }
            ("outer", true, false) => {
                expect(2, "outer loop")?;
                in_loop = true;
            }
            ("vertex", true, true) => {
                expect(4, "vertex x y z")?;
                let p = Vector3::new(
                    coordinate(line, words[1], at)?,
                    coordinate(line, words[2], at)?,
                    coordinate(line, words[3], at)?,
                );
                let corner = merge_vertex(&mut vertices, &mut merged, p);
                if let Some((_, corners)) = facet.as_mut() {
                    corners.push(corner);
                }
            }
            ("endloop", true, true) => {
                expect(1, "endloop")?;
                in_loop = false;
            }
            ("endfacet", true, false) => {
                expect(1, "endfacet")?;
                if let Some((first, corners)) = facet.take() {
                    if corners.len() != 3 {
                        return Err(at(
                            first,
                            format!(
                                "the facet has {} vertices (lines {first}-{line}): an STL facet is a triangle of exactly 3",
                                corners.len()
                            ),
                        ));
                    }
                    triangles.push(([corners[0], corners[1], corners[2]], first));
                }
            }
            (other, open, looping) => {
                let wanted = match (open, looping) {
                    (false, _) => "`facet normal ...` or `endsolid`",
                    (true, false) => "`outer loop` or `endfacet`",
                    (true, true) => "`vertex x y z` or `endloop`",
                };
                return Err(at(
                    line,
                    format!("`{other}` is out of place in an ASCII STL: expected {wanted}"),
                ));
            }
        }
    }
    if let Some((first, _)) = facet {
        return Err(at(
            first,
            "the facet starting here is not closed by `endfacet`: the file is cut short"
                .to_string(),
        ));
    }
    Ok((vertices, triangles))
}

/// The first triangle (0-based) that has no area, and why: a repeated corner, or corners on
/// one line (within 1e-12 of its longest edge squared).
pub(crate) fn degenerate(
    vertices: &[Vector3<Real>],
    triangles: &[[usize; 3]],
) -> Option<(usize, String)> {
    triangles.iter().enumerate().find_map(|(t, c)| {
        if c[0] == c[1] || c[1] == c[2] || c[0] == c[2] {
            return Some((
                t,
                format!(
                    "face {} repeats a corner (vertices {}, {}, {})",
                    t + 1,
                    c[0] + 1,
                    c[1] + 1,
                    c[2] + 1
                ),
            ));
        }
        let [a, b, d] = c.map(|i| vertices[i]);
        let longest = [
            (b - a).norm_squared(),
            (d - b).norm_squared(),
            (a - d).norm_squared(),
        ]
        .into_iter()
        .fold(0.0, Real::max);
        ((b - a).cross(&(d - a)).norm() <= 1e-12 * longest).then(|| {
            (
                t,
                format!(
                    "face {} has zero area (its corners {}, {}, {} lie on one line)",
                    t + 1,
                    c[0] + 1,
                    c[1] + 1,
                    c[2] + 1
                ),
            )
        })
    })
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
