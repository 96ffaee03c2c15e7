//! Finding contacts: contact candidates, open-shell sides, and the query of every node against the obstacles and the other bodies.

use crate::contact::body_part::{position, BodyPart};
use crate::contact::boundary::{inside_polygon, segment_projection, Surface};
use crate::contact::obstacle_features::Features;
use crate::contact::obstacles::to_glam;
use crate::contact::patch_surface::PatchSurface;
use crate::contact::self_contact::SelfContact;
use crate::contact::{
    penetration_tolerance, ActiveContact, ContactError, ContactSet, Obstacle, Obstacles,
    SurfaceProblem, Target,
};
use crate::linkage::{Body, Dimension};
use crate::Real;
use nalgebra::Vector3;
use rapier3d_f64::parry::query::{PointQueryWithLocation, Ray, RayCast};
use rapier3d_f64::parry::shape::TriMesh;
use std::collections::HashMap;

/// A node counts as inside a surface when it is deeper than this fraction of the penetration
/// tolerance (1e-9 of 1% of a member: round-off does not make contacts).
pub const MIN_DEPTH: Real = 1e-9;

/// How far (in barycentric weight, a fraction of the patch) a node may lie beyond the patch it
/// pressed on and keep it (see [`Geometry::keep_patches`]).
pub const KEEP_PATCH: Real = 0.05;

/// A node on the far side of an open shell from where it started the step is in contact when
/// it is within this many of the shell's mean member lengths of the shell (farther, it went
/// round the shell or the nearest patch changed, and it is not held).
pub const SHELL_REACH_MEMBERS: Real = 3.0;

/// An obstacle's sharp point within this many mean member lengths of a node of a body that is
/// itself inside the same obstacle does not press that body's patches (the body follows the
/// obstacle with its own nodes there; see [`Geometry::query`]).
pub const SHARP_REACH_MEMBERS: Real = 2.0;

/// Candidates lie within this many mean member lengths of an obstacle (anywhere along its
/// travel).
const MARGIN_MEMBERS: Real = 2.0;

/// Candidates lie within this many mean member lengths of another body's bounding box (with
/// the nodes of their surface patches, see [`candidate_nodes`]). Every candidate costs the
/// condensed path's set-up dearly (its compliance is dense: on the contact benchmark the
/// factorization with the candidates last grows about as the square of their number), so the
/// margin covers round-off and small moves only; a node that travels farther and touches is
/// added then (`CondensedSolver::grow`).
const BODY_MARGIN_MEMBERS: Real = 0.25;

/// A deformed boundary loop and its bounding box `[x_min, y_min, x_max, y_max]`, m.
type Polygon = (Vec<Vector3<Real>>, [Real; 4]);

/// A closed body's deformed patches as a parry mesh, and its bounding box `[lo, hi]`, m.
type Mesh = (TriMesh, [Vector3<Real>; 2]);

/// What contacts are found against: the bodies' surfaces, the sides of open shells, and the
/// obstacles.
pub(crate) struct Geometry {
    /// Contact surface of each body (2D: its outer boundary), `None` if it has none.
    pub(crate) surfaces: Vec<Option<Surface>>,
    /// Contact surface of each 3D body: its patches, facing out (or an open shell).
    pub(crate) patch_surfaces: Vec<Option<PatchSurface>>,
    /// Per open shell (empty for other bodies), per body, per node: the side of the shell the
    /// node started the step on (+1 in front of its patches, −1 behind, 0 not known).
    pub(crate) sides: Vec<Vec<Vec<i8>>>,
    /// Per open shell (empty for other bodies), per obstacle, per sharp point of the
    /// obstacle: the side of the shell the point started the step on (as [`Geometry::sides`]).
    pub(crate) point_sides: Vec<Vec<Vec<i8>>>,
    /// Per body, how far behind it as an open shell a node may be and be held, m.
    pub(crate) shell_reach: Vec<Real>,
    /// The rigid obstacles, held in rapier.
    pub(crate) obstacles: Obstacles,
    /// Contact of the bodies with themselves.
    pub(crate) own: SelfContact,
    /// Their sharp features and the crossings of nodes into them.
    pub(crate) features: Features,
}

