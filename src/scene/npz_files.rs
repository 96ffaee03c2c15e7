//! `steps/NNNN.npz` and `model.npz`: the fields of the JSON step and model files as NumPy arrays
//! (`[output] format = "npz"`), for models too large for text.
//!
//! Layout (see the README, *Output*): `bodies` holds the body names in scene order; body `k`
//! (1-based) has its arrays under `body<k>_<field>`, so any body name works. Numbers a user reads
//! are 1-based as in JSON. A list of `{"node", "force"}` becomes `<field>_node` (int64, r) and
//! `<field>_force` (float64, r × d); `contacts` becomes `contacts_node`, `contacts_with`,
//! `contacts_depth` and `contacts_force`. Scalars (`step`, `load_factor`, `scene`, `dimension`)
//! are 0-d arrays.

use crate::scene::model_file::{ModelBody, ModelFile, ModelObstacle, SupportedNode};
use crate::scene::npz_archive::{NpzIn, NpzOut};
use crate::scene::results::{BodyResult, ContactForce, NodeForce, StepResult};
use crate::Real;

const AXES: [&str; 3] = ["x", "y", "z"];

/// The name of body `k`'s (0-based) array `field`: `body<k+1>_<field>`.
fn body_key(k: usize, field: &str) -> String {
    format!("body{}_{field}", k + 1)
}

/// The name of obstacle `k`'s (0-based) array `field`: `obstacle<k+1>_<field>`.
fn obstacle_key(k: usize, field: &str) -> String {
    format!("obstacle{}_{field}", k + 1)
}

/// Add `rows` (each of `d` values) as a `[rows, d]` float64 array.
fn add_rows(out: &mut NpzOut, name: &str, rows: &[Vec<Real>], d: usize) -> std::io::Result<()> {
    out.f64s(name, &[rows.len(), d], rows.iter().flatten())
}

fn add_forces(out: &mut NpzOut, name: &str, list: &[NodeForce], d: usize) -> std::io::Result<()> {
    out.i64s(
        &format!("{name}_node"),
        &[list.len()],
        list.iter().map(|f| f.node),
    )?;
    out.f64s(
        &format!("{name}_force"),
        &[list.len(), d],
        list.iter().flat_map(|f| &f.force),
    )
}

/// The bytes of `steps/NNNN.npz` of `step`; `dimensions` gives each body's 2 or 3 (the
/// columns of its per-node arrays, also when it has no nodes).
pub(crate) fn step_npz(step: &StepResult, dimensions: &[usize]) -> std::io::Result<Vec<u8>> {
    let mut out = NpzOut::new();
    out.i64s("step", &[], [step.step])?;
    out.f64s("load_factor", &[], [&step.load_factor])?;
    let names: Vec<&str> = step.bodies.iter().map(|b| b.name.as_str()).collect();
    out.strs("bodies", &[names.len()], &names)?;
    for (k, b) in step.bodies.iter().enumerate() {
        let d = dimensions.get(k).copied().unwrap_or(3);
        let key = |field: &str| body_key(k, field);
        add_rows(&mut out, &key("displacements"), &b.displacements, d)?;
        add_rows(&mut out, &key("positions"), &b.positions, d)?;
        let m = b.axial_forces.len();
        out.f64s(&key("axial_forces"), &[m], &b.axial_forces)?;
        out.f64s(&key("strains"), &[b.strains.len()], &b.strains)?;
        out.f64s(&key("stresses"), &[b.stresses.len()], &b.stresses)?;
        out.i64s(
            &key("overloaded"),
            &[b.overloaded.len()],
            b.overloaded.iter().copied(),
        )?;
        add_forces(&mut out, &key("reactions"), &b.reactions, d)?;
        add_forces(&mut out, &key("loads"), &b.loads, d)?;
        let c = &b.contacts;
        out.i64s(&key("contacts_node"), &[c.len()], c.iter().map(|c| c.node))?;
        let with: Vec<&str> = c.iter().map(|c| c.with.as_str()).collect();
        out.strs(&key("contacts_with"), &[c.len()], &with)?;
        out.f64s(
            &key("contacts_depth"),
            &[c.len()],
            c.iter().map(|c| &c.depth),
        )?;
        out.f64s(
            &key("contacts_force"),
            &[c.len(), d],
            c.iter().flat_map(|c| &c.force),
        )?;
        if let Some(f) = &b.fracture {
            out.i64s(&key("broken"), &[f.broken.len()], f.broken.iter().copied())?;
            let breaks = &f.breaks;
            out.i64s(
                &key("breaks_member"),
                &[breaks.len()],
                breaks.iter().map(|b| b.member),
            )?;
            out.f64s(
                &key("breaks_load_factor"),
                &[breaks.len()],
                breaks.iter().map(|b| &b.load_factor),
            )?;
            // Written only for softening bodies, so other bodies' files keep their arrays.
            if breaks.iter().any(|b| b.tooth.is_some()) {
                out.i64s(
                    &key("breaks_tooth"),
                    &[breaks.len()],
                    breaks.iter().map(|b| b.tooth.unwrap_or(0)),
                )?;
            }
            // Written only for breaks in time (a dynamic scene).
            if breaks.iter().any(|b| b.time.is_some()) {
                out.f64s(
                    &key("breaks_time"),
                    &[breaks.len()],
                    breaks.iter().map(|b| b.time.as_ref().unwrap_or(&0.0)),
                )?;
            }
            out.i64s(&key("fallen"), &[f.fallen.len()], f.fallen.iter().copied())?;
        }
        out.f64s(
            &key("contacts_normal"),
            &[c.len(), d],
            c.iter().flat_map(|c| &c.normal),
        )?;
        out.f64s(
            &key("contacts_normal_force"),
            &[c.len()],
            c.iter().map(|c| &c.normal_force),
        )?;
        out.f64s(
            &key("contacts_tangential_force"),
            &[c.len(), d],
            c.iter().flat_map(|c| &c.tangential_force),
        )?;
        let states: Vec<&str> = c.iter().map(|c| c.state.as_str()).collect();
        out.strs(&key("contacts_state"), &[c.len()], &states)?;
        out.f64s(
            &key("contacts_slip"),
            &[c.len(), d],
            c.iter().flat_map(|c| &c.slip),
        )?;
    }
    out.finish()
}

