//! `model.json`: the undeformed model of a run (what the step files do not repeat), written
//! once per run so results can be drawn and exported again without the scene file.

use crate::contact::{obstacle_surface, PatchSurface};
use crate::scene::results::StepResult;
use crate::scene::World;
use crate::Real;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// The directions a support holds at one node (several supports of a node combined).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SupportedNode {
    /// 1-based node number.
    pub node: usize,
    /// Held directions: any of `"x"`, `"y"`, `"z"`, in that order.
    pub fix: Vec<String>,
}

/// One body of `model.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelBody {
    /// Body name (as in the step files).
    pub name: String,
    /// 2 or 3.
    pub dimension: usize,
    /// Undeformed node positions, m, one `[x, y]` or `[x, y, z]` per node.
    pub nodes: Vec<Vec<Real>>,
    /// Members as 1-based node pairs, in member order.
    pub members: Vec<[usize; 2]>,
    /// Surface triangles as 1-based node triples (3D; may be empty): a closed surface outward
    /// (counter-clockwise seen from outside; given facing in, turned round), an open shell
    /// as given.
    pub patches: Vec<[usize; 3]>,
    /// Supported nodes, by node number.
    pub supports: Vec<SupportedNode>,
    /// The name of each member's material (a `[[materials]]` name), in member order (empty in
    /// files of older runs).
    #[serde(default)]
    pub member_materials: Vec<String>,
    /// Each member's strength, Pa, `[tension, compression]` (`null` where its material has
    /// none; a breaking member's own strength when it is scattered); empty, and absent from
    /// the file, when no material of the body has a strength. Pictures give the peak stress's
    /// ratio to it.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub strengths: Vec<[Option<Real>; 2]>,
}

/// One rigid obstacle of `model.json`: its surface at step 0 and its translation per step.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelObstacle {
    /// Obstacle name (as in the step files' `contacts.with`).
    pub name: String,
    /// Surface vertices at step 0, m, `[x, y, z]` (a 2D scene's obstacles are cut by z = 0
    /// when drawn).
    pub vertices: Vec<[Real; 3]>,
    /// Surface triangles as 1-based vertex triples, counter-clockwise seen from outside.
    pub triangles: Vec<[usize; 3]>,
    /// Translation at every step 0..=steps, m, `[x, y, z]`.
    pub offsets: Vec<[Real; 3]>,
}

/// `model.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelFile {
    /// Scene name.
    pub scene: String,
    /// Every body, in scene order (the order of the step files).
    pub bodies: Vec<ModelBody>,
    /// Every rigid obstacle, in scene order (absent in files of scenes without obstacles and
    /// of older runs).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub obstacles: Vec<ModelObstacle>,
    /// The unit direction pictures draw upwards, when it is not +y (`[output] up`, or
    /// opposite `gravity`); absent: +y.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up: Option<[Real; 3]>,
}

/// The side of the square a half-space is drawn as, in bounding diagonals of the bodies.
pub const HALF_SPACE_PATCH: Real = 4.0;

