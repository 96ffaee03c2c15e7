//! The settle loop of one load step: solve → find contacts → penalties, until the contact set
//! and equilibrium settle.
//!
//! Within one contact iteration the set of active contacts is fixed and Newton solves all the
//! bodies together: out-of-balance `r = F + f_c(u) − f_int(u)`, tangent `K_T(u) + K_c(u)` with
//! each active contact adding its penalty stiffness `k n nᵀ` (implicit penalty). Then every
//! node is projected on the obstacles: the nodes inside one form the next set (a node of the set
//! that came out, pulled by its penalty, leaves it). The step has settled when the set found is
//! the set solved. A set seen before (the contact flips back and forth) ends the loop with a
//! warning, as does running out of contact iterations.

use crate::contact::boundary::{inside_polygon, segment_projection, Surface};
use crate::contact::condensed::CondenseFailure;
use crate::contact::coupled_system::CoupledSystem;
use crate::contact::patch_surface::{triangle_projection, PatchSurface};
use crate::contact::{
    default_penalty, penetration_tolerance, ActiveContact, ContactError, ContactSet,
    ContactSettings, NodeContact, Obstacle, Obstacles, Penalty, SurfaceProblem, Target,
};
use crate::linalg::cholesky::CholeskyError;
use crate::linkage::body_state::{
    fill_tangent, internal_force_vector, loads_at, member_response_at, node_vector, norm,
    prescribed_at,
};
use crate::linkage::line_search::backtrack;
use crate::linkage::{
    post_process, Body, DofMap, PathMethod, PhaseTimes, SolveError, StepState, StiffnessAssembly,
};
use crate::Real;
use nalgebra::Vector3;
use std::collections::HashMap;
use std::time::Instant;

mod condensed_newton;
use condensed_newton::{candidate_nodes, Condensation};

/// The stabilisation of a singular tangent, relative to its largest diagonal entry: small
/// enough that the stabilised matrix is still the tangent to 9 digits, large enough to factor.
pub const STABILISATION: Real = 1e-9;

/// A deformed boundary loop and its bounding box `[x_min, y_min, x_max, y_max]`, m.
type Polygon = (Vec<Vector3<Real>>, [Real; 4]);

/// A contact evaluated at the current displacements.
struct Evaluated {
    contact: ActiveContact,
    /// Penetration, m (negative: the node has come out).
    depth: Real,
    /// Outward unit normal of the surface pressed on.
    normal: Option<Vector3<Real>>,
    /// Penalty stiffness, N/m.
    penalty: Penalty,
    /// The nodes the force acts on, as (body, node, weight): the pressing node with 1, a
    /// segment's end nodes with minus their barycentric weights (momentum is conserved).
    nodes: Vec<(usize, usize, Real)>,
}

/// A node counts as inside a surface when it is deeper than this fraction of the penetration
/// tolerance (1e-9 of 1% of a member: round-off does not make contacts).
pub const MIN_DEPTH: Real = 1e-9;

/// How far (in barycentric weight, a fraction of the patch) a node may lie beyond the patch it
/// pressed on and keep it (see `ContactSolver::keep_patches`).
pub const KEEP_PATCH: Real = 0.05;

/// See [`ContactSolver::force_floor`].
pub const FORCE_FLOOR: Real = 1e-10;

/// A node on the far side of an open shell from where it started the step is in contact when
/// it is within this many of the shell's mean member lengths of the shell (farther, it went
/// round the shell or the nearest patch changed, and it is not held).
pub const SHELL_REACH_MEMBERS: Real = 3.0;

/// One body's part of the coupled solve.
struct BodyPart {
    dofs: DofMap,
    assembly: StiffnessAssembly,
    /// Displacement per body DOF, m (kept between steps: the next step starts here).
    u: Vec<Real>,
    penalty: Penalty,
    /// Penetration above which a step is warned about, m.
    tolerance: Real,
    /// The body's tangent values in its assembly's pattern, N/m.
    local: Vec<Real>,
}

/// A solved step of a scene with contact.
#[derive(Clone, Debug, Default)]
pub struct ContactStep {
    /// Per body, in scene order.
    pub states: Vec<StepState>,
    /// Per body, the nodes pressing on an obstacle or another body.
    pub contacts: Vec<Vec<NodeContact>>,
    /// Contact iterations (solves with a fixed contact set) the step took.
    pub contact_iterations: usize,
    /// Newton iterations, all contact iterations together.
    pub newton_iterations: usize,
    /// Largest penetration at the solution, m.
    pub max_penetration: Real,
    /// What the user should know: penetration above tolerance, a contact set that did not
    /// settle.
    pub warnings: Vec<String>,
    /// Whether some iteration needed the stabilisation (a body held only by contact).
    pub stabilised: bool,
    /// Per body, the total contact force it receives from each obstacle or body it touches,
    /// as (name of the other, force in N), in name order.
    pub totals: Vec<Vec<(String, Vector3<Real>)>>,
}