/// `<name>_node` and `<name>_force` read back as node forces.
fn read_forces(npz: &mut NpzIn, name: &str, d: usize) -> Result<Vec<NodeForce>, String> {
    let nodes_key = format!("{name}_node");
    let nodes = npz.usizes(&nodes_key)?.list(&nodes_key, None)?;
    let force_key = format!("{name}_force");
    let forces = npz
        .f64s(&force_key)?
        .rows(&force_key, Some(nodes.len()), d)?;
    Ok(nodes
        .into_iter()
        .zip(forces)
        .map(|(node, force)| NodeForce { node, force })
        .collect())
}

/// `steps/NNNN.npz` read back from `bytes`, checked against `model` for the columns of its
/// arrays (whether the bodies fit the model otherwise is [`ModelFile::step_problem`]'s).
pub(crate) fn read_step_npz(bytes: &[u8], model: &ModelFile) -> Result<StepResult, String> {
    let mut npz = NpzIn::new(bytes)?;
    let step = npz.usizes("step")?.scalar("step")?;
    let load_factor = npz.f64s("load_factor")?.scalar("load_factor")?;
    let names = npz.strings("bodies")?.list("bodies", None)?;
    if names.len() != model.bodies.len() {
        return Err(format!(
            "array 'bodies' lists {} bodies but the model has {}",
            names.len(),
            model.bodies.len()
        ));
    }
    let mut bodies = Vec::with_capacity(names.len());
    for (name, (k, model_body)) in names.into_iter().zip(model.bodies.iter().enumerate()) {
        let (n, m, d) = (
            model_body.nodes.len(),
            model_body.members.len(),
            model_body.dimension,
        );
        let key = |field: &str| body_key(k, field);
        let mut rows = |field: &str, len: usize| -> Result<Vec<Vec<Real>>, String> {
            let name = key(field);
            npz.f64s(&name)?.rows(&name, Some(len), d)
        };
        let displacements = rows("displacements", n)?;
        let positions = rows("positions", n)?;
        let mut list = |field: &str| -> Result<Vec<Real>, String> {
            let name = key(field);
            npz.f64s(&name)?.list(&name, Some(m))
        };
        let axial_forces = list("axial_forces")?;
        let strains = list("strains")?;
        let stresses = list("stresses")?;
        let overloaded = npz
            .usizes(&key("overloaded"))?
            .list(&key("overloaded"), None)?;
        let reactions = read_forces(&mut npz, &key("reactions"), d)?;
        let loads = read_forces(&mut npz, &key("loads"), d)?;
        let nodes = npz
            .usizes(&key("contacts_node"))?
            .list(&key("contacts_node"), None)?;
        let c = nodes.len();
        let with = npz
            .strings(&key("contacts_with"))?
            .list(&key("contacts_with"), Some(c))?;
        let depth = npz
            .f64s(&key("contacts_depth"))?
            .list(&key("contacts_depth"), Some(c))?;
        let force = npz
            .f64s(&key("contacts_force"))?
            .rows(&key("contacts_force"), Some(c), d)?;
        let normal =
            npz.f64s(&key("contacts_normal"))?
                .rows(&key("contacts_normal"), Some(c), d)?;
        let normal_force = npz
            .f64s(&key("contacts_normal_force"))?
            .list(&key("contacts_normal_force"), Some(c))?;
        let tangential = npz.f64s(&key("contacts_tangential_force"))?.rows(
            &key("contacts_tangential_force"),
            Some(c),
            d,
        )?;
        let state = npz
            .strings(&key("contacts_state"))?
            .list(&key("contacts_state"), Some(c))?;
        let slip = npz
            .f64s(&key("contacts_slip"))?
            .rows(&key("contacts_slip"), Some(c), d)?;
        let contacts = nodes
            .into_iter()
            .zip(with)
            .zip(depth)
            .zip(force)
            .zip(normal.into_iter().zip(normal_force))
            .zip(tangential.into_iter().zip(state).zip(slip))
            .map(
                |(
                    ((((node, with), depth), force), (normal, normal_force)),
                    ((tangential_force, state), slip),
                )| {
                    ContactForce {
                        node,
                        with,
                        depth,
                        force,
                        normal,
                        normal_force,
                        tangential_force,
                        state,
                        slip,
                    }
                },
            )
            .collect();
        bodies.push(BodyResult {
            name,
            displacements,
            positions,
            axial_forces,
            strains,
            stresses,
            overloaded,
            reactions,
            loads,
            contacts,
            fracture: None,
            velocities: Vec::new(),
        });
    }
    Ok(StepResult {
        step,
        load_factor,
        time: None,
        bodies,
    })
}