impl Geometry {
    /// The surfaces of `bodies` (an open shell is a two-sided target: see
    /// [`Geometry::record_sides`]) and the colliders of `obstacles`.
    pub(crate) fn new(
        bodies: &[Body],
        obstacles: &[Obstacle],
        self_contact: Option<bool>,
    ) -> Result<Self, ContactError> {
        let surfaces: Vec<Option<Surface>> = bodies.iter().map(Surface::of).collect();
        let mut patch_surfaces = Vec::with_capacity(bodies.len());
        for body in bodies {
            patch_surfaces.push(match PatchSurface::of(body) {
                Ok(surface) => surface,
                Err(SurfaceProblem::NotClosed(_)) => PatchSurface::open_shell(body),
                Err(problem) => {
                    return Err(ContactError::Surface {
                        body: body.name.clone(),
                        problem,
                    })
                }
            });
        }
        let shapes: Vec<_> = obstacles.iter().map(|o| &o.shape).collect();
        let shortest = bodies
            .iter()
            .flat_map(|b| (0..b.members.len()).map(|m| b.member_length(m)))
            .fold(Real::INFINITY, Real::min);
        let two_d = bodies.iter().any(|b| b.dimension == Dimension::Two);
        let start = bodies.iter().map(|b| b.nodes.clone()).collect();
        let features = Features::new(&shapes, start, shortest, two_d);
        let obstacles = Obstacles::new(obstacles).map_err(ContactError::Obstacle)?;
        let sides = patch_surfaces
            .iter()
            .map(|s| match s {
                Some(s) if s.is_open() => bodies.iter().map(|b| vec![0; b.nodes.len()]).collect(),
                _ => Vec::new(),
            })
            .collect();
        let point_sides = patch_surfaces
            .iter()
            .map(|s| match s {
                Some(s) if s.is_open() => {
                    features.points.iter().map(|p| vec![0; p.len()]).collect()
                }
                _ => Vec::new(),
            })
            .collect();
        let shell_reach = bodies
            .iter()
            .map(|b| SHELL_REACH_MEMBERS * 100.0 * penetration_tolerance(b))
            .collect();
        let own = SelfContact::new(bodies, self_contact, &surfaces, &patch_surfaces);
        Ok(Geometry {
            own,
            surfaces,
            patch_surfaces,
            sides,
            point_sides,
            shell_reach,
            obstacles,
            features,
        })
    }

    /// Commit the obstacle crossings of the contacts `active` solved at the last state (the
    /// obstacles at `offsets` there, m), and take the nodes' positions there as the start of
    /// the segments along which the next crossings are found; record the side of every open
    /// shell each sharp obstacle point is on there ([`Geometry::record_point_sides`]).
    pub(crate) fn record_crossings(
        &mut self,
        bodies: &[Body],
        parts: &[BodyPart],
        active: &ContactSet,
        offsets: Vec<Vector3<Real>>,
    ) {
        self.record_point_sides(bodies, parts, active, &offsets);
        let start = bodies
            .iter()
            .enumerate()
            .map(|(b, body)| {
                (0..body.nodes.len())
                    .map(|n| position(bodies, parts, b, n))
                    .collect()
            })
            .collect();
        self.features.record(active, start, offsets);
    }