/// All the bodies of a scene with contact, solved together step by step.
pub struct ContactSolver {
    parts: Vec<BodyPart>,
    /// First global node of each body.
    node_offsets: Vec<usize>,
    /// Contact surface of each body (2D: its outer boundary), `None` if it has none.
    surfaces: Vec<Option<Surface>>,
    /// Contact surface of each 3D body: its patches, facing out (or an open shell).
    patch_surfaces: Vec<Option<PatchSurface>>,
    /// Per open shell (empty for other bodies), per body, per node: the side of the shell the
    /// node started the step on (+1 in front of its patches, −1 behind, 0 not known).
    sides: Vec<Vec<Vec<i8>>>,
    /// Per body, how far behind it as an open shell a node may be and be held, m.
    shell_reach: Vec<Real>,
    /// Entries between bodies added to the coupled pattern so far (global free DOFs, r ≥ c).
    coupling: Vec<(usize, usize)>,
    obstacles: Obstacles,
    system: CoupledSystem,
    settings: ContactSettings,
    /// The contact set of the last solved step (the next step starts from it).
    active: ContactSet,
    /// The last normal seen per contact (used when a node lies exactly on the surface).
    normals: HashMap<ActiveContact, Vector3<Real>>,
    /// The step the displacements belong to.
    step: usize,
    /// Largest nodal move of a stabilised iteration, m: the smallest mean member length.
    move_cap: Real,
    /// The body whose tangent was singular last (for messages).
    unheld: usize,
    /// The contact set the current factorization was made with (not stabilised).
    factored: Option<ContactSet>,
    /// Every body linear: each factored once per run and condensed on its contact candidates
    /// (`None`: the coupled solve).
    condensed: Option<Vec<Condensation>>,
    /// A body found to move inside itself (beyond rigid motions) when it was condensed: named
    /// if no contact holds it either.
    mechanism: Option<Box<crate::linkage::Mechanism>>,
    /// The factored Jacobian of the condensed contact problem and the set it was made for.
    condensed_jacobian: Option<(ContactSet, crate::contact::condensed::ContactJacobian)>,
    /// Time spent so far in each phase, s.
    pub times: PhaseTimes,
    /// Time spent so far finding contacts (projecting nodes on obstacles), s.
    pub query_seconds: Real,
}

