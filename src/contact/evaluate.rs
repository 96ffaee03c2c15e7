//! Evaluating contacts: one small function per kind of target (obstacle, patch, segment, vertex) giving depth, normal, the nodes the force acts on and the penalty.

use crate::contact::body_part::{position, BodyPart};
use crate::contact::boundary::segment_projection;
use crate::contact::detect::Geometry;
use crate::contact::patch_surface::triangle_projection;
use crate::contact::self_contact::closing;
use crate::contact::{
    return_mapping, ActiveContact, ContactSet, FrictionHistory, FrictionKey, Penalty, Tangential,
    Target,
};
use crate::linkage::body_state::node_vector;
use crate::linkage::Body;
use crate::Real;
use nalgebra::{Matrix3, Vector3};
use std::collections::HashMap;

/// A contact evaluated at the current displacements.
pub(crate) struct Evaluated {
    /// The contact.
    pub(crate) contact: ActiveContact,
    /// Penetration, m (negative: the node has come out).
    pub(crate) depth: Real,
    /// Outward unit normal of the surface pressed on.
    pub(crate) normal: Option<Vector3<Real>>,
    /// Penalty stiffness, N/m.
    pub(crate) penalty: Penalty,
    /// The nodes the force acts on, as (body, node, weight): the pressing node with 1, a
    /// surface's nodes with minus their barycentric weights (momentum is conserved).
    pub(crate) nodes: Vec<(usize, usize, Real)>,
    /// Friction (`None`: a frictionless pair): the tangential force on the pressing side, its
    /// state, tangent and slip this increment.
    pub(crate) tangential: Option<Tangential>,
}

impl Evaluated {
    /// The normal force on the pressing side, N (negative: a pull, see [`Penalty::force`]).
    pub(crate) fn normal_force(&self) -> Real {
        self.penalty.stiffness * self.depth
    }

    /// The force on the pressing side, N: normal and tangential (zero without a normal).
    pub(crate) fn force(&self) -> Vector3<Real> {
        let Some(n) = self.normal else {
            return Vector3::zeros();
        };
        let normal = self.penalty.force(self.depth, &n);
        match &self.tangential {
            Some(t) => normal + t.force,
            None => normal,
        }
    }

    /// The symmetric part of the contact's stiffness against the relative motion of the
    /// pressing side, `−∂f/∂g`, N/m: the penalty's `k n nᵀ` plus that of friction.
    pub(crate) fn stiffness(&self) -> Option<Matrix3<Real>> {
        let n = self.normal?;
        let k = self.penalty.stiffness(&n);
        Some(match &self.tangential {
            Some(t) => k + t.stiffness,
            None => k,
        })
    }

    /// The unsymmetric part of slip, `a bᵀ`, as `(a, b)` (see [`Tangential::rank_one`]).
    pub(crate) fn rank_one(&self) -> Option<(Vector3<Real>, Vector3<Real>)> {
        self.tangential.as_ref().and_then(|t| t.rank_one)
    }
}

/// The friction history key of contact `c`, and the sign its obstacle's offset enters the
/// relative motion of the pressing side with (−1: the obstacle is the surface; +1: the
/// obstacle's sharp point presses; 0: between bodies).
pub(crate) fn friction_key(c: &ActiveContact) -> (FrictionKey, Option<(usize, Real)>) {
    match c.with {
        Target::Obstacle(o) => (
            FrictionKey::Obstacle {
                body: c.body,
                node: c.node,
                obstacle: o,
            },
            Some((o, -1.0)),
        ),
        Target::Sharp { obstacle, .. } => (
            FrictionKey::Sharp {
                body: c.body,
                point: c.node,
                obstacle,
            },
            Some((obstacle, 1.0)),
        ),
        Target::Patch { body, .. }
        | Target::Segment { body, .. }
        | Target::Vertex { body, .. }
        | Target::Closing { body, .. }
        | Target::Edge { body, .. }
        | Target::Corner { body, .. } => (
            FrictionKey::Body {
                body: c.body,
                node: c.node,
                other: body,
            },
            None,
        ),
    }
}