    /// For every open shell, the side of it each sharp point of the obstacles (at `offsets`,
    /// m) is on at the last solved state, with `active` the contacts solved there: as for the
    /// nodes of other bodies ([`Geometry::record_sides`]), a point held by the shell keeps the
    /// side it had, and one on the shell (within round-off) is not known and not held. An open
    /// shell has no inside: a point presses it when it crossed it since, from either side.
    fn record_point_sides(
        &mut self,
        bodies: &[Body],
        parts: &[BodyPart],
        active: &ContactSet,
        offsets: &[Vector3<Real>],
    ) {
        let min_depth = min_depth(parts);
        for shell in 0..self.patch_surfaces.len() {
            let Some(surface) = self.patch_surfaces[shell].as_ref().filter(|s| s.is_open()) else {
                continue;
            };
            let Some((mesh, _)) = surface.mesh(|n| position(bodies, parts, shell, n)) else {
                continue;
            };
            for (o, points) in self.features.points.iter().enumerate() {
                let (Some(offset), Some(sides)) =
                    (offsets.get(o), self.point_sides[shell].get_mut(o))
                else {
                    continue;
                };
                for (point, q) in points.iter().enumerate() {
                    let held = active.contacts.iter().any(|c| {
                        c.body == shell
                            && c.node == point
                            && matches!(c.with, Target::Sharp { obstacle, .. } if obstacle == o)
                    });
                    if held && sides[point] != 0 {
                        continue;
                    }
                    let s = surface
                        .shell_side(&mesh, &(q + offset), |n| position(bodies, parts, shell, n));
                    sides[point] = if s.distance <= min_depth || s.side == 0.0 {
                        0
                    } else if s.side > 0.0 {
                        1
                    } else {
                        -1
                    };
                }
            }
        }
    }

    /// The side of open shell `shell` sharp point `point` of obstacle `o` started the step on
    /// (+1 in front of its patches, −1 behind, 0 not known or not a shell).
    pub(crate) fn point_side(&self, shell: usize, o: usize, point: usize) -> i8 {
        self.point_sides
            .get(shell)
            .and_then(|s| s.get(o))
            .and_then(|s| s.get(point))
            .copied()
            .unwrap_or(0)
    }

    /// Forget the crossings found since the last [`Geometry::record_crossings`] (an increment
    /// undone).
    pub(crate) fn forget_crossings_found(&mut self) {
        self.features.forget_pending();
    }

    /// Where `node` of `body` at `x` stands against obstacle `o` at `offset` (m): depth and
    /// normal. Inside a polyhedral obstacle (or `held` in contact with it), behind the face
    /// (edge, corner) it crossed since the last solved state; else (a smooth obstacle, a node
    /// inside already, or outside) from the nearest point. `None` if the obstacle is not in
    /// the set.
    pub(crate) fn against_obstacle(
        &self,
        body: usize,
        node: usize,
        o: usize,
        x: &Vector3<Real>,
        offset: &Vector3<Real>,
        held: bool,
    ) -> Option<(Real, Option<Vector3<Real>>)> {
        let p = self.obstacles.project(o, x, offset)?;
        // A contact held keeps its crossing when the node comes out (its depth turns negative
        // along the same normal, and the settle loop lets it go).
        let crossing = if p.depth > 0.0 || held {
            self.features.crossing(body, node, o, x, offset)
        } else {
            None
        };
        match crossing {
            Some(c) => Some((c.depth(x, offset), Some(c.normal))),
            None => Some((p.depth, p.normal)),
        }
    }

    /// The name of what a contact touches.
    pub(crate) fn target_name<'a>(&'a self, bodies: &'a [Body], with: Target) -> &'a str {
        match with {
            Target::Obstacle(o) => self.obstacles.name(o),
            Target::Segment { body, .. }
            | Target::Vertex { body, .. }
            | Target::Patch { body, .. }
            | Target::Closing { body, .. }
            | Target::Edge { body, .. }
            | Target::Corner { body, .. } => &bodies[body].name,
            Target::Sharp { obstacle, .. } => self.obstacles.name(obstacle),
        }
    }

