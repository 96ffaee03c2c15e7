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

use crate::contact::coupled_system::CoupledSystem;
use crate::contact::{
    default_penalty, penetration_tolerance, ActiveContact, ContactError, ContactSet,
    ContactSettings, NodeContact, Obstacle, Obstacles, Penalty,
};
use crate::linkage::cholesky::CholeskyError;
use crate::linkage::{
    member_response, post_process, Body, DofMap, PathMethod, PhaseTimes, Schedule, SolveError,
    StepState, StiffnessAssembly,
};
use crate::Real;
use nalgebra::Vector3;
use std::collections::HashMap;
use std::time::Instant;

/// The stabilisation of a singular tangent, relative to its largest diagonal entry: small
/// enough that the stabilised matrix is still the tangent to 9 digits, large enough to factor.
pub const STABILISATION: Real = 1e-9;

/// A contact evaluated at the current displacements: depth (m) and outward normal.
type Evaluated = (ActiveContact, Real, Option<Vector3<Real>>);

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
}

/// All the bodies of a scene with contact, solved together step by step.
pub struct ContactSolver {
    parts: Vec<BodyPart>,
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
        let t = Instant::now();
        let assemblies: Vec<&StiffnessAssembly> = parts.iter().map(|p| &p.assembly).collect();
        let system = CoupledSystem::new(&assemblies, &node_offsets)
            .map_err(|e| ContactError::Factorization(e.to_string()))?;
        let times = PhaseTimes {
            assembly: assembly_time,
            symbolic: t.elapsed().as_secs_f64(),
            ..Default::default()
        };
        Ok(ContactSolver {
            parts,
            obstacles: Obstacles::new(obstacles),
            system,
            settings,
            active: ContactSet::default(),
            normals: HashMap::new(),
            step: 0,
            move_cap: bodies
                .iter()
                .filter(|b| !b.members.is_empty())
                .map(|b| 100.0 * penetration_tolerance(b))
                .fold(Real::INFINITY, Real::min),
            unheld: 0,
            times,
            query_seconds: 0.0,
        })
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
        if step == 0 || step < self.step {
            for p in &mut self.parts {
                p.u.iter_mut().for_each(|v| *v = 0.0);
            }
            self.active = ContactSet::default();
            self.normals.clear();
        }
        self.step = step;
        let offsets: Vec<Vector3<Real>> = obstacles.iter().map(|o| o.offset(step, steps)).collect();
        let forces: Vec<Vec<Real>> = bodies.iter().map(|b| loads_at(b, step, steps)).collect();
        for (part, body) in self.parts.iter_mut().zip(bodies) {
            let prescribed = prescribed_at(body, step, steps);
            for &dof in &part.dofs.supported {
                part.u[dof] = prescribed[dof];
            }
        }
        let mut set = self.active.clone();
        let mut seen: Vec<ContactSet> = Vec::new();
        let mut out = ContactStep::default();
        loop {
            out.contact_iterations += 1;
            let (iterations, settled) = self.newton(bodies, &set, &forces, &offsets, step)?;
            out.newton_iterations += iterations;
            out.stabilised |= !settled;
            let t = Instant::now();
            let found = self.query(bodies, &offsets);
            self.query_seconds += t.elapsed().as_secs_f64();
            if !settled {
                // A stabilised move toward the contacts: look again, no equilibrium yet.
                if out.contact_iterations >= self.settings.max_iterations {
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
        self.finish(bodies, &forces, &offsets, step, out)
    }

    /// The contact force on each body DOF of `body` (index `b`) from the contacts of `set`, N;
    /// also each contact's (depth, normal).
    fn contact_forces(
        &mut self,
        b: usize,
        body: &Body,
        set: &ContactSet,
        offsets: &[Vector3<Real>],
    ) -> (Vec<Real>, Vec<Evaluated>) {
        let part = &self.parts[b];
        let d = part.dofs.dofs_per_node;
        let mut f = vec![0.0; part.u.len()];
        let mut list = Vec::new();
        for c in set.contacts.iter().filter(|c| c.body == b) {
            let x = body.nodes[c.node] + node_vector(&part.u, d, c.node);
            let Some(p) = self.obstacles.project(c.obstacle, &x, &offsets[c.obstacle]) else {
                continue;
            };
            let normal = match p.normal {
                Some(n) => {
                    self.normals.insert(*c, n);
                    Some(n)
                }
                None => self.normals.get(c).copied(),
            };
            if let Some(n) = normal {
                let force = part.penalty.force(p.depth, &n);
                for k in 0..d {
                    f[c.node * d + k] += force[k];
                }
            }
            list.push((*c, p.depth, normal));
        }
        (f, list)
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
        for (b, body) in bodies.iter().enumerate() {
            let (fc, _) = self.contact_forces(b, body, set, offsets);
            let part = &self.parts[b];
            let internal = internal_forces(body, part.dofs.dofs_per_node, &part.u);
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
        (r, applied.sqrt().max(reacted.sqrt()).max(contact.sqrt()))
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
        let tolerance = bodies
            .iter()
            .map(|b| b.newton.tolerance)
            .fold(Real::INFINITY, Real::min)
            .min(1e-8);
        let max_iterations = bodies
            .iter()
            .map(|b| b.newton.max_iterations)
            .max()
            .unwrap_or(30);
        let mut history = Vec::new();
        let mut iterations = 0;
        let mut last_step = Real::INFINITY;
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
            if relative <= tolerance || (iterations > 0 && last_step <= 1e-12 * u_norm) {
                return Ok((iterations, true));
            }
            if iterations >= max_iterations {
                return Err(ContactError::NotConverged {
                    step,
                    iterations,
                    history,
                });
            }
            let stabilised = self.factorize_tangent(bodies, set, offsets)?;
            let t = Instant::now();
            let mut delta = r;
            self.system.solve_in_place(&mut delta);
            self.times.solve += t.elapsed().as_secs_f64();
            iterations += 1;
            if stabilised {
                let largest = self.largest_move(&delta);
                let s = if largest > self.move_cap {
                    self.move_cap / largest
                } else {
                    1.0
                };
                let base: Vec<Vec<Real>> = self.parts.iter().map(|p| p.u.clone()).collect();
                self.move_free(&base, &delta, s);
                return Ok((iterations, false));
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
        for (part, body) in self.parts.iter_mut().zip(bodies) {
            let d = part.dofs.dofs_per_node;
            let u = &part.u;
            part.assembly
                .fill(body, |m| member_tangent(body, d, u, m), &mut part.local);
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
        for (b, body) in bodies.iter().enumerate() {
            let (_, list) = self.contact_forces(b, body, set, offsets);
            let part = &self.parts[b];
            let d = part.dofs.dofs_per_node;
            let offset = self.system.offsets[b];
            for (c, _, normal) in list {
                let Some(n) = normal else { continue };
                let k = part.penalty.stiffness(&n);
                for p in 0..d {
                    for q in 0..d {
                        if let (Some(i), Some(j)) = (
                            part.dofs.free_index(c.node, p),
                            part.dofs.free_index(c.node, q),
                        ) {
                            self.system.add(offset + i, offset + j, k[(p, q)]);
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
        let mut best = (Real::INFINITY, 1.0);
        let mut s = 1.0;
        for _ in 0..5 {
            self.move_free(&base, delta, s);
            let (r, _) = self.out_of_balance(bodies, set, forces, offsets);
            let r = norm(&r);
            if r.is_finite() && r <= (1.0 - 1e-4 * s) * r0 {
                return s * norm(delta);
            }
            if r < best.0 {
                best = (r, s);
            }
            s *= 0.5;
        }
        let s = if best.0.is_finite() { best.1 } else { 1.0 };
        self.move_free(&base, delta, s);
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

    /// Every node inside an obstacle, with the obstacle it is deepest in.
    fn query(&self, bodies: &[Body], offsets: &[Vector3<Real>]) -> ContactSet {
        let mut found = Vec::new();
        for (b, (part, body)) in self.parts.iter().zip(bodies).enumerate() {
            let d = part.dofs.dofs_per_node;
            for (node, x0) in body.nodes.iter().enumerate() {
                let x = x0 + node_vector(&part.u, d, node);
                let mut deepest: Option<(usize, Real)> = None;
                for (o, offset) in offsets.iter().enumerate() {
                    if let Some(p) = self.obstacles.project(o, &x, offset) {
                        if p.depth > 0.0 && deepest.is_none_or(|(_, depth)| p.depth > depth) {
                            deepest = Some((o, p.depth));
                        }
                    }
                }
                if let Some((obstacle, _)) = deepest {
                    found.push(ActiveContact {
                        body: b,
                        node,
                        obstacle,
                    });
                }
            }
        }
        ContactSet::new(found)
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
        for (b, body) in bodies.iter().enumerate() {
            let (fc, list) = self.contact_forces(b, body, &set, offsets);
            let part = &self.parts[b];
            let d = part.dofs.dofs_per_node;
            let mut internal = internal_forces(body, d, &part.u);
            for (i, f) in internal.iter_mut().zip(&fc) {
                *i -= f;
            }
            let members = (0..body.members.len()).map(|m| {
                let r = response(body, d, &part.u, m);
                (r.strain, r.force)
            });
            let mut state = post_process(body, &part.dofs, &part.u, &forces[b], &internal, members);
            state.iterations = out.newton_iterations;
            // Relative to the contact forces too: a body held by contact alone has no reactions.
            let contact_norm = norm(&fc);
            if contact_norm > 0.0 && state.residual.is_finite() {
                let applied = norm(&forces[b]);
                let reacted = part
                    .dofs
                    .supported
                    .iter()
                    .map(|&dof| (internal[dof] - forces[b][dof]).powi(2))
                    .sum::<Real>()
                    .sqrt();
                let scale = applied.max(reacted);
                let out_of_balance = state.residual * scale;
                state.residual = out_of_balance / scale.max(contact_norm);
            }
            if !state.residual.is_finite()
                || state
                    .displacements
                    .iter()
                    .any(|u| !u.iter().all(|c| c.is_finite()))
            {
                return Err(ContactError::NotFinite { step });
            }
            let mut contacts = Vec::with_capacity(list.len());
            for (c, depth, normal) in list {
                let force = normal.map_or(Vector3::zeros(), |n| part.penalty.force(depth, &n));
                let mut force = force;
                for k in d..3 {
                    force[k] = 0.0;
                }
                out.max_penetration = out.max_penetration.max(depth);
                if depth > part.tolerance {
                    out.warnings.push(format!(
                        "step {step}: node {} of body '{}' is {depth:.3e} m inside obstacle '{}' (tolerance {:.3e} m): raise [contact] penalty",
                        c.node + 1,
                        body.name,
                        self.obstacles.name(c.obstacle),
                        part.tolerance
                    ));
                }
                contacts.push(NodeContact {
                    node: c.node,
                    with: self.obstacles.name(c.obstacle).to_string(),
                    depth: depth.max(0.0),
                    force,
                });
            }
            out.states.push(state);
            out.contacts.push(contacts);
        }
        Ok(out)
    }
}

fn node_vector(u: &[Real], d: usize, node: usize) -> Vector3<Real> {
    let mut v = Vector3::zeros();
    for k in 0..d {
        v[k] = u[node * d + k];
    }
    v
}

fn response(body: &Body, d: usize, u: &[Real], m: usize) -> crate::linkage::MemberResponse {
    let member = body.members[m];
    let [a, b] = member.nodes;
    member_response(
        body.kinematics,
        &body.materials[member.material],
        &body.nodes[a],
        &body.nodes[b],
        &node_vector(u, d, a),
        &node_vector(u, d, b),
    )
}

fn member_tangent(body: &Body, d: usize, u: &[Real], m: usize) -> nalgebra::Matrix3<Real> {
    response(body, d, u, m).tangent
}

/// Member forces per body DOF at `u`, N: member m pushes its ends with `∓N n`.
fn internal_forces(body: &Body, d: usize, u: &[Real]) -> Vec<Real> {
    let mut out = vec![0.0; body.dof_count()];
    for m in 0..body.members.len() {
        let r = response(body, d, u, m);
        let [a, b] = body.members[m].nodes;
        for k in 0..d {
            out[a * d + k] -= r.force * r.axis[k];
            out[b * d + k] += r.force * r.axis[k];
        }
    }
    out
}

/// Applied force per body DOF at `step` of `steps`, N.
fn loads_at(body: &Body, step: usize, steps: usize) -> Vec<Real> {
    let d = body.dimension.dofs_per_node();
    let mut f = vec![0.0; body.dof_count()];
    for l in &body.loads {
        let factor = l.schedule.factor(step, steps);
        for k in 0..d {
            f[l.node * d + k] += factor * l.force[k];
        }
    }
    f
}

/// Prescribed displacement per body DOF at `step`, m: grouped by schedule as the linear solve
/// does (within one schedule a later support's value replaces an earlier one's; schedules add).
fn prescribed_at(body: &Body, step: usize, steps: usize) -> Vec<Real> {
    let d = body.dimension.dofs_per_node();
    let mut patterns: Vec<(&Schedule, Vec<Real>)> = Vec::new();
    for s in &body.supports {
        if s.displacement == Vector3::zeros() {
            continue;
        }
        let p = match patterns.iter().position(|(sched, _)| *sched == &s.schedule) {
            Some(p) => p,
            None => {
                patterns.push((&s.schedule, vec![0.0; body.dof_count()]));
                patterns.len() - 1
            }
        };
        for k in 0..d {
            if s.fixed[k] {
                patterns[p].1[s.node * d + k] = s.displacement[k];
            }
        }
    }
    let mut u = vec![0.0; body.dof_count()];
    for (schedule, values) in patterns {
        let factor = schedule.factor(step, steps);
        for (a, b) in u.iter_mut().zip(values) {
            *a += factor * b;
        }
    }
    u
}

fn norm(v: &[Real]) -> Real {
    v.iter().map(|x| x * x).sum::<Real>().sqrt()
}