/// The tangential answer of contact `c` (with `nodes` and weights, normal `n`, depth (m) and
/// penalty) against the history: `None` for a frictionless pair.
#[allow(clippy::too_many_arguments)]
fn friction_of(
    history: &FrictionHistory,
    parts: &[BodyPart],
    c: &ActiveContact,
    nodes: &[(usize, usize, Real)],
    n: &Vector3<Real>,
    depth: Real,
    penalty: Penalty,
    offsets: &[Vector3<Real>],
) -> Option<Tangential> {
    let (key, obstacle) = friction_key(c);
    let (mu, kt) = history.law(&key);
    if mu <= 0.0 {
        return None;
    }
    // A contact held sticking within a Newton solve (see `FrictionHistory::held`).
    let mu = if depth > 0.0 && history.held.contains(&key) {
        Real::INFINITY
    } else {
        mu
    };
    let mut dg = Vector3::zeros();
    for &(b, node, w) in nodes {
        let d = parts[b].dofs.dofs_per_node;
        let now = node_vector(&parts[b].u, d, node);
        let then = history
            .u
            .get(b)
            .map_or(Vector3::zeros(), |u| node_vector(u, d, node));
        dg += (now - then) * w;
    }
    if let Some((o, sign)) = obstacle {
        let then = history.offsets.get(o).copied().unwrap_or_default();
        dg += (offsets[o] - then) * sign;
    }
    let old = history
        .committed
        .get(&key)
        .map_or(Vector3::zeros(), |s| s.force);
    let kn = penalty.stiffness;
    let kt = kt.unwrap_or(kn);
    Some(return_mapping(
        mu,
        kt,
        kn,
        kn * depth.max(0.0),
        n,
        &old,
        &dg,
    ))
}

/// Every contact of a set evaluated at one iterate, and the contact force they make.
pub(crate) struct Evaluation {
    /// The contact force on each body DOF of every body, N.
    pub(crate) forces: Vec<Vec<Real>>,
    /// Each contact evaluated, in the set's order (those whose target is gone left out).
    pub(crate) list: Vec<Evaluated>,
}

/// One contact against its target, before the normal is taken from the cache: depth (m),
/// normal, the nodes the force acts on and the penalty.
struct Touch {
    depth: Real,
    normal: Option<Vector3<Real>>,
    nodes: Vec<(usize, usize, Real)>,
    penalty: Penalty,
}

