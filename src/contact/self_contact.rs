//! Self-contact: a body's own nodes against its own surface (a U whose arms close, pieces of a
//! broken body), and the faces of its cracks against each other.
//!
//! **Surface.** A surface node (2D: of the boundary loop; 3D: of the closed patch surface) of a
//! body with self-contact presses on a segment (3D: patch) of the same body when
//! 1. no corner of the segment is within [`SELF_RINGS`] members of the node at rest (the
//!    segments that contain the node or lie next to it are never its targets: a node on a
//!    face, or at a corner, is on the line of its neighbours' segments at rest);
//! 2. the node projects onto the segment now (the foot of the perpendicular lies on it:
//!    parameter 0 ≤ t ≤ 1; 3D: barycentric weights ≥ 0; both to 1e-9) and lies behind it, deeper than the
//!    round-off depth and at most [`SELF_REACH_MEMBERS`] mean member lengths;
//! 3. it came from the front: at the last solved state (the start of the increment) it was
//!    held on that segment, or it lay in front of the segment's line (plane) or behind it by at
//!    most the contact tolerance (a node pressed by a neighbouring segment a little behind the
//!    same face may slide onto the next one).
//!
//! Condition 3 is what keeps a thick body from touching itself: a node on one face of an arm
//! lies behind the segments of the arm's other face at rest (by the arm's thickness), so it
//! never comes from their front. An unloaded body, and one under loads that do not fold it onto
//! itself, has no self-contact: every node stays where it was against every segment.
//! Of the segments a node meets this way, the nearest (smallest depth) is pressed, and the
//! force is shared by the segment's ends as between two bodies; segments as deep as the nearest
//! tie, and their shared vertex (3D: corner or edge) is pressed instead (`contact::ties`), so
//! that the choice depends on neither the segments' order nor the path.
//!
//! **Crack faces.** A member broken in tension (its ends apart at the break) is a crack's
//! bridge: when its ends come back closer than its rest length `L₀`, the crack has closed, and
//! its two end nodes press on each other along the member's undeformed axis `e₀` with the depth
//! `−e₀ · (uⱼ − uᵢ)` (the member's shortening; breaking bodies have linear kinematics) and the
//! body's penalty: a compression-only spring of the penalty's stiffness. A crack then closes exactly to where its faces were at rest, not a member's
//! length further as a surface rebuilt along the crack faces would allow (the faces of a
//! lattice crack lie one broken member apart). A member broken in compression (crushed) does
//! not close. Limits: crack faces that slide along each other by more than about a member
//! spacing are held only where they meet the body's outer surface; 2D holes and the crack
//! faces are not surfaces for condition 1–3 (only the outer boundary loop is).

use crate::contact::body_part::{position, BodyPart};
use crate::contact::boundary::{segment_projection, Surface};
use crate::contact::patch_surface::PatchSurface;
use crate::contact::ties::{self, Candidate, Pressed};
use crate::contact::{penetration_tolerance, ActiveContact, ContactSet, Penalty, Target};
use crate::linkage::body_state::{linear_stretch, undeformed_axis};
use crate::linkage::fracture::breaks_members;
use crate::linkage::{member_stiffnesses, Body};
use crate::Real;
use nalgebra::Vector3;
use std::collections::HashMap;

/// Segments (patches) with a corner within this many members of a node at rest are not its
/// self-contact targets.
pub const SELF_RINGS: usize = 2;

/// A node is held by a segment of its own body at most this many mean member lengths behind
/// it (deeper, it went round the segment's end, not through it).
pub const SELF_REACH_MEMBERS: Real = 1.5;

/// A foot this far (a fraction of the segment or patch) beyond its end or edge still lies on
/// it. Not round-off only: where a pressed face bends outward between two patches (a ridge), a
/// node just behind it projects beyond the edge of both, and with a margin of round-off it
/// would press neither and pass through (two cubes of one body pushed face to face did, with
/// 1e-9); the nearest of the patches it lies on within this margin holds it.
const ON: Real = 0.05;

/// Whether self-contact is on for `body`: `setting` when given (`[contact] self`), else for a
/// body with breaking members.
pub fn self_contact_on(body: &Body, setting: Option<bool>) -> bool {
    setting.unwrap_or_else(|| breaks_members(body))
}