    /// For every open shell, the side of it each node of the other bodies is on at the last
    /// solved state (the start of the step), with `active` the contacts solved there. A node
    /// held by the shell keeps the side it had (its penalty leaves it a little on the far
    /// side); a node lying on the shell takes the side of the nodes it is joined to by members
    /// (a body resting on the shell is on the side of its other nodes); one whose neighbours
    /// lie on it too stays unknown and is not held.
    pub(crate) fn record_sides(
        &mut self,
        bodies: &[Body],
        parts: &[BodyPart],
        active: &ContactSet,
    ) {
        let min_depth = min_depth(parts);
        self.own.record(bodies, parts, active);
        for shell in 0..self.patch_surfaces.len() {
            let Some(surface) = self.patch_surfaces[shell].as_ref().filter(|s| s.is_open()) else {
                continue;
            };
            let Some((mesh, _)) = surface.mesh(|n| position(bodies, parts, shell, n)) else {
                continue;
            };
            let sides = &mut self.sides[shell];
            for (b, body) in bodies.iter().enumerate() {
                if b == shell {
                    continue;
                }
                let mut held = vec![false; body.nodes.len()];
                for c in &active.contacts {
                    if let (true, Target::Patch { body: t, .. }) = (c.body == b, c.with) {
                        if t == shell {
                            held[c.node] = true;
                        }
                    }
                }
                let signed: Vec<Real> = (0..body.nodes.len())
                    .map(|node| {
                        let x = position(bodies, parts, b, node);
                        let s =
                            surface.shell_side(&mesh, &x, |n| position(bodies, parts, shell, n));
                        if s.distance > min_depth {
                            s.side * s.distance
                        } else {
                            0.0
                        }
                    })
                    .collect();
                let mut neighbours = vec![0.0; body.nodes.len()];
                for member in &body.members {
                    let [i, j] = member.nodes;
                    neighbours[i] += signed[j];
                    neighbours[j] += signed[i];
                }
                for node in 0..body.nodes.len() {
                    if held[node] && sides[b][node] != 0 {
                        continue;
                    }
                    let s = if signed[node] != 0.0 {
                        signed[node]
                    } else {
                        neighbours[node]
                    };
                    sides[b][node] = if s > 0.0 {
                        1
                    } else if s < 0.0 {
                        -1
                    } else {
                        0
                    };
                }
            }
        }
    }

    /// `found`, with a node that presses on a patch of the same body as in `solved` keeping the
    /// patch of `solved` while it still projects onto it or within `KEEP_PATCH` of it: a node
    /// on the edge between two patches (coincident faces of two boxes, sliding sideways by
    /// round-off as the bodies squeeze) is then not moved from one to the other at every
    /// query, which made the set flip back and forth. The force goes to the kept patch's nodes
    /// (equal and opposite all the same); on a curved surface the depth measured from the kept
    /// patch's plane differs by about (distance beyond its edge)² / radius.
    pub(crate) fn keep_patches(
        &self,
        bodies: &[Body],
        parts: &[BodyPart],
        solved: &ContactSet,
        found: ContactSet,
    ) -> ContactSet {
        let before: HashMap<(usize, usize), Target> = solved
            .contacts
            .iter()
            .filter(|c| !matches!(c.with, Target::Sharp { .. } | Target::Closing { .. }))
            .map(|c| ((c.body, c.node), c.with))
            .collect();
        let mut changed = false;
        let mut contacts = found.contacts;
        for c in &mut contacts {
            let (Target::Patch { body, .. }, Some(&old)) = (c.with, before.get(&(c.body, c.node)))
            else {
                continue;
            };
            let Target::Patch {
                body: old_body,
                patch,
            } = old
            else {
                continue;
            };
            if old_body != body || old == c.with {
                continue;
            }
            let Some(surface) = self.patch_surfaces[body].as_ref() else {
                continue;
            };
            let [a, b, cc] = surface.patches[patch];
            let (pa, pb, pc) = (
                position(bodies, parts, body, a),
                position(bodies, parts, body, b),
                position(bodies, parts, body, cc),
            );
            let cross = (pb - pa).cross(&(pc - pa));
            let area2 = cross.norm();
            if area2.is_nan() || area2 <= 0.0 {
                continue;
            }
            let n = cross / area2;
            let x = position(bodies, parts, c.body, c.node);
            let p = x + n * (pa - x).dot(&n);
            let wa = (pb - p).cross(&(pc - p)).dot(&n) / area2;
            let wb = (pc - p).cross(&(pa - p)).dot(&n) / area2;
            if [wa, wb, 1.0 - wa - wb].iter().all(|&w| w >= -KEEP_PATCH) {
                c.with = old;
                changed = true;
            }
        }
        if changed {
            ContactSet::new(contacts)
        } else {
            ContactSet { contacts }
        }
    }

