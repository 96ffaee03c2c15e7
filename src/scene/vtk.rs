//! ParaView files of a run's results: `vtk/NNNN.vtu` per stored step (VTK XML unstructured
//! grid; arrays appended as zlib-compressed binary, or inline ASCII: [`VtkEncoding`]) and `vtk/<scene>.pvd`, the collection ParaView plays as the deformation process.
//!
//! One `.vtu` holds every body of the scene: points are the deformed node positions (z = 0
//! for 2D bodies), body after body; cells are the members as lines (VTK_LINE = 3), in member
//! order, body after body, then the patches as triangles (VTK_TRIANGLE = 5). Point data:
//! `displacement`, `applied_force`, `reaction`, `contact_force`, `tangential_force` (its
//! friction part; 3 components, m or N), `contact_state` (0 no contact, 1 sticking, 2
//! slipping; frictionless contacts slip) and `body` (1-based). Cell data: `axial_force` (N),
//! `stress` (Pa), `overloaded` (0/1), `member` (1-based, 0 on triangles), `body` and
//! `material` (the member's material: 1-based number of its name among the distinct names of
//! `model.json`'s `member_materials`, body after body, in order of first appearance; 0 on
//! triangles); with breaking members also `broken` (0/1, 0 on triangles). A triangle carries the mean axial
//! force and
//! stress of those of its three edges that are members (0 if none) and `overloaded` = 0.
//!
//! A scene with rigid obstacles also gets `vtk/obstacles_NNNN.vtu` per stored step, part 1 of
//! the collection: the obstacles' surfaces from `model.json` moved by their offset at that
//! step, as triangles in 3D and, in 2D, as the segments (VTK_LINE) where they cut z = 0. Cell
//! data `obstacle`: 1-based, in scene order; field data: one Int32 array per obstacle, named
//! after it, holding its number.