/// One body's self-contact state.
struct Own {
    /// Per body node (surface nodes only; empty otherwise): the nodes within [`SELF_RINGS`]
    /// members at rest, sorted.
    near: Vec<Vec<usize>>,
    /// Node positions at the last solved state, m (empty before the first).
    start: Vec<Vector3<Real>>,
    /// The self-contacts held there: per node, its targets.
    held: HashMap<usize, Vec<Target>>,
    /// Per member: `None` intact; `Some(true)` broken with its ends apart (closes as a crack),
    /// `Some(false)` broken with its ends together (crushed: never closes).
    broken: Vec<Option<bool>>,
    /// How far behind a segment a node may be held, m.
    reach: Real,
    /// The contact tolerance of condition 3, m.
    tolerance: Real,
}

/// Self-contact of the bodies of a contact scene.
pub(crate) struct SelfContact {
    /// Per body, `None` when self-contact is off.
    bodies: Vec<Option<Own>>,
}

/// Per self-contact body, its deformed segments (patches) hashed by grid cell, for one query.
pub(crate) struct SelfGrid {
    cells: Vec<Option<Grid>>,
}

/// Targets of one body by grid cell (cell side: twice its reach).
struct Grid {
    side: Real,
    cells: HashMap<[i64; 3], Vec<usize>>,
    /// Corner nodes of every target.
    corners: Vec<Vec<usize>>,
    /// The body's deformed node positions, m.
    now: Vec<Vector3<Real>>,
    /// Per target, its bounding box widened by the reach, m.
    boxes: Vec<[Vector3<Real>; 2]>,
}

impl Grid {
    fn cell(&self, x: &Vector3<Real>) -> [i64; 3] {
        [0, 1, 2].map(|k| (x[k] / self.side).floor() as i64)
    }
}

impl SelfContact {
    /// The self-contact of `bodies` with `[contact] self` = `setting` (`None`: breaking bodies
    /// only); `surfaces` and `patch_surfaces` are the bodies' contact surfaces.
    pub(crate) fn new(
        bodies: &[Body],
        setting: Option<bool>,
        surfaces: &[Option<Surface>],
        patch_surfaces: &[Option<PatchSurface>],
    ) -> Self {
        let bodies = bodies
            .iter()
            .enumerate()
            .map(|(b, body)| {
                if !self_contact_on(body, setting) {
                    return None;
                }
                let surface_nodes: Vec<usize> = match (&patch_surfaces[b], &surfaces[b]) {
                    (Some(p), _) if !p.is_open() => p.nodes.clone(),
                    (None, Some(s)) => s.nodes.clone(),
                    _ => Vec::new(),
                };
                let mut adjacent: Vec<Vec<usize>> = vec![Vec::new(); body.nodes.len()];
                for m in &body.members {
                    let [i, j] = m.nodes;
                    adjacent[i].push(j);
                    adjacent[j].push(i);
                }
                let mut near = vec![Vec::new(); body.nodes.len()];
                for &n in &surface_nodes {
                    let mut found = vec![n];
                    let mut ring = vec![n];
                    for _ in 0..SELF_RINGS {
                        let mut next = Vec::new();
                        for &i in &ring {
                            for &j in &adjacent[i] {
                                if !found.contains(&j) {
                                    found.push(j);
                                    next.push(j);
                                }
                            }
                        }
                        ring = next;
                    }
                    found.sort_unstable();
                    near[n] = found;
                }
                let tolerance = penetration_tolerance(body);
                Some(Own {
                    near,
                    start: Vec::new(),
                    held: HashMap::new(),
                    broken: vec![None; body.members.len()],
                    reach: SELF_REACH_MEMBERS * 100.0 * tolerance,
                    tolerance,
                })
            })
            .collect();
        SelfContact { bodies }
    }

    /// Whether `body` has self-contact.
    pub(crate) fn is_on(&self, body: usize) -> bool {
        self.bodies.get(body).is_some_and(Option::is_some)
    }