impl ContactSolver {
    /// Validate the bodies, build their patterns and the rapier colliders of the obstacles,
    /// and analyze the coupled pattern once.
    pub fn new(
        bodies: &[Body],
        obstacles: &[Obstacle],
        settings: ContactSettings,
    ) -> Result<Self, ContactError> {
        let t = Instant::now();
        let mut parts = Vec::with_capacity(bodies.len());
        let mut node_offsets = Vec::with_capacity(bodies.len());
        let mut nodes = 0;
        for body in bodies {
            body.validate().map_err(SolveError::from)?;
            if let PathMethod::ArcLength { .. } = body.newton.path {
                return Err(ContactError::ArcLength {
                    body: body.name.clone(),
                });
            }
            let dofs = DofMap::new(body);
            let assembly = StiffnessAssembly::new(body, &dofs).map_err(SolveError::from)?;
            parts.push(BodyPart {
                u: vec![0.0; body.dof_count()],
                penalty: Penalty {
                    stiffness: settings.penalty.unwrap_or_else(|| default_penalty(body)),
                },
                tolerance: settings
                    .tolerance
                    .unwrap_or_else(|| penetration_tolerance(body)),
                local: Vec::new(),
                dofs,
                assembly,
            });
            node_offsets.push(nodes);
            nodes += body.nodes.len();
        }
        let assembly_time = t.elapsed().as_secs_f64();
        let mut times = PhaseTimes {
            assembly: assembly_time,
            ..Default::default()
        };
        let surfaces: Vec<Option<Surface>> = bodies.iter().map(Surface::of).collect();
        let mut patch_surfaces = Vec::with_capacity(bodies.len());
        for body in bodies {
            // An open shell is a two-sided target: see `record_sides`.
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
        let obstacle_set = Obstacles::new(obstacles).map_err(ContactError::Obstacle)?;
        let mut condensed = None;
        let mut mechanism = None;
        if settings.condense && bodies.iter().all(|b| !b.is_nonlinear()) {
            // Obstacle offsets along their travel, sampled (a candidate missed is added later).
            let travels: Vec<Vec<Vector3<Real>>> = obstacles
                .iter()
                .map(|o| (0..=32).map(|s| o.offset(s, 32)).collect())
                .collect();
            let marks =
                candidate_nodes(bodies, &surfaces, &patch_surfaces, &obstacle_set, &travels);
            let mut built = Vec::with_capacity(bodies.len());
            for ((body, part), mark) in bodies.iter().zip(&parts).zip(marks) {
                match Condensation::build(body, &part.dofs, &part.assembly, mark) {
                    Ok(c) => {
                        times.symbolic += c.seconds[0];
                        times.numeric += c.seconds[1];
                        times.solve += c.seconds[2];
                        built.push(Condensation::new(c, body.dof_count()));
                    }
                    Err(CondenseFailure::Mechanism(m)) => {
                        mechanism = Some(m);
                        break;
                    }
                    Err(CondenseFailure::Other) => break,
                }
            }
            if built.len() == bodies.len() {
                condensed = Some(built);
            }
        }
        let t = Instant::now();
        let system = if condensed.is_some() {
            CoupledSystem::new(&[], &[], &[])
        } else {
            let assemblies: Vec<&StiffnessAssembly> = parts.iter().map(|p| &p.assembly).collect();
            CoupledSystem::new(&assemblies, &node_offsets, &[])
        }
        .map_err(|e| ContactError::Factorization(e.to_string()))?;
        times.symbolic += t.elapsed().as_secs_f64();
        let sides = patch_surfaces
            .iter()
            .map(|s| match s {
                Some(s) if s.is_open() => bodies.iter().map(|b| vec![0; b.nodes.len()]).collect(),
                _ => Vec::new(),
            })
            .collect();
        let shell_reach = bodies
            .iter()
            .map(|b| SHELL_REACH_MEMBERS * 100.0 * penetration_tolerance(b))
            .collect();
        Ok(ContactSolver {
            parts,
            node_offsets,
            surfaces,
            patch_surfaces,
            sides,
            shell_reach,
            coupling: Vec::new(),
            obstacles: obstacle_set,
            condensed,
            condensed_jacobian: None,
            mechanism,
            system,
            settings,
            active: ContactSet::default(),
            normals: HashMap::new(),
            step: 0,
            move_cap: bodies
                .iter()
                .filter(|b| !b.members.is_empty())
                .map(|b| 10.0 * penetration_tolerance(b))
                .fold(Real::INFINITY, Real::min),
            unheld: 0,
            factored: None,
            times,
            query_seconds: 0.0,
        })
    }

    /// Whether the bodies are solved condensed on their contact candidates (every body linear,
    /// each factored once per run), rather than as one coupled system.
    pub fn is_condensed(&self) -> bool {
        self.condensed.is_some()
    }

    /// Contact candidates of `body` on the condensed path (nodes; `None` on the coupled path).
    pub fn candidate_nodes(&self, body: usize) -> Option<usize> {
        let c = self.condensed.as_ref()?.get(body)?;
        Some(c.body.nodes.iter().filter(|&&m| m).count())
    }

    /// The coupled system of all bodies, analyzed (when leaving the condensed path).
    fn build_coupled(&mut self) -> Result<(), ContactError> {
        let t = Instant::now();
        let assemblies: Vec<&StiffnessAssembly> = self.parts.iter().map(|p| &p.assembly).collect();
        self.system = CoupledSystem::new(&assemblies, &self.node_offsets, &self.coupling)
            .map_err(|e| ContactError::Factorization(e.to_string()))?;
        self.times.symbolic += t.elapsed().as_secs_f64();
        Ok(())
    }

    /// The smallest force scale a residual is measured against, N: `FORCE_FLOOR` times the
    /// smallest penalty times the smallest tolerance (a force of the order of a member's
    /// `E A`). Where nothing is loaded (step 0, a node touching a surface at a depth of
    /// round-off) the residual is then round-off over a real force, not round-off over round-off.
    fn force_floor(&self) -> Real {
        let k = self
            .parts
            .iter()
            .map(|p| p.penalty.stiffness)
            .fold(Real::INFINITY, Real::min);
        let tolerance = self
            .parts
            .iter()
            .map(|p| p.tolerance)
            .fold(Real::INFINITY, Real::min);
        let floor = FORCE_FLOOR * k * tolerance;
        if floor.is_finite() {
            floor
        } else {
            0.0
        }
    }

    /// Rows of the coupled system of all bodies (their free DOFs).
    pub fn free_dofs(&self, body: usize) -> usize {
        self.parts.get(body).map_or(0, |p| p.assembly.n)
    }

    /// The penalty stiffness used for `body`, N/m.
    pub fn penalty(&self, body: usize) -> Real {
        self.parts.get(body).map_or(0.0, |p| p.penalty.stiffness)
    }

    /// Solve `step` of `steps` for `bodies` (the ones given to [`ContactSolver::new`]).
    /// Steps are meant to come in order: each starts from the displacements and the contact
    /// set of the step before (asking for step 0 starts over).
    pub fn solve_step(
        &mut self,
        bodies: &[Body],
        obstacles: &[Obstacle],
        step: usize,
        steps: usize,
    ) -> Result<ContactStep, ContactError> {
        let restart = step == 0 || step < self.step;
        if restart {
            for p in &mut self.parts {
                p.u.iter_mut().for_each(|v| *v = 0.0);
            }
            self.active = ContactSet::default();
            self.normals.clear();
        }
        self.record_sides(bodies);
        self.condensed_step(step, steps, restart);
        self.step = step;
        let offsets: Vec<Vector3<Real>> = obstacles.iter().map(|o| o.offset(step, steps)).collect();
        let forces: Vec<Vec<Real>> = bodies
            .iter()
            .map(|b| loads_at(b, step as Real, steps))
            .collect();
        for (part, body) in self.parts.iter_mut().zip(bodies) {
            let prescribed = prescribed_at(body, step as Real, steps);
            for &dof in &part.dofs.supported {
                part.u[dof] = prescribed[dof];
            }
        }
        let mut set = self.active.clone();
        let mut seen: Vec<ContactSet> = Vec::new();
        let mut out = ContactStep::default();
        let mut refinements = 0;
        loop {
            out.contact_iterations += 1;
            let (iterations, settled) = if self.condensed.is_some() {
                self.newton_condensed(bodies, &set, &forces, &offsets, step)?
            } else {
                self.newton(bodies, &set, &forces, &offsets, step)?
            };
            out.newton_iterations += iterations;
            out.stabilised |= !settled;
            let t = Instant::now();
            let mut found = self.keep_patches(bodies, &set, self.query(bodies, &offsets));
            self.query_seconds += t.elapsed().as_secs_f64();
            if settled && found == set && self.condensed.is_some() {
                // Settled on the candidates: solve for every node, and look again with them.
                let differs = self.expand_condensed();
                let t = Instant::now();
                found = self.keep_patches(bodies, &set, self.query(bodies, &offsets));
                self.query_seconds += t.elapsed().as_secs_f64();
                // The placement was off by the compliance's round-off (a penalty turns 1e-13 m
                // into forces the tolerance sees): above a tenth of the tolerance, Newton again
                // from the solve, which returns at once when the residual there is within it.
                if found == set && differs > 1e-11 && refinements < 3 {
                    refinements += 1;
                    continue;
                }
            }
            if !settled {
                // A stabilised move toward the contacts: look again, no equilibrium yet.
                if out.contact_iterations >= self.settings.max_iterations {
                    if let Some(m) = self.mechanism.take() {
                        return Err(ContactError::Mechanism { step, mechanism: m });
                    }
                    return Err(ContactError::Unsupported {
                        step,
                        body: self.moving_body(bodies),
                        iterations: out.contact_iterations,
                        contacts: found.len(),
                    });
                }
                set = found;
                continue;
            }
            if found == set {
                break;
            }
            if seen.contains(&found) {
                let (joined, left) = found.difference(&set);
                out.warnings.push(format!(
                    "step {step}: the contact set flips back and forth ({} nodes come in and {} go out between iterations): kept the last set solved; use more steps or a larger [contact] penalty",
                    joined.len(),
                    left.len()
                ));
                break;
            }
            if out.contact_iterations >= self.settings.max_iterations {
                out.warnings.push(format!(
                    "step {step}: the contact set did not settle in {} contact iterations: kept the last set solved; use more steps",
                    self.settings.max_iterations
                ));
                break;
            }
            seen.push(set);
            set = found;
        }
        self.active = set;
        self.expand_condensed();
        self.condensed_solved(step);
        self.finish(bodies, &forces, &offsets, step, out)
    }

    /// The contact force on each body DOF of every body from the contacts of `set`, N; and
    /// each contact evaluated.
    fn contact_forces(
        &mut self,
        bodies: &[Body],
        set: &ContactSet,
        offsets: &[Vector3<Real>],
    ) -> (Vec<Vec<Real>>, Vec<Evaluated>) {
        let mut f: Vec<Vec<Real>> = self.parts.iter().map(|p| vec![0.0; p.u.len()]).collect();
        let mut list = Vec::with_capacity(set.len());
        for c in &set.contacts {
            let x = self.position(bodies, c.body, c.node);
            let (depth, normal, nodes, penalty) = match c.with {
                Target::Obstacle(o) => {
                    let Some(p) = self.obstacles.project(o, &x, &offsets[o]) else {
                        continue;
                    };
                    (
                        p.depth,
                        p.normal,
                        vec![(c.body, c.node, 1.0)],
                        self.parts[c.body].penalty,
                    )
                }
                Target::Patch { body, patch } => {
                    let Some(surface) = self.patch_surfaces[body].as_ref() else {
                        continue;
                    };
                    let [a, b, cc] = surface.patches[patch];
                    let mut t = triangle_projection(
                        &x,
                        &self.position(bodies, body, a),
                        &self.position(bodies, body, b),
                        &self.position(bodies, body, cc),
                    );
                    if surface.is_open() {
                        // Pushed back to the side the node started the step on: behind the
                        // patch, the normal turns round and the depth is measured from there.
                        let side = Real::from(self.sides[body][c.body][c.node]);
                        t.normal = t.normal.map(|n| n * side);
                        t.depth *= side;
                    }
                    let penalty = Penalty {
                        stiffness: self.parts[c.body]
                            .penalty
                            .stiffness
                            .min(self.parts[body].penalty.stiffness),
                    };
                    (
                        t.depth,
                        t.normal,
                        vec![
                            (c.body, c.node, 1.0),
                            (body, a, -t.weights[0]),
                            (body, b, -t.weights[1]),
                            (body, cc, -t.weights[2]),
                        ],
                        penalty,
                    )
                }
                Target::Vertex { body, vertex } => {
                    let Some(surface) = self.surfaces[body].as_ref() else {
                        continue;
                    };
                    let (before, v) = surface.segment(surface.previous(vertex));
                    let (_, after) = surface.segment(vertex);
                    let corner = self.position(bodies, body, v);
                    let n = segment_projection(&x, &self.position(bodies, body, before), &corner)
                        .normal
                        .unwrap_or_default()
                        + segment_projection(&x, &corner, &self.position(bodies, body, after))
                            .normal
                            .unwrap_or_default();
                    let normal = (n.norm() > 0.0).then(|| n.normalize());
                    let depth = normal.map_or(0.0, |n| (corner - x).dot(&n));
                    let penalty = Penalty {
                        stiffness: self.parts[c.body]
                            .penalty
                            .stiffness
                            .min(self.parts[body].penalty.stiffness),
                    };
                    (
                        depth,
                        normal,
                        vec![(c.body, c.node, 1.0), (body, v, -1.0)],
                        penalty,
                    )
                }
                Target::Segment { body, segment } => {
                    let Some(surface) = self.surfaces[body].as_ref() else {
                        continue;
                    };
                    let (a, b) = surface.segment(segment);
                    let pa = self.position(bodies, body, a);
                    let pb = self.position(bodies, body, b);
                    let mut s = segment_projection(&x, &pa, &pb);
                    // Nearest to an end: that vertex is pressed, along the mean of the normals of
                    // its two segments (which of the two was found does not matter then).
                    let vertex = if s.t <= 0.0 {
                        let (before, _) = surface.segment(surface.previous(segment));
                        Some((pa, self.position(bodies, body, before), pa, pb))
                    } else if s.t >= 1.0 {
                        let (_, after) = surface.segment(surface.next(segment));
                        Some((pb, pa, pb, self.position(bodies, body, after)))
                    } else {
                        None
                    };
                    if let Some((corner, p0, p1, p2)) = vertex {
                        let n = segment_projection(&x, &p0, &p1).normal.unwrap_or_default()
                            + segment_projection(&x, &p1, &p2).normal.unwrap_or_default();
                        if n.norm() > 0.0 {
                            let n = n.normalize();
                            s.normal = Some(n);
                            s.depth = (corner - x).dot(&n);
                        }
                    }
                    let penalty = Penalty {
                        stiffness: self.parts[c.body]
                            .penalty
                            .stiffness
                            .min(self.parts[body].penalty.stiffness),
                    };
                    (
                        s.depth,
                        s.normal,
                        vec![
                            (c.body, c.node, 1.0),
                            (body, a, -(1.0 - s.t)),
                            (body, b, -s.t),
                        ],
                        penalty,
                    )
                }
            };
            let normal = match normal {
                Some(n) => {
                    self.normals.insert(*c, n);
                    Some(n)
                }
                None => self.normals.get(c).copied(),
            };
            if let Some(n) = normal {
                let force = penalty.force(depth, &n);
                for &(b, node, w) in &nodes {
                    let d = self.parts[b].dofs.dofs_per_node;
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
            });
        }
        (f, list)
    }

    /// The deformed position of `node` of body `b`, m.
    fn position(&self, bodies: &[Body], b: usize, node: usize) -> Vector3<Real> {
        let part = &self.parts[b];
        bodies[b].nodes[node] + node_vector(&part.u, part.dofs.dofs_per_node, node)
    }

    /// The out-of-balance force `F + f_c − f_int` at the free DOFs of all bodies (global
    /// order), N, and the force scale it is measured against: the largest of the applied,
    /// reaction and contact force norms.
    fn out_of_balance(
        &mut self,
        bodies: &[Body],
        set: &ContactSet,
        forces: &[Vec<Real>],
        offsets: &[Vector3<Real>],
    ) -> (Vec<Real>, Real) {
        let mut r = vec![0.0; self.system.n];
        let (mut applied, mut reacted, mut contact) = (0.0, 0.0, 0.0);
        let (all, _) = self.contact_forces(bodies, set, offsets);
        for ((b, body), fc) in bodies.iter().enumerate().zip(all) {
            let part = &self.parts[b];
            let internal = internal_force_vector(body, &part.u);
            let offset = self.system.offsets[b];
            for (i, &dof) in part.dofs.free.iter().enumerate() {
                r[offset + i] = forces[b][dof] + fc[dof] - internal[dof];
            }
            for &dof in &part.dofs.supported {
                reacted += (internal[dof] - forces[b][dof] - fc[dof]).powi(2);
            }
            applied += forces[b].iter().map(|f| f * f).sum::<Real>();
            contact += fc.iter().map(|f| f * f).sum::<Real>();
        }
        let scale = applied.sqrt().max(reacted.sqrt()).max(contact.sqrt());
        (r, scale.max(self.force_floor()))
    }

    /// Newton on all bodies with the contact set fixed. Returns the iterations and whether
    /// it converged; `false` after one stabilised move (the tangent is singular with this
    /// set: a body held only by contact that has not reached its contacts yet), so that the
    /// contacts are looked for again.
    fn newton(
        &mut self,
        bodies: &[Body],
        set: &ContactSet,
        forces: &[Vec<Real>],
        offsets: &[Vector3<Real>],
        step: usize,
    ) -> Result<(usize, bool), ContactError> {
        let (tolerance, max_iterations) = newton_limits(bodies);
        let mut history = Vec::new();
        let mut iterations = 0;
        let mut last_step = Real::INFINITY;
        let linear = bodies.iter().all(|b| !b.is_nonlinear());
        loop {
            let t = Instant::now();
            let (r, scale) = self.out_of_balance(bodies, set, forces, offsets);
            self.times.assembly += t.elapsed().as_secs_f64();
            let rnorm = norm(&r);
            let relative = if scale > 0.0 {
                rnorm / scale
            } else if rnorm > 0.0 {
                Real::INFINITY
            } else {
                0.0
            };
            history.push(relative);
            if !relative.is_finite() {
                return Err(ContactError::NotFinite { step });
            }
            // A correction that no longer moves anything (a rigid motion where nothing is
            // loaded leaves only round-off over round-off) has converged too.
            let u_norm = self
                .parts
                .iter()
                .map(|p| norm(&p.u).powi(2))
                .sum::<Real>()
                .sqrt();
            // Round-off floor: within 100× the tolerance (1e-8 by default, the bar of a
            // Newton step) and no longer falling, more iterations only stir round-off (seen:
            // 1.79e-10 held for 30 iterations when faer's parallel rounding fell that way).
            let stalled = history.len() >= 3
                && relative <= 100.0 * tolerance
                && relative >= 0.5 * history[history.len() - 2];
            if relative <= tolerance || stalled || (iterations > 0 && last_step <= 1e-12 * u_norm) {
                return Ok((iterations, true));
            }
            if iterations >= max_iterations {
                return Err(ContactError::NotConverged {
                    step,
                    iterations,
                    history,
                });
            }
            // Linear bodies with the same contacts keep their tangent but for the small turn of
            // the contact normals: reuse the factor (a modified Newton step) while it converges.
            let reuse = linear
                && self.factored.as_ref() == Some(set)
                && iterations > 0
                && history.len() >= 2
                && history[history.len() - 1] < 0.1 * history[history.len() - 2];
            let stabilised = if reuse {
                false
            } else {
                let stabilised = self.factorize_tangent(bodies, set, offsets)?;
                self.factored = (!stabilised).then(|| set.clone());
                stabilised
            };
            let t = Instant::now();
            let mut delta = r;
            self.system.solve_in_place(&mut delta);
            self.times.solve += t.elapsed().as_secs_f64();
            iterations += 1;
            if stabilised {
                // A body flying toward its contacts: move it at most `move_cap`, then look for
                // contacts again. A smaller correction (the singular direction is not loaded,
                // as the common sideways motion of two bodies pressed together) is a Newton step.
                let largest = self.largest_move(&delta);
                if largest > self.move_cap {
                    let base: Vec<Vec<Real>> = self.parts.iter().map(|p| p.u.clone()).collect();
                    self.move_free(&base, &delta, self.move_cap / largest);
                    return Ok((iterations, false));
                }
            }
            last_step = self.line_search(bodies, set, forces, offsets, &delta, rnorm);
        }
    }

    /// Fill the coupled tangent (members plus penalties) and factor it. When it is singular
    /// (a body not held by its supports and the contacts of `set`), factor it again with
    /// `STABILISATION` times its largest diagonal entry added to the diagonal and return true.
    fn factorize_tangent(
        &mut self,
        bodies: &[Body],
        set: &ContactSet,
        offsets: &[Vector3<Real>],
    ) -> Result<bool, ContactError> {
        let t = Instant::now();
        self.couple(bodies, set, offsets)?;
        for (part, body) in self.parts.iter_mut().zip(bodies) {
            fill_tangent(body, &part.assembly, &part.u, &mut part.local);
        }
        let locals: Vec<Vec<Real>> = self
            .parts
            .iter_mut()
            .map(|p| std::mem::take(&mut p.local))
            .collect();
        self.system.fill(&locals);
        for (part, local) in self.parts.iter_mut().zip(locals) {
            part.local = local;
        }
        let (_, list) = self.contact_forces(bodies, set, offsets);
        for e in &list {
            let Some(n) = e.normal else { continue };
            let k = e.penalty.stiffness(&n);
            for &(b1, node1, w1) in &e.nodes {
                for &(b2, node2, w2) in &e.nodes {
                    let (p1, p2) = (&self.parts[b1], &self.parts[b2]);
                    let d = p1.dofs.dofs_per_node.min(p2.dofs.dofs_per_node);
                    for p in 0..d {
                        for q in 0..d {
                            if let (Some(i), Some(j)) =
                                (p1.dofs.free_index(node1, p), p2.dofs.free_index(node2, q))
                            {
                                let (r, c) =
                                    (self.system.offsets[b1] + i, self.system.offsets[b2] + j);
                                self.system.add(r, c, w1 * w2 * k[(p, q)]);
                            }
                        }
                    }
                }
            }
        }
        self.times.assembly += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let mut result = self.system.factorize();
        let mut stabilised = false;
        if let Err(CholeskyError::NonPositivePivot { dof })
        | Err(CholeskyError::NearlySingular { dof, .. }) = result
        {
            let (b, _) = self.system.locate(dof);
            self.unheld = b;
            self.system.stabilise(STABILISATION);
            stabilised = true;
            result = self.system.factorize();
        }
        self.times.numeric += t.elapsed().as_secs_f64();
        match result {
            Ok(()) => Ok(stabilised),
            Err(other) => Err(ContactError::Factorization(other.to_string())),
        }
    }

    /// Make the coupled pattern hold the entries between the nodes of every contact of `set`
    /// (new contacts between bodies add entries: the pattern is rebuilt and analyzed again,
    /// keeping every entry added before so that a contact coming back costs nothing).
    fn couple(
        &mut self,
        bodies: &[Body],
        set: &ContactSet,
        offsets: &[Vector3<Real>],
    ) -> Result<(), ContactError> {
        let (_, list) = self.contact_forces(bodies, set, offsets);
        let mut missing = Vec::new();
        for e in list.iter().filter(|e| e.nodes.len() > 1) {
            for &(b1, n1, _) in &e.nodes {
                for &(b2, n2, _) in &e.nodes {
                    let (p1, p2) = (&self.parts[b1], &self.parts[b2]);
                    for p in 0..p1.dofs.dofs_per_node {
                        for q in 0..p2.dofs.dofs_per_node {
                            if let (Some(i), Some(j)) =
                                (p1.dofs.free_index(n1, p), p2.dofs.free_index(n2, q))
                            {
                                let (r, c) =
                                    (self.system.offsets[b1] + i, self.system.offsets[b2] + j);
                                if !self.system.contains(r, c) {
                                    missing.push((r.max(c), r.min(c)));
                                }
                            }
                        }
                    }
                }
            }
        }
        if missing.is_empty() {
            return Ok(());
        }
        let t = Instant::now();
        self.coupling.extend(missing);
        self.coupling.sort_unstable();
        self.coupling.dedup();
        let assemblies: Vec<&StiffnessAssembly> = self.parts.iter().map(|p| &p.assembly).collect();
        self.system = CoupledSystem::new(&assemblies, &self.node_offsets, &self.coupling)
            .map_err(|e| ContactError::Factorization(e.to_string()))?;
        self.times.symbolic += t.elapsed().as_secs_f64();
        Ok(())
    }

    /// The largest nodal length of a correction `delta` (global free DOFs), m.
    fn largest_move(&self, delta: &[Real]) -> Real {
        let mut largest: Real = 0.0;
        for (b, part) in self.parts.iter().enumerate() {
            let offset = self.system.offsets[b];
            let d = part.dofs.dofs_per_node;
            let mut moves = vec![0.0; part.u.len() / d.max(1)];
            for (i, &dof) in part.dofs.free.iter().enumerate() {
                moves[dof / d] += delta[offset + i] * delta[offset + i];
            }
            largest = moves.into_iter().map(Real::sqrt).fold(largest, Real::max);
        }
        largest
    }

    /// The name of the body whose tangent was singular last.
    fn moving_body(&self, bodies: &[Body]) -> String {
        bodies
            .get(self.unheld)
            .map_or_else(String::new, |b| b.name.clone())
    }

    /// Move the free DOFs by `s δ`, s = 1, 1/2, … 1/16: the first that lowers the
    /// out-of-balance norm (Armijo, 1e-4), else the best tried. Returns the length moved, m.
    fn line_search(
        &mut self,
        bodies: &[Body],
        set: &ContactSet,
        forces: &[Vec<Real>],
        offsets: &[Vector3<Real>],
        delta: &[Real],
        r0: Real,
    ) -> Real {
        let base: Vec<Vec<Real>> = self.parts.iter().map(|p| p.u.clone()).collect();
        let (s, accepted) = backtrack(r0, |s| {
            self.move_free(&base, delta, s);
            norm(&self.out_of_balance(bodies, set, forces, offsets).0)
        });
        if !accepted {
            self.move_free(&base, delta, s);
        }
        s * norm(delta)
    }

    fn move_free(&mut self, base: &[Vec<Real>], delta: &[Real], s: Real) {
        for (b, part) in self.parts.iter_mut().enumerate() {
            let offset = self.system.offsets[b];
            for (i, &dof) in part.dofs.free.iter().enumerate() {
                part.u[dof] = base[b][dof] + s * delta[offset + i];
            }
        }
    }

    /// For every open shell, the side of it each node of the other bodies is on at the last
    /// solved state (the start of the step). A node held by the shell keeps the side it had
    /// (its penalty leaves it a little on the far side); a node lying on the shell takes the
    /// side of the nodes it is joined to by members (a body resting on the shell is on the side
    /// of its other nodes); one whose neighbours lie on it too stays unknown and is not held.
    fn record_sides(&mut self, bodies: &[Body]) {
        let min_depth = MIN_DEPTH
            * self
                .parts
                .iter()
                .map(|p| p.tolerance)
                .fold(Real::INFINITY, Real::min);
        for shell in 0..self.patch_surfaces.len() {
            let Some(surface) = self.patch_surfaces[shell].as_ref().filter(|s| s.is_open()) else {
                continue;
            };
            let Some((mesh, _)) = surface.mesh(|n| self.position(bodies, shell, n)) else {
                continue;
            };
            let mut sides = std::mem::take(&mut self.sides[shell]);
            for (b, body) in bodies.iter().enumerate() {
                if b == shell {
                    continue;
                }
                let mut held = vec![false; body.nodes.len()];
                for c in &self.active.contacts {
                    if let (true, Target::Patch { body: t, .. }) = (c.body == b, c.with) {
                        if t == shell {
                            held[c.node] = true;
                        }
                    }
                }
                let signed: Vec<Real> = (0..body.nodes.len())
                    .map(|node| {
                        let x = self.position(bodies, b, node);
                        let s = surface.shell_side(&mesh, &x, |n| self.position(bodies, shell, n));
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
            self.sides[shell] = sides;
        }
    }

    /// Every node inside an obstacle or (2D) inside another body, with what it is deepest in.
    /// `found`, with a node that presses on a patch of the same body as in `solved` keeping the
    /// patch of `solved` while it still projects onto it or within `KEEP_PATCH` of it: a node
    /// on the edge between two patches (coincident faces of two boxes, sliding sideways by
    /// round-off as the bodies squeeze) is then not moved from one to the other at every
    /// query, which made the set flip back and forth. The force goes to the kept patch's nodes
    /// (equal and opposite all the same); on a curved surface the depth measured from the kept
    /// patch's plane differs by about (distance beyond its edge)² / radius.
    fn keep_patches(&self, bodies: &[Body], solved: &ContactSet, found: ContactSet) -> ContactSet {
        let before: HashMap<(usize, usize), Target> = solved
            .contacts
            .iter()
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
                self.position(bodies, body, a),
                self.position(bodies, body, b),
                self.position(bodies, body, cc),
            );
            let cross = (pb - pa).cross(&(pc - pa));
            let area2 = cross.norm();
            if area2.is_nan() || area2 <= 0.0 {
                continue;
            }
            let n = cross / area2;
            let x = self.position(bodies, c.body, c.node);
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

    fn query(&self, bodies: &[Body], offsets: &[Vector3<Real>]) -> ContactSet {
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
                        .map(|&n| self.position(bodies, b, n))
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
        let min_depth = MIN_DEPTH
            * self
                .parts
                .iter()
                .map(|p| p.tolerance)
                .fold(Real::INFINITY, Real::min);
        let meshes: Vec<_> = self
            .patch_surfaces
            .iter()
            .enumerate()
            .map(|(b, s)| {
                s.as_ref()
                    .and_then(|s| s.mesh(|n| self.position(bodies, b, n)))
            })
            .collect();
        let mut found = Vec::new();
        for (b, body) in bodies.iter().enumerate() {
            for node in 0..body.nodes.len() {
                let x = self.position(bodies, b, node);
                let mut deepest: Option<(Target, Real)> = None;
                let mut consider = |target: Target, depth: Real| {
                    if depth > min_depth && deepest.is_none_or(|(_, d)| depth > d) {
                        deepest = Some((target, depth));
                    }
                };
                for (o, offset) in offsets.iter().enumerate() {
                    if let Some(p) = self.obstacles.project(o, &x, offset) {
                        consider(Target::Obstacle(o), p.depth);
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
                    let distances: Vec<Real> = (0..points.len())
                        .map(|i| {
                            segment_projection(&x, &points[i], &points[(i + 1) % points.len()])
                                .distance
                        })
                        .collect();
                    let Some(i) =
                        (0..distances.len()).min_by(|&i, &j| distances[i].total_cmp(&distances[j]))
                    else {
                        continue;
                    };
                    // Equally near the segments on both sides of a vertex (a node on a symmetry
                    // line): press on the vertex, so that neither segment is favoured.
                    let n = points.len();
                    let tie = |j: usize| (distances[j] - distances[i]).abs() <= 1e-9 * distances[i];
                    let target = if tie((i + n - 1) % n) {
                        Target::Vertex {
                            body: other,
                            vertex: i,
                        }
                    } else if tie((i + 1) % n) {
                        Target::Vertex {
                            body: other,
                            vertex: (i + 1) % n,
                        }
                    } else {
                        Target::Segment {
                            body: other,
                            segment: i,
                        }
                    };
                    consider(target, distances[i]);
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
                        let s = surface.shell_side(mesh, &x, |n| self.position(bodies, other, n));
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
                if let Some((with, _)) = deepest {
                    found.push(ActiveContact {
                        body: b,
                        node,
                        with,
                    });
                }
            }
        }
        ContactSet::new(found)
    }

    /// The name of what a contact touches.
    fn target_name<'a>(&'a self, bodies: &'a [Body], with: Target) -> &'a str {
        match with {
            Target::Obstacle(o) => self.obstacles.name(o),
            Target::Segment { body, .. }
            | Target::Vertex { body, .. }
            | Target::Patch { body, .. } => &bodies[body].name,
        }
    }

    /// States, contacts and penetration of the settled step.
    fn finish(
        &mut self,
        bodies: &[Body],
        forces: &[Vec<Real>],
        offsets: &[Vector3<Real>],
        step: usize,
        mut out: ContactStep,
    ) -> Result<ContactStep, ContactError> {
        let set = self.active.clone();
        let (all, list) = self.contact_forces(bodies, &set, offsets);
        // Per body, per node touched: (what it touches, deepest depth, force received).
        let mut touched: Vec<Vec<NodeContact>> = vec![Vec::new(); bodies.len()];
        for e in &list {
            let name = self.target_name(bodies, e.contact.with).to_string();
            let force = e
                .normal
                .map_or(Vector3::zeros(), |n| e.penalty.force(e.depth, &n));
            out.max_penetration = out.max_penetration.max(e.depth);
            let part = &self.parts[e.contact.body];
            if e.depth > part.tolerance {
                out.warnings.push(format!(
                    "step {step}: node {} of body '{}' is {:.3e} m inside '{name}' (tolerance {:.3e} m): raise [contact] penalty",
                    e.contact.node + 1,
                    bodies[e.contact.body].name,
                    e.depth,
                    part.tolerance
                ));
            }
            for (k, &(b, node, w)) in e.nodes.iter().enumerate() {
                // The pressing node touches the target; a surface node touches the pressing body.
                let (with, depth) = if k == 0 {
                    (name.clone(), e.depth.max(0.0))
                } else {
                    (bodies[e.contact.body].name.clone(), 0.0)
                };
                let list = &mut touched[b];
                match list.iter_mut().find(|t| t.node == node && t.with == with) {
                    Some(t) => {
                        t.depth = t.depth.max(depth);
                        t.force += force * w;
                    }
                    None => list.push(NodeContact {
                        node,
                        with,
                        depth,
                        force: force * w,
                    }),
                }
            }
        }
        for ((b, body), fc) in bodies.iter().enumerate().zip(all) {
            let part = &self.parts[b];
            let d = part.dofs.dofs_per_node;
            let mut internal = internal_force_vector(body, &part.u);
            for (i, f) in internal.iter_mut().zip(&fc) {
                *i -= f;
            }
            let members = (0..body.members.len()).map(|m| {
                let r = member_response_at(body, &part.u, m);
                (r.strain, r.force)
            });
            let mut state = post_process(body, &part.dofs, &part.u, &forces[b], &internal, members);
            state.iterations = out.newton_iterations;
            // Relative to the contact forces too: a body held by contact alone has no reactions.
            // Relative to the largest of applied, reaction and contact forces (a body held by
            // contact alone has no reactions), and at least the force floor.
            let out_of_balance = part
                .dofs
                .free
                .iter()
                .map(|&dof| (internal[dof] - forces[b][dof]).powi(2))
                .sum::<Real>()
                .sqrt();
            let reacted = part
                .dofs
                .supported
                .iter()
                .map(|&dof| (internal[dof] - forces[b][dof]).powi(2))
                .sum::<Real>()
                .sqrt();
            let scale = norm(&forces[b])
                .max(reacted)
                .max(norm(&fc))
                .max(self.force_floor());
            state.residual = if scale > 0.0 {
                out_of_balance / scale
            } else {
                out_of_balance
            };
            if !state.residual.is_finite()
                || state
                    .displacements
                    .iter()
                    .any(|u| !u.iter().all(|c| c.is_finite()))
            {
                return Err(ContactError::NotFinite { step });
            }
            let mut contacts = std::mem::take(&mut touched[b]);
            for c in &mut contacts {
                for k in d..3 {
                    c.force[k] = 0.0;
                }
            }
            contacts.sort_by(|a, b| a.node.cmp(&b.node).then(a.with.cmp(&b.with)));
            let mut totals: Vec<(String, Vector3<Real>)> = Vec::new();
            for c in &contacts {
                match totals.iter_mut().find(|(with, _)| *with == c.with) {
                    Some((_, f)) => *f += c.force,
                    None => totals.push((c.with.clone(), c.force)),
                }
            }
            totals.sort_by(|a, b| a.0.cmp(&b.0));
            out.totals.push(totals);
            out.states.push(state);
            out.contacts.push(contacts);
        }
        Ok(out)
    }
}

/// The Newton tolerance of a contact scene (the smallest of the bodies', at most 1e-10) and the
/// iterations allowed per contact set (the largest of the bodies').
fn newton_limits(bodies: &[Body]) -> (Real, usize) {
    let tolerance = bodies
        .iter()
        .map(|b| b.newton.tolerance)
        .fold(Real::INFINITY, Real::min)
        .min(1e-10);
    let max_iterations = bodies
        .iter()
        .map(|b| b.newton.max_iterations)
        .max()
        .unwrap_or(30);
    (tolerance, max_iterations)
}