    /// Every node inside an obstacle (at `offsets` along their travel, m) or inside another
    /// body, with what it is deepest in.
    pub(crate) fn query(
        &self,
        bodies: &[Body],
        parts: &[BodyPart],
        offsets: &[Vector3<Real>],
    ) -> ContactSet {
        self.query_keeping(bodies, parts, offsets, &[])
    }

    /// [`Geometry::query`], with the contacts `kept` (a flipping set's obstacle contacts that
    /// still press, see `contact::pressing`) in the set too: a node kept counts as inside its
    /// obstacle, so the sharp points near it are left out as for a node found inside.
    pub(crate) fn query_keeping(
        &self,
        bodies: &[Body],
        parts: &[BodyPart],
        offsets: &[Vector3<Real>],
        kept: &[ActiveContact],
    ) -> ContactSet {
        // Deformed boundary polygons and their bounding boxes (the broad phase).
        let polygons: Vec<Option<Polygon>> = self
            .surfaces
            .iter()
            .enumerate()
            .map(|(b, s)| {
                s.as_ref().map(|s| {
                    let points: Vec<Vector3<Real>> = s
                        .nodes
                        .iter()
                        .map(|&n| position(bodies, parts, b, n))
                        .collect();
                    let mut bounds = [
                        Real::INFINITY,
                        Real::INFINITY,
                        -Real::INFINITY,
                        -Real::INFINITY,
                    ];
                    for p in &points {
                        bounds = [
                            bounds[0].min(p.x),
                            bounds[1].min(p.y),
                            bounds[2].max(p.x),
                            bounds[3].max(p.y),
                        ];
                    }
                    (points, bounds)
                })
            })
            .collect();
        // A node on a surface at a depth of round-off (a rim node on a floor through it) does
        // not count: it would flip in and out of the set.
        let min_depth = min_depth(parts);
        let meshes: Vec<_> = self
            .patch_surfaces
            .iter()
            .enumerate()
            .map(|(b, s)| {
                s.as_ref()
                    .and_then(|s| s.mesh(|n| position(bodies, parts, b, n)))
            })
            .collect();
        let own = self
            .own
            .grid(bodies, parts, &self.surfaces, &self.patch_surfaces);
        let mut found = Vec::new();
        for (b, body) in bodies.iter().enumerate() {
            for node in 0..body.nodes.len() {
                let x = position(bodies, parts, b, node);
                let mut deepest: Option<(Target, Real)> = None;
                let mut consider = |target: Target, depth: Real| {
                    if depth > min_depth && deepest.is_none_or(|(_, d)| depth > d) {
                        deepest = Some((target, depth));
                    }
                };
                for (o, offset) in offsets.iter().enumerate() {
                    if let Some((depth, _)) = self.against_obstacle(b, node, o, &x, offset, false) {
                        consider(Target::Obstacle(o), depth);
                    }
                }
                for (other, polygon) in polygons.iter().enumerate() {
                    let Some((points, bounds)) = polygon else {
                        continue;
                    };
                    if other == b
                        || x.x < bounds[0]
                        || x.y < bounds[1]
                        || x.x > bounds[2]
                        || x.y > bounds[3]
                        || !inside_polygon(&x, points)
                    {
                        continue;
                    }
                    if let Some((target, depth)) = inside_boundary(other, &x, points) {
                        consider(target, depth);
                    }
                }
                for (other, mesh) in meshes.iter().enumerate() {
                    let (Some((mesh, [lo, hi])), Some(surface)) =
                        (mesh, &self.patch_surfaces[other])
                    else {
                        continue;
                    };
                    let open = surface.is_open();
                    let reach = if open { self.shell_reach[other] } else { 0.0 };
                    if other == b || (0..3).any(|k| x[k] < lo[k] - reach || x[k] > hi[k] + reach) {
                        continue;
                    }
                    if open {
                        // Two-sided: held when on the other side from where the step started.
                        let started = self.sides[other][b][node];
                        if started == 0 {
                            continue;
                        }
                        let s = surface.shell_side(mesh, &x, |n| position(bodies, parts, other, n));
                        if s.side * Real::from(started) < 0.0 && !s.on_rim && s.distance <= reach {
                            consider(
                                Target::Patch {
                                    body: other,
                                    patch: s.patch,
                                },
                                s.distance,
                            );
                        }
                    } else if let Some((patch, depth)) = PatchSurface::inside(mesh, &x) {
                        consider(Target::Patch { body: other, patch }, depth);
                    }
                }
                let own_surface = self.patch_surfaces[b].as_ref();
                if let Some((target, depth)) =
                    self.own
                        .deepest(&own, own_surface, (b, node), &x, min_depth)
                {
                    consider(target, depth);
                }
                if let Some((with, _)) = deepest {
                    found.push(ActiveContact {
                        body: b,
                        node,
                        with,
                    });
                }
            }
        }
        found.extend_from_slice(kept);
        let sharp = self.sharp_points_inside(bodies, parts, offsets, &polygons, &meshes, &found);
        found.extend(sharp);
        found.extend(self.own.closed_cracks(bodies, parts, min_depth));
        ContactSet::new(found)
    }
}