/// Evaluate every contact of `set` at the bodies' current displacements, with the obstacles at
/// `offsets` (m), and their friction against `friction` (`None`: frictionless). A contact whose
/// normal cannot be found (a node exactly on the surface) takes the last one seen in
/// `normals`; every normal found is remembered there.
#[allow(clippy::too_many_arguments)]
pub(crate) fn evaluate(
    geometry: &Geometry,
    normals: &mut HashMap<ActiveContact, Vector3<Real>>,
    bodies: &[Body],
    parts: &[BodyPart],
    set: &ContactSet,
    offsets: &[Vector3<Real>],
    friction: Option<&FrictionHistory>,
) -> Evaluation {
    let mut f: Vec<Vec<Real>> = parts.iter().map(|p| vec![0.0; p.u.len()]).collect();
    let mut list = Vec::with_capacity(set.len());
    for c in &set.contacts {
        // A sharp contact's `node` is the obstacle's point, not a node of the body.
        let x = match c.with {
            Target::Sharp { .. } => Vector3::zeros(),
            _ => position(bodies, parts, c.body, c.node),
        };
        let touch = match c.with {
            Target::Obstacle(o) => on_obstacle(geometry, parts, c, o, &x, &offsets[o]),
            Target::Patch { body, patch } => on_patch(geometry, bodies, parts, c, body, patch, &x),
            Target::Vertex { body, vertex } => {
                on_vertex(geometry, bodies, parts, c, body, vertex, &x)
            }
            Target::Edge { body, nodes } => on_edge(geometry, bodies, parts, c, body, nodes, &x),
            Target::Corner { body, node, tied } => {
                on_corner(geometry, bodies, parts, c, (body, node, tied), &x)
            }
            Target::Segment { body, segment } => {
                on_segment(geometry, bodies, parts, c, body, segment, &x)
            }
            Target::Sharp { obstacle, patch } => on_sharp(
                geometry,
                bodies,
                parts,
                c,
                obstacle,
                patch,
                &offsets[obstacle],
            ),
            Target::Closing { body, member } => {
                closing(bodies, parts, body, member).map(|(depth, normal, nodes, penalty)| Touch {
                    depth,
                    normal,
                    nodes,
                    penalty,
                })
            }
        };
        let Some(Touch {
            depth,
            normal,
            nodes,
            penalty,
        }) = touch
        else {
            continue;
        };
        let normal = match normal {
            Some(n) => {
                normals.insert(*c, n);
                Some(n)
            }
            None => normals.get(c).copied(),
        };
        let mut tangential = None;
        if let Some(n) = normal {
            let mut force = penalty.force(depth, &n);
            tangential = friction
                .and_then(|h| friction_of(h, parts, c, &nodes, &n, depth, penalty, offsets));
            if let Some(t) = &tangential {
                force += t.force;
            }
            for &(b, node, w) in &nodes {
                let d = parts[b].dofs.dofs_per_node;
                for k in 0..d {
                    f[b][node * d + k] += w * force[k];
                }
            }
        }
        list.push(Evaluated {
            contact: *c,
            depth,
            normal,
            penalty,
            nodes,
            tangential,
        });
    }
    Evaluation { forces: f, list }
}

/// The penalty between two bodies: the softer of their penalties.
fn pair_penalty(parts: &[BodyPart], a: usize, b: usize) -> Penalty {
    Penalty {
        stiffness: parts[a].penalty.stiffness.min(parts[b].penalty.stiffness),
    }
}

/// A node at `x` against obstacle `o` at `offset` (m): the pressing node alone.
fn on_obstacle(
    geometry: &Geometry,
    parts: &[BodyPart],
    c: &ActiveContact,
    o: usize,
    x: &Vector3<Real>,
    offset: &Vector3<Real>,
) -> Option<Touch> {
    let (depth, normal) = geometry.against_obstacle(c.body, c.node, o, x, offset, true)?;
    Some(Touch {
        depth,
        normal,
        nodes: vec![(c.body, c.node, 1.0)],
        penalty: parts[c.body].penalty,
    })
}

/// Sharp point `c.node` of obstacle `o` at `offset` (m) against `patch` of `c.body` (a
/// boundary segment in 2D): as a node of another body pressing it, the force spread over the
/// patch's corners (the obstacle, rigid, takes the rest).
fn on_sharp(
    geometry: &Geometry,
    bodies: &[Body],
    parts: &[BodyPart],
    c: &ActiveContact,
    o: usize,
    patch: usize,
    offset: &Vector3<Real>,
) -> Option<Touch> {
    let q = geometry.features.points.get(o)?.get(c.node)? + offset;
    let body = c.body;
    let penalty = parts[body].penalty;
    if let Some(surface) = geometry.patch_surfaces[body].as_ref() {
        let [a, b, cc] = *surface.patches.get(patch)?;
        let mut t = triangle_projection(
            &q,
            &position(bodies, parts, body, a),
            &position(bodies, parts, body, b),
            &position(bodies, parts, body, cc),
        );
        if surface.is_open() {
            // Pushed back to the side of the shell the point started the step on (as a node
            // of another body on an open shell, see `on_patch`).
            let side = Real::from(geometry.point_side(body, o, c.node));
            t.normal = t.normal.map(|n| n * side);
            t.depth *= side;
        }
        return Some(Touch {
            depth: t.depth,
            normal: t.normal,
            nodes: vec![
                (body, a, -t.weights[0]),
                (body, b, -t.weights[1]),
                (body, cc, -t.weights[2]),
            ],
            penalty,
        });
    }
    let surface = geometry.surfaces[body].as_ref()?;
    let (a, b) = surface.segment(patch);
    let s = segment_projection(
        &q,
        &position(bodies, parts, body, a),
        &position(bodies, parts, body, b),
    );
    Some(Touch {
        depth: s.depth,
        normal: s.normal,
        nodes: vec![(body, a, -(1.0 - s.t)), (body, b, -s.t)],
        penalty,
    })
}