    /// Take the last solved state (displacements in `parts`, contacts `active`) as the start
    /// of the next increment, with the contact tolerances of `parts`, and classify the members
    /// broken since (see the module documentation).
    pub(crate) fn record(&mut self, bodies: &[Body], parts: &[BodyPart], active: &ContactSet) {
        for (b, own) in self.bodies.iter_mut().enumerate() {
            let Some(own) = own else { continue };
            own.start = (0..bodies[b].nodes.len())
                .map(|n| position(bodies, parts, b, n))
                .collect();
            own.tolerance = parts[b].tolerance;
            own.held = HashMap::new();
            for c in &active.contacts {
                if c.body == b && target_body(c.with) == Some(b) {
                    own.held.entry(c.node).or_default().push(c.with);
                }
            }
            let stiffness = member_stiffnesses(&bodies[b]);
            for (m, k) in stiffness.iter().enumerate() {
                if *k > 0.0 {
                    own.broken[m] = None;
                } else if own.broken[m].is_none() {
                    own.broken[m] = Some(closure(bodies, parts, b, m).is_some_and(|d| d <= 0.0));
                }
            }
        }
    }

    /// The deformed targets of every self-contact body, hashed for [`SelfContact::deepest`].
    pub(crate) fn grid(
        &self,
        bodies: &[Body],
        parts: &[BodyPart],
        surfaces: &[Option<Surface>],
        patch_surfaces: &[Option<PatchSurface>],
    ) -> SelfGrid {
        let cells = self
            .bodies
            .iter()
            .enumerate()
            .map(|(b, own)| {
                let own = own
                    .as_ref()
                    .filter(|o| !o.start.is_empty() && o.reach > 0.0)?;
                let corners = targets(b, surfaces, patch_surfaces)?;
                let mut grid = Grid {
                    side: 2.0 * own.reach,
                    cells: HashMap::new(),
                    corners: Vec::new(),
                    boxes: Vec::with_capacity(corners.len()),
                    now: (0..bodies[b].nodes.len())
                        .map(|n| position(bodies, parts, b, n))
                        .collect(),
                };
                for (t, nodes) in corners.iter().enumerate() {
                    let (mut lo, mut hi) = (
                        Vector3::repeat(Real::INFINITY),
                        Vector3::repeat(-Real::INFINITY),
                    );
                    for &n in nodes {
                        lo = lo.inf(&grid.now[n]);
                        hi = hi.sup(&grid.now[n]);
                    }
                    let (lo, hi) = (
                        lo - Vector3::repeat(own.reach),
                        hi + Vector3::repeat(own.reach),
                    );
                    grid.boxes.push([lo, hi]);
                    let (lo, hi) = (grid.cell(&lo), grid.cell(&hi));
                    for i in lo[0]..=hi[0] {
                        for j in lo[1]..=hi[1] {
                            for k in lo[2]..=hi[2] {
                                grid.cells.entry([i, j, k]).or_default().push(t);
                            }
                        }
                    }
                }
                grid.corners = corners;
                Some(grid)
            })
            .collect();
        SelfGrid { cells }
    }