impl Geometry {
    /// Every point along a sharp obstacle edge (2D: every corner of an obstacle's section) that
    /// lies inside a closed body, pressing the patch (2D: boundary segment) it entered through:
    /// the first one met going back along the obstacle's travel since the last solved state
    /// (the nearest one when the obstacle has not moved); and every such point on the other
    /// side of an open shell from where it started the step, pressing the nearest patch. A
    /// sharp feature then presses between the nodes of a coarse body. A point within
    /// `SHARP_REACH_MEMBERS` mean member lengths of a node of the body that is itself inside the
    /// same obstacle (in `nodes`) is left out: the body follows the obstacle with its own nodes
    /// there, and the point would count the same contact twice.
    fn sharp_points_inside(
        &self,
        bodies: &[Body],
        parts: &[BodyPart],
        offsets: &[Vector3<Real>],
        polygons: &[Option<Polygon>],
        meshes: &[Option<Mesh>],
        nodes: &[ActiveContact],
    ) -> Vec<ActiveContact> {
        let min_depth = min_depth(parts);
        let mut found = Vec::new();
        for (o, offset) in offsets.iter().enumerate() {
            let Some(points) = self.features.points.get(o).filter(|p| !p.is_empty()) else {
                continue;
            };
            let back = self.features.start_offset(o) - offset;
            for (b, body) in bodies.iter().enumerate() {
                let reach = SHARP_REACH_MEMBERS * 100.0 * penetration_tolerance(body);
                let held: Vec<Vector3<Real>> = nodes
                    .iter()
                    .filter(|c| c.body == b && c.with == Target::Obstacle(o))
                    .map(|c| position(bodies, parts, b, c.node))
                    .collect();
                for (point, q) in points.iter().enumerate() {
                    let x = q + offset;
                    if held.iter().any(|h| (h - x).norm() < reach) {
                        continue;
                    }
                    let patch = match (&meshes[b], &self.patch_surfaces[b], &polygons[b]) {
                        (Some((mesh, bounds)), Some(surface), _) if !surface.is_open() => {
                            entered_patch(mesh, bounds, &x, &back, min_depth)
                        }
                        (Some((mesh, [lo, hi])), Some(surface), _) => {
                            // An open shell: the patch the point crossed since the last solved
                            // state, from either side, as a node of another body does (not
                            // beside the rim, and within the shell's reach).
                            let started = self.point_side(b, o, point);
                            let shell_reach = self.shell_reach[b];
                            let near = (0..3).all(|k| {
                                x[k] >= lo[k] - shell_reach && x[k] <= hi[k] + shell_reach
                            });
                            if started == 0 || !near {
                                None
                            } else {
                                let s =
                                    surface.shell_side(mesh, &x, |n| position(bodies, parts, b, n));
                                (s.side * Real::from(started) < 0.0
                                    && !s.on_rim
                                    && s.distance > min_depth
                                    && s.distance <= shell_reach)
                                    .then_some(s.patch)
                            }
                        }
                        (None, _, Some(polygon)) => entered_segment(polygon, &x, &back, min_depth),
                        _ => None,
                    };
                    if let Some(patch) = patch {
                        found.push(ActiveContact {
                            body: b,
                            node: point,
                            with: Target::Sharp { obstacle: o, patch },
                        });
                    }
                }
            }
        }
        found
    }
}