/// A node at `x` against `patch` of 3D body `body`: the force spread over the patch's corners.
fn on_patch(
    geometry: &Geometry,
    bodies: &[Body],
    parts: &[BodyPart],
    c: &ActiveContact,
    body: usize,
    patch: usize,
    x: &Vector3<Real>,
) -> Option<Touch> {
    let surface = geometry.patch_surfaces[body].as_ref()?;
    let [a, b, cc] = surface.patches[patch];
    let mut t = triangle_projection(
        x,
        &position(bodies, parts, body, a),
        &position(bodies, parts, body, b),
        &position(bodies, parts, body, cc),
    );
    if surface.is_open() {
        // Pushed back to the side the node started the step on: behind the patch, the normal
        // turns round and the depth is measured from there.
        let side = Real::from(geometry.sides[body][c.body][c.node]);
        t.normal = t.normal.map(|n| n * side);
        t.depth *= side;
    }
    Some(Touch {
        depth: t.depth,
        normal: t.normal,
        nodes: vec![
            (c.body, c.node, 1.0),
            (body, a, -t.weights[0]),
            (body, b, -t.weights[1]),
            (body, cc, -t.weights[2]),
        ],
        penalty: pair_penalty(parts, c.body, body),
    })
}

/// A node at `x` against the edge `nodes` of 3D body `body`'s closed surface (a tie between
/// its two patches, see `contact::ties`): along the area-weighted mean of their normals
/// (perpendicular to the edge), the depth measured from the edge, the force shared by the
/// edge's ends by the node's position along it (its nearest point of the edge).
///
/// The tangent is the frozen-normal one every patch contact uses (`k n nᵀ` over the nodes'
/// weights): it leaves out the turning of the normal and the sliding of the weights with the
/// nodes, which are of the order of the depth over a member and vanish as the bodies come to
/// rest on each other.
fn on_edge(
    geometry: &Geometry,
    bodies: &[Body],
    parts: &[BodyPart],
    c: &ActiveContact,
    body: usize,
    nodes: [usize; 2],
    x: &Vector3<Real>,
) -> Option<Touch> {
    let surface = geometry.patch_surfaces[body].as_ref()?;
    let at = |n: usize| position(bodies, parts, body, n);
    let normal = surface.mean_normal(&surface.edge_patches(nodes), at);
    let (pa, pb) = (at(nodes[0]), at(nodes[1]));
    let e = pb - pa;
    let length2 = e.norm_squared();
    let t = if length2 > 0.0 {
        ((x - pa).dot(&e) / length2).clamp(0.0, 1.0)
    } else {
        0.5
    };
    let depth = normal.map_or(0.0, |n| (pa - x).dot(&n));
    Some(Touch {
        depth,
        normal,
        nodes: vec![
            (c.body, c.node, 1.0),
            (body, nodes[0], -(1.0 - t)),
            (body, nodes[1], -t),
        ],
        penalty: pair_penalty(parts, c.body, body),
    })
}