/// The bytes of `model.npz` of `model`: `scene`, `bodies` (names), per body `body<k>_dimension`,
/// `_nodes` (n × d), `_members` (m × 2, 1-based), `_patches` (p × 3, 1-based), `_supports_node`
/// (1-based), `_supports_fix` (bool, s × d: x, y(, z) held), `_member_materials` (m, the
/// name of each member's material) and, when a material has a strength, `_strengths` (m × 2,
/// Pa: tension, compression; NaN for none); `obstacles` (names) and per
/// obstacle `obstacle<k>_vertices` (v × 3), `_triangles` (t × 3, 1-based), `_offsets`
/// ((steps + 1) × 3); `up` (3) when pictures draw another direction than +y upwards.
pub(crate) fn model_npz(model: &ModelFile) -> std::io::Result<Vec<u8>> {
    let mut out = NpzOut::new();
    out.strs("scene", &[], &[model.scene.as_str()])?;
    let names: Vec<&str> = model.bodies.iter().map(|b| b.name.as_str()).collect();
    out.strs("bodies", &[names.len()], &names)?;
    for (k, b) in model.bodies.iter().enumerate() {
        let key = |field: &str| body_key(k, field);
        let d = b.dimension;
        out.i64s(&key("dimension"), &[], [d])?;
        add_rows(&mut out, &key("nodes"), &b.nodes, d)?;
        out.i64s(
            &key("members"),
            &[b.members.len(), 2],
            b.members.iter().flatten().copied(),
        )?;
        out.i64s(
            &key("patches"),
            &[b.patches.len(), 3],
            b.patches.iter().flatten().copied(),
        )?;
        let s = &b.supports;
        out.i64s(&key("supports_node"), &[s.len()], s.iter().map(|s| s.node))?;
        out.bools(
            &key("supports_fix"),
            &[s.len(), d],
            s.iter()
                .flat_map(|s| AXES[..d].iter().map(|a| s.fix.iter().any(|f| f == a))),
        )?;
        let materials: Vec<&str> = b.member_materials.iter().map(|m| m.as_str()).collect();
        out.strs(&key("member_materials"), &[materials.len()], &materials)?;
        if !b.strengths.is_empty() {
            let values: Vec<f64> = b
                .strengths
                .iter()
                .flatten()
                .map(|s| s.unwrap_or(f64::NAN))
                .collect();
            out.f64s(&key("strengths"), &[b.strengths.len(), 2], &values)?;
        }
    }
    let names: Vec<&str> = model.obstacles.iter().map(|o| o.name.as_str()).collect();
    out.strs("obstacles", &[names.len()], &names)?;
    if let Some(up) = model.up {
        out.f64s("up", &[3], up.iter())?;
    }
    for (k, o) in model.obstacles.iter().enumerate() {
        let key = |field: &str| obstacle_key(k, field);
        out.f64s(
            &key("vertices"),
            &[o.vertices.len(), 3],
            o.vertices.iter().flatten(),
        )?;
        out.i64s(
            &key("triangles"),
            &[o.triangles.len(), 3],
            o.triangles.iter().flatten().copied(),
        )?;
        out.f64s(
            &key("offsets"),
            &[o.offsets.len(), 3],
            o.offsets.iter().flatten(),
        )?;
    }
    out.finish()
}