/// The patch of the closed `mesh` (bounding box `[lo, hi]`) a point now at `x` inside it (deeper
/// than `min_depth`, m) entered through coming from the direction `back` (m; zero: the nearest
/// patch).
fn entered_patch(
    mesh: &TriMesh,
    [lo, hi]: &[Vector3<Real>; 2],
    x: &Vector3<Real>,
    back: &Vector3<Real>,
    min_depth: Real,
) -> Option<usize> {
    if (0..3).any(|k| x[k] < lo[k] || x[k] > hi[k]) {
        return None;
    }
    let (nearest, depth) = PatchSurface::inside(mesh, x)?;
    if depth <= min_depth {
        return None;
    }
    let Some(direction) = back.try_normalize(0.0) else {
        return Some(nearest);
    };
    let ray = Ray::new(to_glam(x), to_glam(&direction));
    let Some(hit) = mesh.cast_local_ray(&ray, Real::MAX, false) else {
        return Some(nearest);
    };
    // The patch under the hit point (the ray's feature numbering is not the patch's).
    let (_, (patch, _)) = mesh.project_local_point_and_get_location(ray.point_at(hit), false);
    Some(patch as usize)
}

/// The boundary segment of the deformed 2D `polygon` a point now at `x` inside it (deeper than
/// `min_depth`, m) entered through coming from the direction `back` (m; zero: the nearest).
fn entered_segment(
    (points, bounds): &Polygon,
    x: &Vector3<Real>,
    back: &Vector3<Real>,
    min_depth: Real,
) -> Option<usize> {
    if x.x < bounds[0]
        || x.y < bounds[1]
        || x.x > bounds[2]
        || x.y > bounds[3]
        || !inside_polygon(x, points)
    {
        return None;
    }
    let n = points.len();
    let segment = |i: usize| (points[i], points[(i + 1) % n]);
    let (nearest, depth) = (0..n)
        .map(|i| {
            let (a, b) = segment(i);
            (i, segment_projection(x, &a, &b).distance)
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))?;
    if depth <= min_depth {
        return None;
    }
    // The first segment met going back: x + s d = a + t (b − a), s > 0, 0 ≤ t ≤ 1.
    let d = back;
    let mut first: Option<(usize, Real)> = None;
    for i in 0..n {
        let (a, b) = segment(i);
        let e = b - a;
        let det = e.x * d.y - e.y * d.x;
        if det == 0.0 {
            continue;
        }
        let w = a - x;
        let s = (e.x * w.y - e.y * w.x) / det;
        let t = (d.x * w.y - d.y * w.x) / det;
        if s > 0.0 && (0.0..=1.0).contains(&t) && first.is_none_or(|(_, f)| s < f) {
            first = Some((i, s));
        }
    }
    Some(first.map_or(nearest, |(i, _)| i))
}

/// What a node at `x` inside the deformed boundary `points` of 2D body `body` presses on, and
/// how deep (m): the nearest segment, or the vertex between two segments equally near.
fn inside_boundary(
    body: usize,
    x: &Vector3<Real>,
    points: &[Vector3<Real>],
) -> Option<(Target, Real)> {
    let distances: Vec<Real> = (0..points.len())
        .map(|i| segment_projection(x, &points[i], &points[(i + 1) % points.len()]).distance)
        .collect();
    let i = (0..distances.len()).min_by(|&i, &j| distances[i].total_cmp(&distances[j]))?;
    // Equally near the segments on both sides of a vertex (a node on a symmetry line): press
    // on the vertex, so that neither segment is favoured.
    let n = points.len();
    let tie = |j: usize| (distances[j] - distances[i]).abs() <= 1e-9 * distances[i];
    let target = if tie((i + n - 1) % n) {
        Target::Vertex { body, vertex: i }
    } else if tie((i + 1) % n) {
        Target::Vertex {
            body,
            vertex: (i + 1) % n,
        }
    } else {
        Target::Segment { body, segment: i }
    };
    Some((target, distances[i]))
}

