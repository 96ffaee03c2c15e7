//! The coupled Newton of all bodies in contact: one sparse system of members and penalties, refactored per iteration (or kept while a linear model converges fast).

use crate::contact::body_part::{largest_nodal_move, BodyPart};
use crate::contact::coupled_iterative::CoupledIterative;
use crate::contact::coupled_system::CoupledSystem;
use crate::contact::evaluate::{Evaluated, Evaluation};
use crate::contact::problem::{Problem, LOADED_RIGID_MOTION, STABILISATION};
use crate::contact::{ActiveContact, ContactError, ContactSet};
use crate::linalg::{CholeskyError, LowRankCorrection, SparseColumn};
use crate::linkage::body_state::{fill_tangent, internal_force_vector, norm};
use crate::linkage::dynamics::InertiaTerm;
use crate::linkage::line_search::backtrack;
use crate::linkage::{add_follower_load_stiffness, pair_members};
use crate::linkage::{Body, Convergence, PhaseTimes, SolverUsed, StiffnessAssembly};
use crate::Real;
use nalgebra::Vector3;
use std::collections::HashMap;
use std::time::Instant;

/// The Newton of all bodies as one coupled sparse system (members plus penalties).
pub(crate) struct CoupledSolver {
    system: CoupledSystem,
    /// First global node of each body.
    node_offsets: Vec<usize>,
    /// Entries between bodies added to the coupled pattern so far (global free DOFs, r ≥ c).
    coupling: Vec<(usize, usize)>,
    /// The contact set the current factorization was made with (not stabilised).
    factored: Option<ContactSet>,
    /// The inertia coefficients per body it was made with (empty: a load step).
    factored_inertia: Vec<Real>,
    /// The body whose tangent was singular last (for messages).
    pub(crate) unheld: usize,
    /// Negative pivots of the last tangent factored (LDLᵀ; 0 when positive definite).
    pub(crate) negative_pivots: usize,
    /// Conjugate gradients, when a body is solved iteratively.
    iterative: Option<CoupledIterative>,
    /// Whether conjugate gradients could not serve an iteration and the coupled matrix was
    /// factored directly instead (the iterative bodies are then "iterative, then direct").
    fell_back: bool,
    /// The unsymmetric part of slipping contacts' tangents, `Σ u vᵀ` over global free DOFs,
    /// as filled with the tangent (solved by [`LowRankCorrection`] on the symmetric factor).
    rank_one: Vec<(SparseColumn, SparseColumn)>,
    /// The Woodbury correction of the current factorization for `rank_one`.
    correction: Option<LowRankCorrection>,
}

impl CoupledSolver {
    /// The coupled pattern of `parts`, analyzed (an empty system when `build` is false: the
    /// condensed path builds it only if it falls back). With `iterative` (a body solved by
    /// conjugate gradients) the pattern is analyzed only if a direct factorization is needed.
    pub(crate) fn new(
        parts: &[BodyPart],
        node_offsets: Vec<usize>,
        build: bool,
        iterative: Option<CoupledIterative>,
    ) -> Result<Self, ContactError> {
        let analyze = iterative.is_none();
        let system = if build {
            let assemblies: Vec<&StiffnessAssembly> = parts.iter().map(|p| &p.assembly).collect();
            CoupledSystem::new(&assemblies, &node_offsets, &[], analyze)
        } else {
            CoupledSystem::new(&[], &[], &[], analyze)
        }
        .map_err(ContactError::Factorization)?;
        Ok(CoupledSolver {
            system,
            node_offsets,
            coupling: Vec::new(),
            factored: None,
            factored_inertia: Vec::new(),
            unheld: 0,
            negative_pivots: 0,
            iterative,
            fell_back: false,
            rank_one: Vec::new(),
            correction: None,
        })
    }