/// Rows of 3 as arrays.
fn triples<T: Copy + Default>(rows: Vec<Vec<T>>) -> Vec<[T; 3]> {
    rows.into_iter()
        .map(|r| {
            let mut a = [T::default(); 3];
            a.copy_from_slice(&r);
            a
        })
        .collect()
}

/// `model.npz` read back from `bytes`.
pub(crate) fn read_model_npz(bytes: &[u8]) -> Result<ModelFile, String> {
    let mut npz = NpzIn::new(bytes)?;
    let scene = npz.strings("scene")?.scalar("scene")?;
    let names = npz.strings("bodies")?.list("bodies", None)?;
    let mut bodies = Vec::with_capacity(names.len());
    for (k, name) in names.into_iter().enumerate() {
        let key = |field: &str| body_key(k, field);
        let dimension = npz.usizes(&key("dimension"))?.scalar(&key("dimension"))?;
        if dimension != 2 && dimension != 3 {
            return Err(format!(
                "array '{}' is {dimension}: 2 or 3",
                key("dimension")
            ));
        }
        let nodes = npz
            .f64s(&key("nodes"))?
            .rows(&key("nodes"), None, dimension)?;
        let members = npz
            .usizes(&key("members"))?
            .rows(&key("members"), None, 2)?
            .into_iter()
            .map(|r| [r[0], r[1]])
            .collect();
        let patches = triples(
            npz.usizes(&key("patches"))?
                .rows(&key("patches"), None, 3)?,
        );
        let nodes_held = npz
            .usizes(&key("supports_node"))?
            .list(&key("supports_node"), None)?;
        let fix = npz.bools(&key("supports_fix"))?.rows(
            &key("supports_fix"),
            Some(nodes_held.len()),
            dimension,
        )?;
        let supports = nodes_held
            .into_iter()
            .zip(fix)
            .map(|(node, held)| SupportedNode {
                node,
                fix: AXES
                    .iter()
                    .zip(held)
                    .filter(|(_, h)| *h)
                    .map(|(a, _)| a.to_string())
                    .collect(),
            })
            .collect();
        // Absent in archives of older runs.
        let member_materials = if npz.contains(&key("member_materials")) {
            npz.strings(&key("member_materials"))?
                .list(&key("member_materials"), None)?
        } else {
            Vec::new()
        };
        let strengths = if npz.contains(&key("strengths")) {
            npz.f64s(&key("strengths"))?
                .rows(&key("strengths"), None, 2)?
                .into_iter()
                .map(|r| [r[0], r[1]].map(|s: f64| (!s.is_nan()).then_some(s)))
                .collect()
        } else {
            Vec::new()
        };
        bodies.push(ModelBody {
            name,
            dimension,
            nodes,
            members,
            patches,
            supports,
            member_materials,
            strengths,
        });
    }
    let names = npz.strings("obstacles")?.list("obstacles", None)?;
    let mut obstacles = Vec::with_capacity(names.len());
    for (k, name) in names.into_iter().enumerate() {
        let key = |field: &str| obstacle_key(k, field);
        obstacles.push(ModelObstacle {
            name,
            vertices: triples(
                npz.f64s(&key("vertices"))?
                    .rows(&key("vertices"), None, 3)?,
            ),
            triangles: triples(
                npz.usizes(&key("triangles"))?
                    .rows(&key("triangles"), None, 3)?,
            ),
            offsets: triples(npz.f64s(&key("offsets"))?.rows(&key("offsets"), None, 3)?),
        });
    }
    // Absent when +y, and in archives of older runs.
    let up = if npz.contains("up") {
        let v = npz.f64s("up")?.list("up", Some(3))?;
        Some([v[0], v[1], v[2]])
    } else {
        None
    };
    Ok(ModelFile {
        scene,
        bodies,
        obstacles,
        up,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model() -> ModelFile {
        ModelFile {
            scene: "s".into(),
            bodies: vec![
                ModelBody {
                    name: "a body/with spaces".into(),
                    dimension: 2,
                    nodes: vec![vec![0.0, 0.0], vec![1.0, 0.1 + 0.2]],
                    members: vec![[1, 2]],
                    patches: vec![],
                    supports: vec![SupportedNode {
                        node: 1,
                        fix: vec!["x".into(), "y".into()],
                    }],
                    member_materials: vec!["steel".into()],
                    strengths: vec![],
                },
                ModelBody {
                    name: "3d".into(),
                    dimension: 3,
                    nodes: vec![vec![0.0; 3], vec![1.0, 0.0, 0.0], vec![0.0, 1.0, 0.0]],
                    members: vec![[1, 2], [2, 3], [3, 1]],
                    patches: vec![[1, 2, 3]],
                    supports: vec![SupportedNode {
                        node: 3,
                        fix: vec!["z".into()],
                    }],
                    member_materials: vec!["a".into(), "b".into(), "a".into()],
                    strengths: vec![[Some(2.5e8), None], [None, None], [Some(1.0), Some(2.0)]],
                },
            ],
            obstacles: vec![ModelObstacle {
                name: "floor".into(),
                vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
                triangles: vec![[1, 3, 2]],
                offsets: vec![[0.0; 3], [0.0, -1e-3, 0.0]],
            }],
            up: Some([0.0, 0.0, 1.0]),
        }
    }

    fn step() -> StepResult {
        let tricky = [0.12499999999999999, -0.0, 5e-324, 1.7976931348623157e308];
        StepResult {
            step: 7,
            load_factor: 0.7000000000000001,
            time: None,
            bodies: vec![
                BodyResult {
                    name: "a body/with spaces".into(),
                    displacements: vec![vec![0.0, 0.0], vec![tricky[0], tricky[2]]],
                    positions: vec![vec![0.0, 0.0], vec![1.0, tricky[1]]],
                    axial_forces: vec![tricky[3]],
                    strains: vec![1e-17],
                    stresses: vec![-2.5e8],
                    overloaded: vec![1],
                    reactions: vec![NodeForce {
                        node: 1,
                        force: vec![-1.0, 3.0],
                    }],
                    loads: vec![],
                    contacts: vec![ContactForce {
                        node: 2,
                        with: "flöor".into(),
                        depth: 1e-6,
                        force: vec![0.0, 2.0],
                        normal: vec![0.0, 1.0],
                        normal_force: 1.5,
                        tangential_force: vec![tricky[0], 0.0],
                        state: "stick".into(),
                        slip: vec![tricky[2], 0.0],
                    }],
                    fracture: None,
                    velocities: Vec::new(),
                },
                BodyResult {
                    name: "3d".into(),
                    displacements: vec![vec![0.1, 0.2, 0.3]; 3],
                    positions: vec![vec![1.0 / 3.0, 2.0, 3.0]; 3],
                    axial_forces: vec![1.0, 2.0, 3.0],
                    strains: vec![0.0; 3],
                    stresses: vec![4.0, 5.0, 6.0],
                    overloaded: vec![],
                    reactions: vec![],
                    loads: vec![NodeForce {
                        node: 2,
                        force: vec![0.0, 0.0, -10.0],
                    }],
                    contacts: vec![],
                    fracture: None,
                    velocities: Vec::new(),
                },
            ],
        }
    }

    fn bits(step: &StepResult) -> String {
        // Debug prints every float in full (shortest round trip), -0.0 included.
        format!("{step:?}")
    }

    #[test]
    fn a_step_and_its_model_come_back_bit_for_bit() {
        let model = model();
        let bytes = model_npz(&model).unwrap();
        assert_eq!(read_model_npz(&bytes).unwrap(), model);
        let step = step();
        let bytes = step_npz(&step, &[2, 3]).unwrap();
        let back = read_step_npz(&bytes, &model).unwrap();
        assert_eq!(bits(&back), bits(&step));
        assert_eq!(
            back.bodies[0].positions[1][1].to_bits(),
            (-0.0f64).to_bits()
        );
    }

    #[test]
    fn an_array_of_the_wrong_shape_is_named() {
        let mut model = model();
        model.bodies[0].nodes.push(vec![2.0, 2.0]);
        let bytes = step_npz(&step(), &[2, 3]).unwrap();
        let e = read_step_npz(&bytes, &model).unwrap_err();
        assert!(
            e.contains("array 'body1_displacements' has shape [2, 2]"),
            "{e}"
        );
        model.bodies.pop();
        let e = read_step_npz(&bytes, &model).unwrap_err();
        assert!(
            e.contains("array 'bodies' lists 2 bodies but the model has 1"),
            "{e}"
        );
        let e = read_step_npz(b"PK not really", &model).unwrap_err();
        assert!(e.contains("not a NumPy .npz archive"), "{e}");
    }
}
