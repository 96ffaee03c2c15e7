//! Bodies prepared from a mesh file (OBJ or STL, closed) or an outline (a file of loops or the
//! points in the scene): reading, turning the mesh outward, preparing, and writing the
//! paper's files of the result.

use crate::contact::orient_outward;
use crate::linkage::prepare::{prepare_mesh_until, prepare_outline_until, PreparedBody};
use crate::linkage::{Dimension, Interrupt};
use crate::scene::mesh_file::read_mesh;
use crate::scene::paper_files::{write_links, write_nodes, write_patches};
use crate::Real;
use std::path::{Path, PathBuf};

/// Read an outline file: one `x y` (m) per line, a blank line between loops, `#` starts a
/// comment; the first loop is the outside, the others holes. Errors name the file and line.
pub fn read_outline(path: &Path) -> Result<Vec<Vec<[Real; 2]>>, String> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        format!(
            "{}: cannot read the outline file: {e} (text, one \"x y\" per line)",
            path.display()
        )
    })?;
    let mut loops: Vec<Vec<[Real; 2]>> = vec![Vec::new()];
    for (n, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            if raw.trim().is_empty() && loops.last().is_some_and(|l| !l.is_empty()) {
                loops.push(Vec::new());
            }
            continue;
        }
        let fail = |m: &str| format!("{}:{}: {m}: {raw:?}", path.display(), n + 1);
        let words: Vec<&str> = line.split_whitespace().collect();
        if words.len() != 2 {
            return Err(fail("give two numbers, \"x y\" in metres"));
        }
        let mut p = [0.0; 2];
        for (k, w) in words.iter().enumerate() {
            p[k] = w
                .parse::<Real>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| fail(&format!("{w:?} is not a finite number")))?;
        }
        if let Some(current) = loops.last_mut() {
            current.push(p);
        }
    }
    loops.retain(|l| !l.is_empty());
    Ok(loops)
}

/// Prepare a body from `path`: a closed OBJ or STL mesh (3D, turned outward first) or an
/// outline file (2D, any other extension), at `spacing` (m). Errors name the file. Once `stop`
/// is raised (SIGINT, SIGTERM) a mesh's preparation ends early with an error saying so.
pub fn prepare_file(path: &Path, spacing: Real, stop: Interrupt) -> Result<PreparedBody, String> {
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    if extension == "stl" || extension == "obj" {
        let (vertices, triangles) = read_mesh(path)?;
        // The problem is the mesh's; what it is for is said here: a body fills the solid
        // the mesh encloses.
        let oriented = orient_outward(&vertices, &triangles).map_err(|e| {
            format!(
                "{}: {e} (a body is prepared from the solid its mesh encloses: the mesh of a body must be closed)",
                path.display()
            )
        })?;
        prepare_mesh_until(&vertices, &oriented.triangles, spacing, stop)
            .map_err(|e| format!("{}: {e}", path.display()))
    } else {
        let loops = read_outline(path)?;
        prepare_outline_until(&loops, spacing, stop).map_err(|e| format!("{}: {e}", path.display()))
    }
}

/// Write `body` as the paper's files `dir/<stem>.nodes`, `.links` and (3D) `.patches`, each
/// atomically; the paths written.
pub fn write_prepared(
    dir: &Path,
    stem: &str,
    body: &PreparedBody,
) -> std::io::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)?;
    let g = &body.geometry;
    let mut written = vec![
        dir.join(format!("{stem}.nodes")),
        dir.join(format!("{stem}.links")),
    ];
    write_nodes(&written[0], g.dimension, &g.nodes)?;
    write_links(&written[1], &g.members, None)?;
    if g.dimension == Dimension::Three {
        written.push(dir.join(format!("{stem}.patches")));
        write_patches(&written[2], &g.patches)?;
    }
    Ok(written)
}

/// The body a scene's `mesh` or `outline` key prepares (files relative to `folder`), or `None`
/// when it gives neither. Errors name the key. `stop`: as for [`prepare_file`].
pub(crate) fn prepared_geometry(
    spec: &crate::scene::spec::BodySpec,
    folder: &Path,
    stop: Interrupt,
) -> Result<Option<PreparedBody>, String> {
    if let Some(m) = &spec.mesh {
        let path = folder.join(&m.file);
        return prepare_file_checked(&path, "mesh", &m.file, m.spacing, stop).map(Some);
    }
    let Some(o) = &spec.outline else {
        return Ok(None);
    };
    match (&o.file, &o.points) {
        (Some(file), None) => {
            let path = folder.join(file);
            let loops = read_outline(&path).map_err(|e| format!("`outline`: {e}"))?;
            prepare_outline_until(&loops, o.spacing, stop)
                .map(Some)
                .map_err(|e| format!("`outline` = {file:?}: {e}"))
        }
        (None, Some(points)) => {
            prepare_outline_until(std::slice::from_ref(points), o.spacing, stop)
                .map(Some)
                .map_err(|e| format!("`outline`: {e}"))
        }
        _ => Err("`outline` needs exactly one of `file` and `points`".to_string()),
    }
}

/// [`prepare_file`] for a scene key, with a missing file named at the key.
fn prepare_file_checked(
    path: &Path,
    key: &str,
    file: &str,
    spacing: Real,
    stop: Interrupt,
) -> Result<PreparedBody, String> {
    if !path.is_file() {
        return Err(format!(
            "`{key}` file {file:?}: there is no file {}: file names are relative to the folder of the scene file",
            path.display()
        ));
    }
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    if extension != "stl" && extension != "obj" {
        return Err(format!(
            "`{key}` file {file:?}: give an .stl or .obj file (a 2D outline goes in `outline`)"
        ));
    }
    prepare_file(path, spacing, stop).map_err(|e| format!("`{key}`: {e}"))
}