use crate::contact::cut_by_z0;
use crate::linkage::Interrupt;
use crate::scene::atomic_file::write_atomically;
use crate::scene::model_file::{ModelBody, ModelFile};
use crate::scene::publish::{publish_keeping, remove_stale, staging_dir};
use crate::scene::results::{BodyResult, StepResult};
use crate::scene::run_results::RunResults;
use crate::scene::vtu_arrays::{VtkEncoding, VtuArrays};
use crate::Real;
use nalgebra::Vector3;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Why VTK files could not be written.
#[derive(Debug, thiserror::Error)]
pub enum VtkError {
    /// The model does not fit its obstacles' steps (a `model.json` edited or torn).
    #[error("{path}: {problem}; run the scene again with `linkage run`")]
    BadModel {
        /// `model.json` of the results folder.
        path: PathBuf,
        /// What is wrong.
        problem: String,
    },
    /// A file could not be written.
    #[error("{path}: cannot write: {source}")]
    Write {
        /// File or folder.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// Asked to stop (SIGINT, SIGTERM) while writing: `vtk/` is as it was.
    #[error("{dir}: interrupted while writing the VTK files: vtk/ is as it was")]
    Interrupted {
        /// The results folder.
        dir: PathBuf,
    },
}

/// Write `dir/vtk/NNNN.vtu` for every stored step of `run` and `dir/vtk/<scene>.pvd`, and
/// with obstacles `dir/vtk/obstacles_NNNN.vtu` (part 1 of the collection; `NNNN` padded to
/// [`RunResults::digits`], as the step files are named); `dir` is the
/// results folder (`DIR/<scene>`). The collection's `timestep` is a dynamic scene's time (s)
/// of each stored state; else the load factor when it grows strictly over the stored steps,
/// else the step number (ParaView needs increasing times). Returns the files written.
///
/// The files are written into a staging folder that then replaces `vtk/` as a whole, so `vtk/`
/// never holds files of an older run beside these (a user's other files in it, not `.vtu` or
/// `.pvd`, are kept), and a write that fails leaves the old `vtk/` as it was. Once `stop` is
/// raised the writing stops before the next file ([`VtkError::Interrupted`]), the same way.
pub fn write_vtk(
    run: &RunResults,
    dir: &Path,
    encoding: VtkEncoding,
    stop: Interrupt,
) -> Result<Vec<PathBuf>, VtkError> {
    let final_dir = dir.join("vtk");
    remove_stale(dir, "vtk");
    let staging = staging_dir(dir, "vtk");
    let written = write_vtk_into(run, dir, &staging, encoding, stop).and_then(|written| {
        publish_keeping(&staging, &final_dir, &is_vtk_file).map_err(|source| VtkError::Write {
            path: final_dir.clone(),
            source,
        })?;
        Ok(written)
    });
    if staging.exists() {
        let _ = std::fs::remove_dir_all(&staging);
    }
    Ok(written?
        .iter()
        .filter_map(|p| p.file_name())
        .map(|name| final_dir.join(name))
        .collect())
}

/// Whether `name` is a file [`write_vtk`] writes (`.vtu`, `.pvd`).
fn is_vtk_file(name: &std::ffi::OsStr) -> bool {
    let name = name.to_string_lossy();
    name.ends_with(".vtu") || name.ends_with(".pvd")
}

/// The files of [`write_vtk`] written into the folder `dir` (the results folder
/// `results_dir` names `model.json` in errors).
fn write_vtk_into(
    run: &RunResults,
    results_dir: &Path,
    dir: &Path,
    encoding: VtkEncoding,
    stop: Interrupt,
) -> Result<Vec<PathBuf>, VtkError> {
    let stopped = || {
        if stop.is_raised() {
            Err(VtkError::Interrupted {
                dir: results_dir.to_path_buf(),
            })
        } else {
            Ok(())
        }
    };
    std::fs::create_dir_all(dir).map_err(|source| VtkError::Write {
        path: dir.to_path_buf(),
        source,
    })?;
    let mut written = Vec::new();
    let mut entries = Vec::new();
    for result in &run.steps {
        stopped()?;
        let step = result.step;
        let name = format!("{}.vtu", run.stem(step));
        let path = dir.join(&name);
        write_atomically(&path, &vtu_file(&run.model.bodies, result, encoding)).map_err(
            |source| VtkError::Write {
                path: path.clone(),
                source,
            },
        )?;
        written.push(path);
        entries.push((step, result.load_factor, result.time, name));
    }
    let mut obstacle_files = Vec::new();
    if !run.model.obstacles.is_empty() {
        for result in &run.steps {
            stopped()?;
            let step = result.step;
            let file = obstacles_vtu_file(&run.model, step, encoding).map_err(|problem| {
                VtkError::BadModel {
                    path: results_dir.join("model.json"),
                    problem,
                }
            })?;
            let name = format!("obstacles_{}.vtu", run.stem(step));
            let path = dir.join(&name);
            write_atomically(&path, &file).map_err(|source| VtkError::Write {
                path: path.clone(),
                source,
            })?;
            written.push(path);
            obstacle_files.push(name);
        }
    }
    let increasing = entries.windows(2).all(|w| w[1].1 > w[0].1);
    // A dynamic scene's states carry their time (s): the collection plays in real time.
    let timed = entries.iter().all(|e| e.2.is_some());
    let mut pvd = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n",
    );
    for (k, (step, factor, t, name)) in entries.iter().enumerate() {
        let time = match t {
            Some(t) if timed => *t,
            _ if increasing => *factor,
            _ => *step as Real,
        };
        let _ = writeln!(
            pvd,
            "    <DataSet timestep=\"{time}\" group=\"\" part=\"0\" file=\"{name}\"/>"
        );
        if let Some(obstacles) = obstacle_files.get(k) {
            let _ = writeln!(
                pvd,
                "    <DataSet timestep=\"{time}\" group=\"\" part=\"1\" file=\"{obstacles}\"/>"
            );
        }
    }
    pvd.push_str("  </Collection>\n</VTKFile>\n");
    stopped()?;
    let path = dir.join(format!("{}.pvd", run.model.scene));
    write_atomically(&path, pvd.as_bytes()).map_err(|source| VtkError::Write {
        path: path.clone(),
        source,
    })?;
    written.push(path);
    Ok(written)
}