    /// The segment (patch) of its own body that surface `node` of body `b`, now at `x`,
    /// presses on, and its depth (m): the nearest of those meeting conditions 1–3 of the module
    /// documentation, deeper than `min_depth` (m).
    pub(crate) fn deepest(
        &self,
        grid: &SelfGrid,
        surface: Option<&PatchSurface>,
        (b, node): (usize, usize),
        x: &Vector3<Real>,
        min_depth: Real,
    ) -> Option<(Target, Real)> {
        let own = self.bodies.get(b)?.as_ref()?;
        let grid = grid.cells.get(b)?.as_ref()?;
        let near = own.near.get(node).filter(|n| !n.is_empty())?;
        let list = grid.cells.get(&grid.cell(x))?;
        let corners = &grid.corners;
        let mut candidates: Vec<Candidate> = Vec::new();
        for &t in list {
            let [lo, hi] = &grid.boxes[t];
            if (0..3).any(|k| x[k] < lo[k] || x[k] > hi[k]) {
                continue;
            }
            let nodes = &corners[t];
            if nodes.iter().any(|n| near.binary_search(n).is_ok()) {
                continue;
            }
            let now: Vec<Vector3<Real>> = nodes.iter().map(|&n| grid.now[n]).collect();
            let Some((depth, on)) = behind(x, &now) else {
                continue;
            };
            if !on || depth <= min_depth || depth > own.reach {
                continue;
            }
            let held = own.held.get(&node).map_or(&[][..], Vec::as_slice);
            if !held_on(held, t, nodes, corners.len()) {
                let then: Vec<Vector3<Real>> = nodes.iter().map(|&n| own.start[n]).collect();
                match behind(&own.start[node], &then) {
                    Some((d, _)) if d <= own.tolerance => {}
                    _ => continue,
                }
            }
            candidates.push(Candidate {
                index: t,
                corners: nodes,
                distance: depth,
            });
        }
        let nearest = candidates
            .iter()
            .min_by(|p, q| p.distance.total_cmp(&q.distance))?;
        let (depth, corners_of_nearest) = (nearest.distance, nearest.corners);
        let longest = corners_of_nearest
            .iter()
            .flat_map(|&p| corners_of_nearest.iter().map(move |&q| (p, q)))
            .map(|(p, q)| (grid.now[p] - grid.now[q]).norm())
            .fold(0.0, Real::max);
        let target = match ties::pressed(&candidates, ties::TIE * longest)? {
            Pressed::Patch(t) if corners[t].len() == 2 => Target::Segment {
                body: b,
                segment: t,
            },
            // 2D: the vertex's place in the boundary loop is that of the segment it starts.
            Pressed::Corner(v, _) if corners_of_nearest.len() == 2 => Target::Vertex {
                body: b,
                vertex: corners.iter().position(|c| c[0] == v)?,
            },
            pressed => surface?.target(b, pressed, x, |n| grid.now[n]),
        };
        Some((target, depth))
    }

    /// The broken members of self-contact bodies whose crack has closed (ends closer than the
    /// rest length by more than `min_depth`, m), as contacts of their first node against
    /// [`Target::Closing`].
    pub(crate) fn closed_cracks(
        &self,
        bodies: &[Body],
        parts: &[BodyPart],
        min_depth: Real,
    ) -> Vec<ActiveContact> {
        let mut out = Vec::new();
        for (b, own) in self.bodies.iter().enumerate() {
            let Some(own) = own else { continue };
            for (m, broken) in own.broken.iter().enumerate() {
                if *broken != Some(true) {
                    continue;
                }
                let i = bodies[b].members[m].nodes[0];
                if closure(bodies, parts, b, m).is_some_and(|d| d > min_depth) {
                    out.push(ActiveContact {
                        body: b,
                        node: i,
                        with: Target::Closing { body: b, member: m },
                    });
                }
            }
        }
        out
    }
}

/// Whether a node held at the last solved state on `held` (targets of its own body) was held
/// on target `t` (corner nodes `nodes`; `count` targets in all), or on an edge or corner (2D:
/// vertex) of it that a tie made it press (see `contact::ties`).
fn held_on(held: &[Target], t: usize, nodes: &[usize], count: usize) -> bool {
    held.iter().any(|&target| match target {
        Target::Segment { segment, .. } => segment == t,
        Target::Vertex { vertex, .. } => vertex == t || vertex == (t + 1) % count,
        Target::Patch { patch, .. } => patch == t,
        Target::Corner { node, .. } => nodes.contains(&node),
        Target::Edge { nodes: [p, q], .. } => nodes.contains(&p) && nodes.contains(&q),
        Target::Obstacle(_) | Target::Sharp { .. } | Target::Closing { .. } => false,
    })
}

/// The body a contact's target belongs to (`None`: an obstacle).
fn target_body(with: Target) -> Option<usize> {
    match with {
        Target::Segment { body, .. }
        | Target::Patch { body, .. }
        | Target::Vertex { body, .. }
        | Target::Closing { body, .. }
        | Target::Edge { body, .. }
        | Target::Corner { body, .. } => Some(body),
        Target::Obstacle(_) | Target::Sharp { .. } => None,
    }
}