    /// The coupled pattern of all bodies with the entries between bodies so far, analyzed.
    pub(crate) fn rebuild(&mut self, parts: &[BodyPart]) -> Result<(), ContactError> {
        let assemblies: Vec<&StiffnessAssembly> = parts.iter().map(|p| &p.assembly).collect();
        self.system = CoupledSystem::new(
            &assemblies,
            &self.node_offsets,
            &self.coupling,
            self.iterative.is_none(),
        )
        .map_err(ContactError::Factorization)?;
        self.factored = None;
        Ok(())
    }

    /// Drop the factored tangent kept for reuse: a body's members changed (a member broke),
    /// so the next iteration factors the tangent anew.
    pub(crate) fn forget_factor(&mut self) {
        self.factored = None;
    }

    /// [`CoupledSolver::rebuild`] after body `b`'s DOFs changed (a piece of it removed, or
    /// given back; `body` as it is now): the entries between bodies, in the old numbering, are
    /// dropped and found again as contacts need them; with conjugate gradients, the body's
    /// block preconditioner is built anew for its new rows.
    pub(crate) fn rebuild_renumbered(
        &mut self,
        parts: &[BodyPart],
        (b, body): (usize, &Body),
    ) -> Result<(), ContactError> {
        if let Some(iterative) = self.iterative.as_mut() {
            iterative.renumber(b, body, &parts[b].dofs, &parts[b].assembly);
        }
        self.coupling.clear();
        self.rebuild(parts)
    }

    /// Conjugate-gradient iterations so far (0 when every body is solved directly).
    pub(crate) fn linear_iterations(&self) -> usize {
        self.iterative.as_ref().map_or(0, |i| i.iterations)
    }

    /// The linear solver body `b`'s rows get.
    pub(crate) fn solver_used(&self, b: usize) -> SolverUsed {
        match &self.iterative {
            Some(i) if i.iterative.get(b).copied().unwrap_or(false) => {
                if self.fell_back {
                    SolverUsed::IterativeThenDirect
                } else {
                    SolverUsed::Iterative
                }
            }
            _ => SolverUsed::Direct,
        }
    }

    /// The out-of-balance force `F + f_c − f_int` at the free DOFs of all bodies (global
    /// order), N, for the contacts `evaluated` at the current displacements; and the force
    /// scale it is measured against: the largest of the applied, reaction and contact force
    /// norms, at least the force floor. Within a time step (`p.inertia`), the inertia force
    /// `c M (u − u*)` of each body ([`InertiaTerm`]) is taken off too, and its norm is one
    /// more force scale (a body in free flight has no other force).
    pub(crate) fn out_of_balance(
        &self,
        p: &Problem,
        parts: &[BodyPart],
        evaluated: &Evaluation,
    ) -> (Vec<Real>, Real) {
        let mut r = vec![0.0; self.system.n];
        let (mut applied, mut reacted, mut contact, mut inertial) = (0.0, 0.0, 0.0, 0.0);
        for ((b, body), fc) in p.bodies.iter().enumerate().zip(&evaluated.forces) {
            let part = &parts[b];
            let mut internal = internal_force_vector(body, &part.u);
            if let Some(term) = p.inertia.and_then(|i| i.get(b)) {
                let mut f = vec![0.0; internal.len()];
                term.add_force(&part.u, &mut f);
                inertial += f.iter().map(|f| f * f).sum::<Real>();
                for (i, f) in internal.iter_mut().zip(&f) {
                    *i += f;
                }
            }
            let offset = self.system.offsets[b];
            // Nodal loads, and following pressures on the faces deformed by `u`.
            let forces = p.applied(b, &part.u);
            for (i, &dof) in part.dofs.free.iter().enumerate() {
                r[offset + i] = forces[dof] + fc[dof] - internal[dof];
            }
            for &dof in &part.dofs.supported {
                reacted += (internal[dof] - forces[dof] - fc[dof]).powi(2);
            }
            applied += forces.iter().map(|f| f * f).sum::<Real>();
            contact += fc.iter().map(|f| f * f).sum::<Real>();
        }
        let scale = applied
            .sqrt()
            .max(reacted.sqrt())
            .max(contact.sqrt())
            .max(inertial.sqrt());
        (r, scale.max(p.force_floor))
    }