/// One VTK cell: a member (line) or a patch (triangle) with its cell data.
struct Cell {
    points: Vec<usize>,
    kind: u8,
    axial_force: Real,
    stress: Real,
    overloaded: u8,
    /// 1 for a broken member (written only when a body has breaking members).
    broken: u8,
    member: usize,
    body: usize,
    /// 1-based number of the member's material name (0 on triangles).
    material: usize,
}

/// A per-node 3-vector array of one body from a list of (1-based node, force) entries.
fn node_vectors<'a>(
    n: usize,
    entries: impl Iterator<Item = (usize, &'a Vec<Real>)>,
) -> Vec<[Real; 3]> {
    let mut v = vec![[0.0; 3]; n];
    for (node, f) in entries {
        if let Some(slot) = v.get_mut(node.wrapping_sub(1)) {
            for (s, x) in slot.iter_mut().zip(f) {
                *s += x;
            }
        }
    }
    v
}

fn padded(p: &[Real]) -> [Real; 3] {
    [
        p.first().copied().unwrap_or(0.0),
        p.get(1).copied().unwrap_or(0.0),
        p.get(2).copied().unwrap_or(0.0),
    ]
}

/// One `.vtu` file for `result` of a run with model `bodies`, its arrays in `encoding`.
pub(crate) fn vtu_file(
    bodies: &[ModelBody],
    result: &StepResult,
    encoding: VtkEncoding,
) -> Vec<u8> {
    let mut points: Vec<[Real; 3]> = Vec::new();
    let mut displacement = Vec::new();
    let mut applied = Vec::new();
    let mut reaction = Vec::new();
    let mut contact = Vec::new();
    let mut tangential = Vec::new();
    let mut contact_state = Vec::new();
    let mut point_body = Vec::new();
    let mut lines: Vec<Cell> = Vec::new();
    let mut triangles = Vec::new();
    let mut material_names: Vec<&str> = Vec::new();
    for (k, (m, r)) in bodies.iter().zip(&result.bodies).enumerate() {
        let base = points.len();
        let n = m.nodes.len();
        points.extend(r.positions.iter().map(|p| padded(p)));
        displacement.extend(r.displacements.iter().map(|p| padded(p)));
        applied.extend(node_vectors(n, r.loads.iter().map(|l| (l.node, &l.force))));
        reaction.extend(node_vectors(
            n,
            r.reactions.iter().map(|l| (l.node, &l.force)),
        ));
        contact.extend(node_vectors(
            n,
            r.contacts.iter().map(|c| (c.node, &c.force)),
        ));
        tangential.extend(node_vectors(
            n,
            r.contacts.iter().map(|c| (c.node, &c.tangential_force)),
        ));
        let mut states = vec![0usize; n];
        for c in &r.contacts {
            if let Some(s) = states.get_mut(c.node.wrapping_sub(1)) {
                // Slip wins over stick where a node touches two things.
                *s = (*s).max(if c.state == "stick" { 1 } else { 2 });
            }
        }
        contact_state.extend(states);
        point_body.extend(std::iter::repeat_n(k + 1, n));
        let overloaded = overloaded_flags(m, r);
        let broken = broken_flags(m, r);
        let mut member_of: HashMap<(usize, usize), usize> = HashMap::new();
        for (j, e) in m.members.iter().enumerate() {
            member_of.insert((e[0].min(e[1]), e[0].max(e[1])), j);
            let material = match m.member_materials.get(j) {
                Some(name) => match material_names.iter().position(|n| n == name) {
                    Some(i) => i + 1,
                    None => {
                        material_names.push(name);
                        material_names.len()
                    }
                },
                None => 0,
            };
            lines.push(Cell {
                points: vec![base + e[0] - 1, base + e[1] - 1],
                kind: 3,
                axial_force: r.axial_forces[j],
                stress: r.stresses[j],
                overloaded: overloaded[j],
                broken: broken[j],
                member: j + 1,
                body: k + 1,
                material,
            });
        }
        for p in &m.patches {
            let edges = [(p[0], p[1]), (p[1], p[2]), (p[2], p[0])];
            let members: Vec<usize> = edges
                .iter()
                .filter_map(|&(a, b)| member_of.get(&(a.min(b), a.max(b))).copied())
                .collect();
            let mean = |v: &[Real]| {
                if members.is_empty() {
                    0.0
                } else {
                    members.iter().map(|&j| v[j]).sum::<Real>() / members.len() as Real
                }
            };
            triangles.push(Cell {
                points: p.iter().map(|&i| base + i - 1).collect(),
                kind: 5,
                axial_force: mean(&r.axial_forces),
                stress: mean(&r.stresses),
                overloaded: 0,
                broken: 0,
                member: 0,
                body: k + 1,
                material: 0,
            });
        }
    }
    lines.extend(triangles);
    let cells = lines;

    let mut a = VtuArrays::new(encoding, 64 * (points.len() + cells.len()) + 1024);
    a.xml.push_str(&file_opening(encoding));
    a.xml.push_str("  <UnstructuredGrid>\n");
    let _ = writeln!(
        a.xml,
        "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
        points.len(),
        cells.len()
    );
    a.xml
        .push_str("      <PointData Vectors=\"displacement\">\n");
    a.vectors("displacement", &displacement);
    a.vectors("applied_force", &applied);
    a.vectors("reaction", &reaction);
    a.vectors("contact_force", &contact);
    a.vectors("tangential_force", &tangential);
    a.ints("contact_state", contact_state.iter().copied());
    a.ints("body", point_body.iter().copied());
    a.xml
        .push_str("      </PointData>\n      <CellData Scalars=\"stress\">\n");
    a.scalars("axial_force", cells.iter().map(|c| c.axial_force));
    a.scalars("stress", cells.iter().map(|c| c.stress));
    a.ints("overloaded", cells.iter().map(|c| c.overloaded as usize));
    if result.bodies.iter().any(|b| b.fracture.is_some()) {
        a.ints("broken", cells.iter().map(|c| c.broken as usize));
    }
    a.ints("member", cells.iter().map(|c| c.member));
    a.ints("body", cells.iter().map(|c| c.body));
    a.ints("material", cells.iter().map(|c| c.material));
    a.xml.push_str("      </CellData>\n      <Points>\n");
    a.vectors("Points", &points);
    a.xml.push_str("      </Points>\n      <Cells>\n");
    a.longs(
        "connectivity",
        cells.iter().flat_map(|c| c.points.iter().copied()),
    );
    a.longs(
        "offsets",
        cells.iter().scan(0, |offset, c| {
            *offset += c.points.len();
            Some(*offset)
        }),
    );
    a.bytes("types", cells.iter().map(|c| c.kind));
    a.xml
        .push_str("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n");
    a.finish()
}