/// The obstacles of `world` as drawn: surfaces at step 0 (a half-space as a square of
/// [`HALF_SPACE_PATCH`] times the bodies' bounding diagonal, 1 m if that is 0, centred on
/// the projection of the centroid of the bodies' nodes) and their offsets at every step.
fn model_obstacles(world: &World) -> Vec<ModelObstacle> {
    let nodes = world.bodies.iter().flat_map(|b| b.nodes.iter());
    let mut count = 0usize;
    let mut sum = Vector3::zeros();
    let mut lo = Vector3::repeat(Real::INFINITY);
    let mut hi = Vector3::repeat(Real::NEG_INFINITY);
    for p in nodes {
        count += 1;
        sum += p;
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let (centroid, diagonal) = if count == 0 {
        (Vector3::zeros(), 0.0)
    } else {
        (sum / count as Real, (hi - lo).norm())
    };
    let side = if diagonal > 0.0 && diagonal.is_finite() {
        HALF_SPACE_PATCH * diagonal
    } else {
        1.0
    };
    world
        .obstacles
        .iter()
        .map(|o| {
            let s = obstacle_surface(&o.shape, &centroid, side);
            ModelObstacle {
                name: o.name.clone(),
                vertices: s.vertices.iter().map(|v| [v.x, v.y, v.z]).collect(),
                triangles: s.triangles.iter().map(|t| t.map(|i| i + 1)).collect(),
                offsets: (0..=world.steps)
                    .map(|k| {
                        let d = o.offset(k, world.steps);
                        [d.x, d.y, d.z]
                    })
                    .collect(),
            }
        })
        .collect()
}

/// Each member's `[tension, compression]` strength of `body` (Pa; `None` where its material
/// has none): the drawn strength of a breaking member with scatter, else its material's. Empty
/// when no material has a strength.
fn member_strengths(body: &crate::linkage::Body) -> Vec<[Option<Real>; 2]> {
    if !body
        .materials
        .iter()
        .any(|m| m.tensile_strength.is_some() || m.compressive_strength.is_some())
    {
        return Vec::new();
    }
    let finite = |s: Real| s.is_finite().then_some(s);
    let limits = crate::linkage::fracture::member_limits(body);
    body.members
        .iter()
        .zip(&limits)
        .map(|(m, limit)| match limit {
            Some((t, c)) => [finite(*t), finite(*c)],
            None => {
                let mat = &body.materials[m.material];
                [mat.tensile_strength, mat.compressive_strength]
            }
        })
        .collect()
}

/// The patches of `body`, a closed surface turned outward as contact sees it
/// ([`PatchSurface::of`]); an open shell or a surface that is not consistent as given.
fn outward_patches(body: &crate::linkage::Body) -> Vec<[usize; 3]> {
    match PatchSurface::of(body) {
        Ok(Some(surface)) if surface.flipped => surface.patches,
        _ => body.patches.clone(),
    }
}

impl ModelFile {
    /// The undeformed model of `world`.
    pub fn new(world: &World) -> Self {
        let bodies = world
            .bodies
            .iter()
            .map(|b| {
                let d = b.dimension.dofs_per_node();
                let mut fixed = vec![[false; 3]; b.nodes.len()];
                for s in &b.supports {
                    if let Some(f) = fixed.get_mut(s.node) {
                        for (k, held) in s.fixed.iter().enumerate().take(d) {
                            f[k] |= *held;
                        }
                    }
                }
                let supports = fixed
                    .iter()
                    .enumerate()
                    .filter(|(_, f)| f.iter().any(|h| *h))
                    .map(|(n, f)| SupportedNode {
                        node: n + 1,
                        fix: ["x", "y", "z"]
                            .iter()
                            .zip(f)
                            .filter(|(_, h)| **h)
                            .map(|(name, _)| name.to_string())
                            .collect(),
                    })
                    .collect();
                ModelBody {
                    name: b.name.clone(),
                    dimension: d,
                    nodes: b.nodes.iter().map(|p| p.as_slice()[..d].to_vec()).collect(),
                    members: b
                        .members
                        .iter()
                        .map(|m| [m.nodes[0] + 1, m.nodes[1] + 1])
                        .collect(),
                    patches: outward_patches(b)
                        .iter()
                        .map(|p| p.map(|n| n + 1))
                        .collect(),
                    supports,
                    member_materials: b
                        .members
                        .iter()
                        .map(|m| b.materials[m.material].name.clone())
                        .collect(),
                    strengths: member_strengths(b),
                }
            })
            .collect();
        ModelFile {
            scene: world.name.clone(),
            bodies,
            obstacles: model_obstacles(world),
            up: (world.pictures.up != [0.0, 1.0, 0.0]).then_some(world.pictures.up),
        }
    }

    /// Whether every number in the file refers to something that exists (a torn or edited
    /// file is caught here rather than by an index out of range later). Returns the problem.
    pub fn problem(&self) -> Option<String> {
        if let Some(up) = self.up {
            let norm = up.iter().map(|x| x * x).sum::<Real>().sqrt();
            if !(norm > 0.5 && norm < 2.0) {
                return Some(format!(
                    "its up direction {up:?} is not a unit vector: give [x, y, z] of length 1 (or leave it out for +y)"
                ));
            }
        }
        for o in &self.obstacles {
            let n = o.vertices.len();
            if let Some(t) = o
                .triangles
                .iter()
                .position(|t| t.iter().any(|&k| k == 0 || k > n))
            {
                return Some(format!(
                    "obstacle '{}': triangle {} names a vertex outside 1..={n}",
                    o.name,
                    t + 1
                ));
            }
        }
        for b in &self.bodies {
            let n = b.nodes.len();
            if b.dimension != 2 && b.dimension != 3 {
                return Some(format!(
                    "body '{}' has dimension {}: 2 or 3",
                    b.name, b.dimension
                ));
            }
            if let Some(p) = b.nodes.iter().position(|p| p.len() != b.dimension) {
                return Some(format!(
                    "body '{}': node {} has {} coordinates, not {}",
                    b.name,
                    p + 1,
                    b.nodes[p].len(),
                    b.dimension
                ));
            }
            let bad = |k: usize| k == 0 || k > n;
            if let Some(m) = b.members.iter().position(|m| m.iter().any(|&k| bad(k))) {
                return Some(format!(
                    "body '{}': member {} names a node outside 1..={n}",
                    b.name,
                    m + 1
                ));
            }
            if let Some(p) = b.patches.iter().position(|p| p.iter().any(|&k| bad(k))) {
                return Some(format!(
                    "body '{}': patch {} names a node outside 1..={n}",
                    b.name,
                    p + 1
                ));
            }
            if !b.member_materials.is_empty() && b.member_materials.len() != b.members.len() {
                return Some(format!(
                    "body '{}': {} member materials for {} members",
                    b.name,
                    b.member_materials.len(),
                    b.members.len()
                ));
            }
            if !b.strengths.is_empty() && b.strengths.len() != b.members.len() {
                return Some(format!(
                    "body '{}': {} strengths for {} members",
                    b.name,
                    b.strengths.len(),
                    b.members.len()
                ));
            }
            if let Some(s) = b.supports.iter().find(|s| bad(s.node)) {
                return Some(format!(
                    "body '{}': support names node {} outside 1..={n}",
                    b.name, s.node
                ));
            }
        }
        None
    }

    /// Whether `step` belongs to this model: the same bodies, one position and displacement
    /// per node, one force and stress per member, and only existing nodes and members named.
    /// Returns the problem.
    pub fn step_problem(&self, step: &StepResult) -> Option<String> {
        if step.bodies.len() != self.bodies.len() {
            return Some(format!(
                "has {} bodies but model.json has {}",
                step.bodies.len(),
                self.bodies.len()
            ));
        }
        for (b, m) in step.bodies.iter().zip(&self.bodies) {
            let n = m.nodes.len();
            let per_node_ok =
                |v: &[Vec<Real>]| v.len() == n && v.iter().all(|x| x.len() == m.dimension);
            if b.name != m.name
                || !per_node_ok(&b.positions)
                || !per_node_ok(&b.displacements)
                || b.axial_forces.len() != m.members.len()
                || b.stresses.len() != m.members.len()
            {
                return Some(format!(
                    "body '{}' does not match model.json (body '{}': {} nodes, {} members)",
                    b.name,
                    m.name,
                    n,
                    m.members.len()
                ));
            }
            let node_ok = |k: usize| (1..=n).contains(&k);
            let force_ok = |node: usize, f: &[Real]| node_ok(node) && f.len() == m.dimension;
            if !b
                .overloaded
                .iter()
                .all(|k| (1..=m.members.len()).contains(k))
                || !b.loads.iter().all(|l| force_ok(l.node, &l.force))
                || !b.reactions.iter().all(|l| force_ok(l.node, &l.force))
                || !b.contacts.iter().all(|c| force_ok(c.node, &c.force))
            {
                return Some(format!(
                    "body '{}' names a node or member that does not exist, or a force with the wrong number of components",
                    b.name
                ));
            }
        }
        None
    }
}