    /// Newton with the contact set of `p` fixed (see [`crate::contact::ContactSolver`]).
    pub(crate) fn newton(
        &mut self,
        p: &Problem,
        parts: &mut [BodyPart],
        normals: &mut HashMap<ActiveContact, Vector3<Real>>,
        times: &mut PhaseTimes,
    ) -> Result<(usize, bool), ContactError> {
        let mut monitor = Convergence::new(p.tolerance);
        let mut iterations = 0;
        let mut last_step = Real::INFINITY;
        let linear = p.bodies.iter().all(|b| !b.is_nonlinear());
        // The contacts and residual of the state the line search accepted (evaluated there).
        let mut pending = None;
        loop {
            let t = Instant::now();
            let (evaluated, r, scale) = match pending.take() {
                Some(e) => e,
                None => {
                    let evaluated = p.evaluate(normals, parts);
                    let (r, scale) = self.out_of_balance(p, parts, &evaluated);
                    (evaluated, r, scale)
                }
            };
            times.assembly += t.elapsed().as_secs_f64();
            let rnorm = norm(&r);
            let u_norm = parts
                .iter()
                .map(|p| norm(&p.u).powi(2))
                .sum::<Real>()
                .sqrt();
            if p.converged(&mut monitor, rnorm, scale, iterations, last_step, u_norm)? {
                return Ok((iterations, true));
            }
            // Linear bodies with the same contacts keep their tangent but for the small turn of
            // the contact normals: reuse the factor (a modified Newton step) while it converges.
            // Within a time step the factor of the last one serves from the first iteration
            // when the step size (the coefficient of `c M`) and the contact set are the same:
            // a body in free flight, or resting on a plane, is not refactored at every step.
            let same_tangent = linear
                && self.iterative.is_none()
                && self.factored.as_ref() == Some(p.set)
                && self.factored_inertia == inertia_coefficients(p);
            let reuse = same_tangent
                && if iterations == 0 {
                    p.inertia.is_some()
                } else {
                    monitor.converging_fast()
                };
            let (stabilised, delta) = if reuse {
                let t = Instant::now();
                let mut delta = r;
                self.solve_factored(&mut delta);
                times.solve += t.elapsed().as_secs_f64();
                (false, delta)
            } else {
                self.fill_tangent(p, parts, &evaluated.list, times)?;
                let t = Instant::now();
                let solved = self
                    .iterative
                    .as_mut()
                    .and_then(|it| it.solve(&self.system, p.set, &r, scale, 0.1 * p.tolerance));
                times.solve += t.elapsed().as_secs_f64();
                match solved {
                    Some(delta) => {
                        self.negative_pivots = 0;
                        (false, delta)
                    }
                    None => {
                        // Direct (conjugate gradients could not serve: a singular block).
                        self.fell_back |= self.iterative.is_some();
                        let stabilised = self.factorize_filled(p, times)?;
                        self.factored = (!stabilised).then(|| p.set.clone());
                        self.factored_inertia = inertia_coefficients(p);
                        let t = Instant::now();
                        self.correct_for_rank_one();
                        let mut delta = r;
                        self.solve_factored(&mut delta);
                        times.solve += t.elapsed().as_secs_f64();
                        (stabilised, delta)
                    }
                }
            };
            iterations += 1;
            if stabilised {
                // A body flying toward its contacts: move it at most the move cap, then look
                // for contacts again. A smaller correction (the singular direction is not
                // loaded, as the common sideways motion of two bodies pressed together) is a
                // Newton step.
                let largest = self.largest_move(parts, &delta);
                if let Some(s) = p.capped(largest) {
                    let base: Vec<Vec<Real>> = parts.iter().map(|p| p.u.clone()).collect();
                    self.move_free(parts, &base, &delta, s);
                    return Ok((iterations, false));
                }
            }
            // Move the free DOFs by `s δ` (Armijo backtracking on the out-of-balance norm).
            let base: Vec<Vec<Real>> = parts.iter().map(|p| p.u.clone()).collect();
            let mut last = None;
            let (s, accepted) = backtrack(rnorm, |s| {
                self.move_free(parts, &base, &delta, s);
                let evaluated = p.evaluate(normals, parts);
                let (r, scale) = self.out_of_balance(p, parts, &evaluated);
                let rnorm = norm(&r);
                last = Some((evaluated, r, scale));
                rnorm
            });
            if accepted {
                pending = last;
            } else {
                self.move_free(parts, &base, &delta, s);
                if stabilised && rnorm > LOADED_RIGID_MOTION * scale {
                    // A loaded rigid motion that no contact of this set holds (a body resting
                    // on a surface at a depth of round-off): moving it cannot reduce the
                    // residual with the set fixed. Look for contacts again.
                    return Ok((iterations, false));
                }
            }
            last_step = s * norm(&delta);
        }
    }