/// The XML declaration and the opening `VTKFile` element of an unstructured grid.
fn file_opening(encoding: VtkEncoding) -> String {
    format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\"{}>\n",
        encoding.file_attributes()
    )
}

/// `obstacles_NNNN.vtu` for `step`, arrays in `encoding`: every obstacle's surface moved by
/// its offset at `step`; in a 2D scene (bodies of dimension 2) its cut by z = 0 as lines.
/// Errors say what in `model.json` does not fit.
pub(crate) fn obstacles_vtu_file(
    model: &ModelFile,
    step: usize,
    encoding: VtkEncoding,
) -> Result<Vec<u8>, String> {
    let two_d = model.bodies.first().is_some_and(|b| b.dimension == 2);
    let mut points: Vec<[Real; 3]> = Vec::new();
    let mut cells: Vec<(Vec<usize>, usize)> = Vec::new();
    for (k, o) in model.obstacles.iter().enumerate() {
        let d = o.offsets.get(step).ok_or_else(|| {
            format!(
                "obstacle '{}' has offsets for steps 0..={} only, not step {step}",
                o.name,
                o.offsets.len() as isize - 1
            )
        })?;
        let d = Vector3::from(*d);
        let vertices: Vec<Vector3<Real>> =
            o.vertices.iter().map(|v| Vector3::from(*v) + d).collect();
        let n = vertices.len();
        if let Some(t) = o
            .triangles
            .iter()
            .find(|t| t.iter().any(|&i| i == 0 || i > n))
        {
            return Err(format!(
                "obstacle '{}': triangle {t:?} names a vertex outside 1..={n}",
                o.name
            ));
        }
        let triangles: Vec<[usize; 3]> = o.triangles.iter().map(|t| t.map(|i| i - 1)).collect();
        let base = points.len();
        if two_d {
            for [a, b] in cut_by_z0(&vertices, &triangles) {
                cells.push((vec![points.len(), points.len() + 1], k + 1));
                points.push([a.x, a.y, a.z]);
                points.push([b.x, b.y, b.z]);
            }
        } else {
            points.extend(vertices.iter().map(|v| [v.x, v.y, v.z]));
            cells.extend(
                triangles
                    .iter()
                    .map(|t| (t.iter().map(|i| base + i).collect(), k + 1)),
            );
        }
    }
    let kind = if two_d { 3 } else { 5 };
    let mut a = VtuArrays::new(encoding, 64 * (points.len() + cells.len()) + 1024);
    a.xml.push_str(&file_opening(encoding));
    // Field data stays inline text in either encoding: one small number per obstacle.
    a.xml.push_str("  <UnstructuredGrid>\n    <FieldData>\n");
    for (k, o) in model.obstacles.iter().enumerate() {
        let _ = writeln!(
            a.xml,
            "      <DataArray type=\"Int32\" Name=\"{}\" NumberOfTuples=\"1\" format=\"ascii\">{}</DataArray>",
            xml_attribute(&o.name),
            k + 1
        );
    }
    a.xml.push_str("    </FieldData>\n");
    let _ = writeln!(
        a.xml,
        "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
        points.len(),
        cells.len()
    );
    a.xml.push_str("      <CellData Scalars=\"obstacle\">\n");
    a.ints("obstacle", cells.iter().map(|c| c.1));
    a.xml.push_str("      </CellData>\n      <Points>\n");
    a.vectors("Points", &points);
    a.xml.push_str("      </Points>\n      <Cells>\n");
    a.longs(
        "connectivity",
        cells.iter().flat_map(|c| c.0.iter().copied()),
    );
    a.longs(
        "offsets",
        cells.iter().scan(0, |offset, c| {
            *offset += c.0.len();
            Some(*offset)
        }),
    );
    a.bytes("types", cells.iter().map(|_| kind));
    a.xml
        .push_str("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n");
    Ok(a.finish())
}

/// `text` escaped for an XML attribute value.
fn xml_attribute(text: &str) -> String {
    let mut s = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => s.push_str("&amp;"),
            '<' => s.push_str("&lt;"),
            '>' => s.push_str("&gt;"),
            '"' => s.push_str("&quot;"),
            '\'' => s.push_str("&apos;"),
            c => s.push(c),
        }
    }
    s
}

/// 1 per member broken so far (all 0 for a body without breaking members).
fn broken_flags(m: &ModelBody, r: &BodyResult) -> Vec<u8> {
    let mut f = vec![0u8; m.members.len()];
    for &j in r.fracture.iter().flat_map(|fr| &fr.broken) {
        if let Some(x) = f.get_mut(j.wrapping_sub(1)) {
            *x = 1;
        }
    }
    f
}

fn overloaded_flags(m: &ModelBody, r: &BodyResult) -> Vec<u8> {
    let mut f = vec![0u8; m.members.len()];
    for &j in &r.overloaded {
        if let Some(x) = f.get_mut(j.wrapping_sub(1)) {
            *x = 1;
        }
    }
    f
}