/// The corner nodes of body `b`'s self-contact targets: its boundary segments (2D) or its
/// closed surface's patches (3D).
fn targets(
    b: usize,
    surfaces: &[Option<Surface>],
    patch_surfaces: &[Option<PatchSurface>],
) -> Option<Vec<Vec<usize>>> {
    match (&patch_surfaces[b], &surfaces[b]) {
        (Some(p), _) if !p.is_open() => Some(p.patches.iter().map(|t| t.to_vec()).collect()),
        (None, Some(s)) => Some(
            (0..s.nodes.len())
                .map(|i| {
                    let (a, c) = s.segment(i);
                    vec![a, c]
                })
                .collect(),
        ),
        _ => None,
    }
}

/// How deep `x` lies behind the segment (2 `corners`, 2D) or triangle (3 corners, outward by
/// their order) along its outward normal (m, negative in front), and whether its foot lies on
/// it. `None` for a degenerate one.
fn behind(x: &Vector3<Real>, corners: &[Vector3<Real>]) -> Option<(Real, bool)> {
    if let [a, b] = corners {
        let e = b - a;
        let length2 = e.norm_squared();
        if length2 <= 0.0 || !length2.is_finite() {
            return None;
        }
        let t = (x - a).dot(&e) / length2;
        let s = segment_projection(x, a, b);
        let n = s.normal?;
        return Some(((a - x).dot(&n), (-ON..=1.0 + ON).contains(&t)));
    }
    let [a, b, c] = corners else { return None };
    let cross = (b - a).cross(&(c - a));
    let area2 = cross.norm();
    if area2 <= 0.0 || !area2.is_finite() {
        return None;
    }
    let n = cross / area2;
    let depth = (a - x).dot(&n);
    let p = x + n * depth;
    let wa = (b - p).cross(&(c - p)).dot(&n) / area2;
    let wb = (c - p).cross(&(a - p)).dot(&n) / area2;
    Some((depth, wa >= -ON && wb >= -ON && 1.0 - wa - wb >= -ON))
}

/// A closed crack's depth (m), normal, the nodes its force acts on (body, node, weight) and
/// its penalty.
pub(crate) type Closed = (
    Real,
    Option<Vector3<Real>>,
    Vec<(usize, usize, Real)>,
    Penalty,
);

/// How far the ends `i → j` of member `member` of `body` have closed beyond its rest length,
/// m: `−e₀ · (uⱼ − uᵢ)` along its undeformed axis `e₀` (linear kinematics, as the breaking
/// bodies are: the closure is then a compression-only spring of the penalty's stiffness along
/// the member, linear in the displacements, and its tangent `k e₀ e₀ᵀ` is exact).
fn closure(bodies: &[Body], parts: &[BodyPart], body: usize, member: usize) -> Option<Real> {
    let b = bodies.get(body)?;
    let nodes = b.members.get(member)?.nodes;
    let axis = undeformed_axis(b, nodes[0], nodes[1]);
    let part = &parts[body];
    Some(-linear_stretch(
        &part.u,
        part.dofs.dofs_per_node,
        nodes,
        &axis,
    ))
}

/// The depth (m, see [`closure`]), normal (`−e₀`: from the other end towards the pressing
/// one), nodes and penalty of the closed crack of member `member` of `body`.
pub(crate) fn closing(
    bodies: &[Body],
    parts: &[BodyPart],
    body: usize,
    member: usize,
) -> Option<Closed> {
    let depth = closure(bodies, parts, body, member)?;
    let [i, j] = bodies[body].members[member].nodes;
    let axis = undeformed_axis(&bodies[body], i, j);
    Some((
        depth,
        Some(-axis),
        vec![(body, i, 1.0), (body, j, -1.0)],
        parts[body].penalty,
    ))
}

impl SelfContact {
    /// Classify member `member` of body `b`, broken since the last [`SelfContact::record`],
    /// as broken in tension (`apart`: its crack closes) or crushed, from how it broke rather
    /// than from where its ends are at the next recorded state (a body solved without contact
    /// is recorded at step ends only, and a crack may have opened and closed within a step).
    pub(crate) fn mark_broken(&mut self, b: usize, member: usize, apart: bool) {
        if let Some(Some(own)) = self.bodies.get_mut(b) {
            if let Some(slot) = own.broken.get_mut(member) {
                slot.get_or_insert(apart);
            }
        }
    }
}