/// A node at `x` against the corner `node` of 3D body `body`'s closed surface (a tie between
/// the patches around it selected by `tied`, see `contact::ties`): along the area-weighted mean
/// of those patches' normals, the depth measured from the corner, the force on the corner
/// node alone (the tangent as in [`on_edge`]).
fn on_corner(
    geometry: &Geometry,
    bodies: &[Body],
    parts: &[BodyPart],
    c: &ActiveContact,
    (body, node, tied): (usize, usize, u64),
    x: &Vector3<Real>,
) -> Option<Touch> {
    let surface = geometry.patch_surfaces[body].as_ref()?;
    let at = |n: usize| position(bodies, parts, body, n);
    let normal = surface.mean_normal(&surface.fan_tied(node, tied), at);
    let depth = normal.map_or(0.0, |n| (at(node) - x).dot(&n));
    Some(Touch {
        depth,
        normal,
        nodes: vec![(c.body, c.node, 1.0), (body, node, -1.0)],
        penalty: pair_penalty(parts, c.body, body),
    })
}

/// A node at `x` against `vertex` of 2D body `body`'s boundary: along the mean of the normals
/// of the vertex's two segments.
fn on_vertex(
    geometry: &Geometry,
    bodies: &[Body],
    parts: &[BodyPart],
    c: &ActiveContact,
    body: usize,
    vertex: usize,
    x: &Vector3<Real>,
) -> Option<Touch> {
    let surface = geometry.surfaces[body].as_ref()?;
    let (before, v) = surface.segment(surface.previous(vertex));
    let (_, after) = surface.segment(vertex);
    let corner = position(bodies, parts, body, v);
    let n = segment_projection(x, &position(bodies, parts, body, before), &corner)
        .normal
        .unwrap_or_default()
        + segment_projection(x, &corner, &position(bodies, parts, body, after))
            .normal
            .unwrap_or_default();
    let normal = (n.norm() > 0.0).then(|| n.normalize());
    let depth = normal.map_or(0.0, |n| (corner - x).dot(&n));
    Some(Touch {
        depth,
        normal,
        nodes: vec![(c.body, c.node, 1.0), (body, v, -1.0)],
        penalty: pair_penalty(parts, c.body, body),
    })
}

/// A node at `x` against `segment` of 2D body `body`'s boundary: the force shared by the
/// segment's ends.
fn on_segment(
    geometry: &Geometry,
    bodies: &[Body],
    parts: &[BodyPart],
    c: &ActiveContact,
    body: usize,
    segment: usize,
    x: &Vector3<Real>,
) -> Option<Touch> {
    let surface = geometry.surfaces[body].as_ref()?;
    let (a, b) = surface.segment(segment);
    let pa = position(bodies, parts, body, a);
    let pb = position(bodies, parts, body, b);
    let mut s = segment_projection(x, &pa, &pb);
    // Nearest to an end: that vertex is pressed, along the mean of the normals of its two
    // segments (which of the two was found does not matter then).
    let vertex = if s.t <= 0.0 {
        let (before, _) = surface.segment(surface.previous(segment));
        Some((pa, position(bodies, parts, body, before), pa, pb))
    } else if s.t >= 1.0 {
        let (_, after) = surface.segment(surface.next(segment));
        Some((pb, pa, pb, position(bodies, parts, body, after)))
    } else {
        None
    };
    if let Some((corner, p0, p1, p2)) = vertex {
        let n = segment_projection(x, &p0, &p1).normal.unwrap_or_default()
            + segment_projection(x, &p1, &p2).normal.unwrap_or_default();
        if n.norm() > 0.0 {
            let n = n.normalize();
            s.normal = Some(n);
            s.depth = (corner - x).dot(&n);
        }
    }
    Some(Touch {
        depth: s.depth,
        normal: s.normal,
        nodes: vec![
            (c.body, c.node, 1.0),
            (body, a, -(1.0 - s.t)),
            (body, b, -s.t),
        ],
        penalty: pair_penalty(parts, c.body, body),
    })
}