    /// Fill the coupled tangent: members plus the penalties of the contacts `evaluated`.
    fn fill_tangent(
        &mut self,
        p: &Problem,
        parts: &mut [BodyPart],
        evaluated: &[Evaluated],
        times: &mut PhaseTimes,
    ) -> Result<(), ContactError> {
        let t = Instant::now();
        self.couple(parts, evaluated, times)?;
        for (part, body) in parts.iter_mut().zip(p.bodies) {
            fill_tangent(body, &part.assembly, &part.u, &mut part.local);
            // A following pressure's load stiffness, as the body's own Newton takes it.
            if !body.pressures.is_empty() && body.newton.load_stiffness {
                add_follower_load_stiffness(
                    body,
                    (&part.dofs, &part.assembly, &pair_members(body)),
                    &part.u,
                    p.time,
                    &mut part.local,
                );
            }
        }
        let locals: Vec<Vec<Real>> = parts
            .iter_mut()
            .map(|p| std::mem::take(&mut p.local))
            .collect();
        self.system.fill(&locals);
        for (part, local) in parts.iter_mut().zip(locals) {
            part.local = local;
        }
        // Within a time step each body's tangent gains its `c M` (diagonal).
        if let Some(inertia) = p.inertia {
            for ((b, part), term) in parts.iter().enumerate().zip(inertia) {
                let offset = self.system.offsets[b];
                for (i, &dof) in part.dofs.free.iter().enumerate() {
                    let g = offset + i;
                    self.system.add(g, g, term.coefficient * term.mass[dof]);
                }
            }
        }
        self.rank_one.clear();
        for e in evaluated {
            let Some(k) = e.stiffness() else { continue };
            if let Some((a, b)) = e.rank_one() {
                let column = |v: &Vector3<Real>| {
                    let mut col = SparseColumn::new();
                    for &(body, node, w) in &e.nodes {
                        let part = &parts[body];
                        for q in 0..part.dofs.dofs_per_node {
                            if let Some(i) = part.dofs.free_index(node, q) {
                                col.push((self.system.offsets[body] + i, w * v[q]));
                            }
                        }
                    }
                    col
                };
                self.rank_one.push((column(&a), column(&b)));
            }
            for &(b1, node1, w1) in &e.nodes {
                for &(b2, node2, w2) in &e.nodes {
                    let (p1, p2) = (&parts[b1], &parts[b2]);
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
        times.assembly += t.elapsed().as_secs_f64();
        Ok(())
    }

    /// Form the Woodbury correction of the factored symmetric tangent for the unsymmetric
    /// part of slipping contacts (none when nothing slips).
    fn correct_for_rank_one(&mut self) {
        let pairs = std::mem::take(&mut self.rank_one);
        let system = &mut self.system;
        self.correction =
            LowRankCorrection::new(system.n, pairs, |b: &mut [Real]| system.solve_in_place(b));
    }

    /// Solve with the factored tangent, its unsymmetric slip part included.
    fn solve_factored(&mut self, rhs: &mut [Real]) {
        self.system.solve_in_place(rhs);
        if let Some(c) = &self.correction {
            c.correct(rhs);
        }
    }

    /// Factor the filled tangent. When it is singular (a body not held by its supports and the
    /// contacts), factor it again with `STABILISATION` times its largest diagonal entry added
    /// to the diagonal and return true. When that fails too, the tangent is indefinite (a body
    /// buckling under contact): LDLᵀ, its negative pivots counted.
    fn factorize_filled(
        &mut self,
        p: &Problem,
        times: &mut PhaseTimes,
    ) -> Result<bool, ContactError> {
        let t = Instant::now();
        let mut result = self.system.factorize();
        let mut stabilised = false;
        self.negative_pivots = 0;
        if let Err(CholeskyError::NonPositivePivot { dof })
        | Err(CholeskyError::NearlySingular { dof, .. }) = result
        {
            let (b, _) = self.system.locate(dof);
            self.unheld = b;
            let values = p
                .bodies
                .iter()
                .any(|b| b.is_nonlinear())
                .then(|| self.system.values.clone());
            self.system.stabilise(STABILISATION);
            stabilised = true;
            result = self.system.factorize();
            if let (Err(_), Some(values)) = (&result, values) {
                // Not merely singular: indefinite beyond the stabilisation.
                self.system.values = values;
                result = self.system.factorize_indefinite().map(|negative| {
                    self.negative_pivots = negative;
                });
                stabilised = false;
            }
        }
        times.numeric += t.elapsed().as_secs_f64();
        result.map_err(ContactError::Factorization)?;
        Ok(stabilised)
    }

    /// Make the coupled pattern hold the entries between the nodes of every contact
    /// `evaluated` (new contacts between bodies add entries: the pattern is rebuilt and
    /// analyzed again, keeping every entry added before so that a contact coming back costs
    /// nothing).
    fn couple(
        &mut self,
        parts: &[BodyPart],
        evaluated: &[Evaluated],
        times: &mut PhaseTimes,
    ) -> Result<(), ContactError> {
        let mut missing = Vec::new();
        for e in evaluated.iter().filter(|e| e.nodes.len() > 1) {
            for &(b1, n1, _) in &e.nodes {
                for &(b2, n2, _) in &e.nodes {
                    let (p1, p2) = (&parts[b1], &parts[b2]);
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
        self.rebuild(parts)?;
        times.symbolic += t.elapsed().as_secs_f64();
        Ok(())
    }

    /// The largest nodal length of a correction `delta` (global free DOFs), m.
    fn largest_move(&self, parts: &[BodyPart], delta: &[Real]) -> Real {
        let mut largest: Real = 0.0;
        for (b, part) in parts.iter().enumerate() {
            let offset = self.system.offsets[b];
            largest = largest.max(largest_nodal_move(part, |i| delta[offset + i]));
        }
        largest
    }

    /// Set the free DOFs to `base + s δ` (`delta` over global free DOFs, m).
    fn move_free(&self, parts: &mut [BodyPart], base: &[Vec<Real>], delta: &[Real], s: Real) {
        for (b, part) in parts.iter_mut().enumerate() {
            let offset = self.system.offsets[b];
            for (i, &dof) in part.dofs.free.iter().enumerate() {
                part.u[dof] = base[b][dof] + s * delta[offset + i];
            }
        }
    }
}

/// The inertia coefficient of each body in `p`, 1/s² (empty for a load step): a factor of the
/// tangent serves another iteration only with the same ones.
fn inertia_coefficients(p: &Problem) -> Vec<Real> {
    p.inertia
        .map(|i| i.iter().map(|t: &InertiaTerm| t.coefficient).collect())
        .unwrap_or_default()
}