/// The depth below which a node is not inside a surface, m: `MIN_DEPTH` of the smallest
/// penetration tolerance.
fn min_depth(parts: &[BodyPart]) -> Real {
    MIN_DEPTH
        * parts
            .iter()
            .map(|p| p.tolerance)
            .fold(Real::INFINITY, Real::min)
}

/// Per body, the nodes that may touch something: surface nodes (3D: of its patches; 2D: of its
/// boundary loop; all nodes when it has neither) near another body's bounding box or near an
/// obstacle anywhere along its travel (`travels`: per obstacle, offsets sampled along it, m).
///
/// A node near another body comes with the other nodes of its patches (2D: its neighbours
/// along the loop): a node of the other body pressing near it presses one of those patches,
/// whose nodes are then in the contact's row (at the edge of a face, the side's patches).
pub(crate) fn candidate_nodes(
    bodies: &[Body],
    geometry: &Geometry,
    travels: &[Vec<Vector3<Real>>],
) -> Vec<Vec<bool>> {
    let margin: Vec<Real> = bodies
        .iter()
        .map(|b| MARGIN_MEMBERS * 100.0 * penetration_tolerance(b))
        .collect();
    let body_margin: Vec<Real> = bodies
        .iter()
        .map(|b| BODY_MARGIN_MEMBERS * 100.0 * penetration_tolerance(b))
        .collect();
    let boxes: Vec<(Vector3<Real>, Vector3<Real>)> = bodies
        .iter()
        .map(|b| {
            b.nodes.iter().fold(
                (
                    Vector3::repeat(Real::INFINITY),
                    Vector3::repeat(-Real::INFINITY),
                ),
                |(lo, hi), x| (lo.inf(x), hi.sup(x)),
            )
        })
        .collect();
    let mut out = Vec::with_capacity(bodies.len());
    for (b, body) in bodies.iter().enumerate() {
        let surface: Vec<usize> = match (&geometry.patch_surfaces[b], &geometry.surfaces[b]) {
            (Some(p), _) => p.nodes.clone(),
            (None, Some(s)) => s.nodes.clone(),
            (None, None) => (0..body.nodes.len()).collect(),
        };
        let mut mark = vec![false; body.nodes.len()];
        let mut near = vec![false; body.nodes.len()];
        for node in surface {
            let x = body.nodes[node];
            let near_body = boxes.iter().enumerate().any(|(o, (lo, hi))| {
                let m = body_margin[b].max(body_margin[o]);
                o != b && (0..3).all(|k| x[k] >= lo[k] - m && x[k] <= hi[k] + m)
            });
            near[node] = near_body;
            let near_obstacle = || {
                travels.iter().enumerate().any(|(o, offsets)| {
                    offsets.iter().any(|offset| {
                        geometry
                            .obstacles
                            .project(o, &x, offset)
                            .is_some_and(|p| p.depth >= -margin[b])
                    })
                })
            };
            mark[node] = geometry.own.is_on(b) || near_body || near_obstacle();
        }
        match (&geometry.patch_surfaces[b], &geometry.surfaces[b]) {
            (Some(p), _) => {
                for patch in p.patches.iter().filter(|t| t.iter().any(|&i| near[i])) {
                    patch.iter().for_each(|&i| mark[i] = true);
                }
            }
            (None, Some(s)) => {
                let n = s.nodes.len();
                for (i, &node) in s.nodes.iter().enumerate() {
                    if near[node] {
                        mark[s.nodes[(i + 1) % n]] = true;
                        mark[s.nodes[(i + n - 1) % n]] = true;
                    }
                }
            }
            (None, None) => {}
        }
        out.push(mark);
    }
    out
}

/// `mark` plus every node within `rings` members of a marked one.
pub(crate) fn widen(body: &Body, mark: &mut [bool], rings: usize) {
    for _ in 0..rings {
        let before = mark.to_vec();
        for member in &body.members {
            let [a, b] = member.nodes;
            if before[a] || before[b] {
                mark[a] = true;
                mark[b] = true;
            }
        }
    }
}
