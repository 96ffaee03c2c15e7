//! The condensed Newton of the settle loop when every body is linear: on the contact candidates only, each body factored once per run.

use crate::contact::body_part::{largest_nodal_move, BodyPart};
use crate::contact::condensed::anderson::Anderson;
use crate::contact::condensed::{
    approximate_from, exact_for, CondenseFailure, CondensedBody, ContactJacobian, ContactRow,
    Correction, FrictionRow, NOT_CANDIDATE,
};
use crate::contact::detect::widen;
use crate::contact::evaluate::friction_key;
use crate::contact::problem::{Problem, LOADED_RIGID_MOTION, STABILISATION};
use crate::contact::{
    ActiveContact, ContactError, ContactSet, FrictionHistory, FrictionKey, SlipState,
};
use crate::linkage::body_state::norm;
use crate::linkage::line_search::backtrack;
use crate::linkage::{Body, Convergence, Mechanism, PhaseTimes};
use crate::Real;
use nalgebra::Vector3;
use rayon::prelude::*;
use std::collections::{HashMap, HashSet};
use std::time::Instant;

/// A linear body's condensed state within the settle loop.
struct Condensation {
    body: CondensedBody,
    /// Contact forces assumed at the candidate slots, N.
    fhat: Vec<Real>,
    /// Rigid-motion amplitudes, m.
    alpha: Vec<Real>,
    /// The step's load per free DOF, N, and `K⁻¹` of it at the candidates, m.
    load: Vec<Real>,
    base: Vec<Real>,
    /// Body displacements of the last full solve, m, and the amplitudes then.
    expanded: Vec<Real>,
    alpha_expanded: Vec<Real>,
    /// Load plus contact forces per free DOF at the last full solve, N.
    rhs_expanded: Vec<Real>,
    /// The pseudo-time aimed at (step units) and the number of steps (the load of a body
    /// condensed again).
    step: (Real, usize),
    /// The last two solved increments: (pseudo-time, f̂, α), oldest first (the next increment
    /// starts from their extrapolation).
    history: Vec<(Real, Vec<Real>, Vec<Real>)>,
    /// Whether the bodies' displacements are those of the last full solve (no placement since).
    fresh: bool,
}

impl Condensation {
    fn new(body: CondensedBody, dofs: usize) -> Self {
        let r = body.modes.len();
        Condensation {
            fhat: vec![0.0; body.len()],
            alpha: vec![0.0; r],
            load: Vec::new(),
            base: vec![0.0; body.len()],
            expanded: vec![0.0; dofs],
            alpha_expanded: vec![0.0; r],
            rhs_expanded: vec![0.0; body.slot.len()],
            history: Vec::new(),
            step: (0.0, 1),
            fresh: false,
            body,
        }
    }
}

/// One body's condensed state at the last converged increment (see [`CondensedState`]).
struct SavedCondensation {
    fhat: Vec<Real>,
    alpha: Vec<Real>,
    expanded: Vec<Real>,
    alpha_expanded: Vec<Real>,
    rhs_expanded: Vec<Real>,
    /// Candidate DOFs then (a body condensed again since cannot take the saved forces).
    candidates: usize,
}

/// The condensed state a failed increment is undone to: per body the contact forces and
/// rigid amplitudes assumed, and the last full solve.
pub(crate) struct CondensedState {
    bodies: Vec<SavedCondensation>,
}

/// The residuals of the condensed problem at one placement.
struct Residual {
    /// Per body, contact force found minus assumed at the candidates, N.
    phi1: Vec<Vec<Real>>,
    /// Per body, the out-of-balance along its rigid motions, N.
    phi2: Vec<Vec<Real>>,
    /// Their norm, N.
    norm: Real,
    /// The force scale (applied and contact forces, at least the force floor), N.
    scale: Real,
    /// The contact rows at the placement.
    rows: Vec<ContactRow>,
    /// The friction contacts at the placement (empty without friction).
    friction: Vec<FrictionState>,
}

/// A friction contact's answer at one placement, for the holding of reversed contacts.
struct FrictionState {
    key: FrictionKey,
    /// The direction of its tangential force (unit; zero without one).
    direction: Vector3<Real>,
    /// Whether it slips.
    slipping: bool,
    /// Whether it sticks with a tangential force beyond μ f_N (only a held contact can).
    beyond: bool,
}

/// Newton with contacts held sticking (see [`FrictionHistory::held`]), against the flipping
/// of contacts between sticking and slipping that stalls Newton at a shear's onset: a contact
/// is held when Newton's full step turns its tangential force by more than a right angle and
/// makes it slip, or when it turns from sticking to slipping a second time. (Holding every
/// contact at a step's start, an elastic predictor, was tried and made more steps need a
/// cut.) When Newton has converged so, the held contacts beyond μ f_N are let go (they slip)
/// and Newton goes on. Converged only with every held contact
/// within μ f_N, where the return mapping sticks too: the answer is that of the exact law.
struct Holding {
    /// The history the contacts are evaluated against, with the held contacts.
    history: FrictionHistory,
    /// How often each contact was held in this solve.
    count: HashMap<FrictionKey, usize>,
    /// How often held contacts were let go in this solve.
    releases: usize,
}

/// Whether each contact not held slipped at the last iterate, and how often it has turned from
/// sticking to slipping or back since it was last let go.
#[derive(Default)]
struct Flips {
    slipped: HashMap<FrictionKey, bool>,
    flips: HashMap<FrictionKey, usize>,
}

/// How often one contact may be held within a Newton solve.
const MOST_HOLDS: usize = 2;

/// How often held contacts may be let go within a Newton solve; beyond, every contact follows
/// the exact law at every iterate.
const MOST_RELEASES: usize = 8;

/// The Newton of the contact problem on the bodies' contact candidates, every body linear and
/// factored once per run (see [`CondensedBody`] and [`ContactJacobian`]).
pub(crate) struct CondensedSolver {
    bodies: Vec<Condensation>,
    /// The factored Jacobian of the condensed contact problem and the set it was made for.
    jacobian: Option<(ContactSet, ContactJacobian)>,
    /// Whether slipping contacts' rows follow their slip (`slip_axes`): the last placement had
    /// [`approximate_from`] rows or more (where a Jacobian may take their tangents
    /// approximately, diagonal in these axes).
    follow_slip: bool,
}

impl CondensedSolver {
    /// Condense every body on the nodes of `marks`; `None` if one cannot be (the coupled solve
    /// then), with the mechanism found if that was why.
    pub(crate) fn build(
        bodies: &[Body],
        parts: &[BodyPart],
        marks: Vec<Vec<bool>>,
        times: &mut PhaseTimes,
    ) -> (Option<Self>, Option<Box<Mechanism>>) {
        // The bodies are condensed side by side: much of a body's set-up (its symbolic
        // analysis, the factorization's many small supernodes) runs on one thread, so another
        // body's work fills the other core. Each body's arithmetic is the same as alone (the
        // METIS calls take turns, see `linalg::ordering`).
        let results: Vec<Result<CondensedBody, CondenseFailure>> = bodies
            .par_iter()
            .zip(parts)
            .zip(marks)
            .map(|((body, part), mark)| CondensedBody::new(body, &part.dofs, &part.assembly, mark))
            .collect();
        let mut built = Vec::with_capacity(bodies.len());
        // The first body (in order) that cannot be condensed decides, as one at a time did.
        for (body, result) in bodies.iter().zip(results) {
            match result {
                Ok(c) => {
                    add_seconds(times, &c);
                    built.push(Condensation::new(c, body.dof_count()));
                }
                Err(CondenseFailure::Mechanism(m)) => return (None, Some(m)),
                Err(CondenseFailure::Other) => return (None, None),
            }
        }
        let solver = CondensedSolver {
            bodies: built,
            jacobian: None,
            follow_slip: false,
        };
        (Some(solver), None)
    }

    /// Contact candidates of `body` (nodes).
    pub(crate) fn candidates(&self, body: usize) -> Option<usize> {
        let c = self.bodies.get(body)?;
        Some(c.body.nodes.iter().filter(|&&m| m).count())
    }

    /// Start a step (`restart`: from rest, forgetting the solved increments).
    pub(crate) fn start_step(&mut self, restart: bool) {
        if !restart {
            return;
        }
        for c in self.bodies.iter_mut() {
            c.fhat.iter_mut().for_each(|v| *v = 0.0);
            c.alpha.iter_mut().for_each(|v| *v = 0.0);
            c.alpha_expanded.iter_mut().for_each(|v| *v = 0.0);
            c.expanded.iter_mut().for_each(|v| *v = 0.0);
            c.rhs_expanded.iter_mut().for_each(|v| *v = 0.0);
            c.history.clear();
        }
    }

    /// Aim the next increment at pseudo-time `t` of `steps` (step units, fractional within a
    /// cut step): each body's load and base displacement there. The contact forces and rigid
    /// amplitudes start from the straight line through the last two solved increments when
    /// `t` lies no further beyond the newer than the two lie apart (exact for loads that grow
    /// in proportion while the contacts stay): Newton then only corrects.
    pub(crate) fn aim(&mut self, t: Real, steps: usize) {
        for c in self.bodies.iter_mut() {
            if let [(t0, f0, a0), (t1, f1, a1)] = &c.history[..] {
                let (t0, t1) = (*t0, *t1);
                if t0 < t1
                    && t > t1
                    && t - t1 <= (t1 - t0) * (1.0 + 1e-12)
                    && f1.len() == c.fhat.len()
                {
                    // Lagrange weights of the two points at t (2 and -1 for whole steps).
                    let w0 = (t - t1) / (t0 - t1);
                    let w1 = (t - t0) / (t1 - t0);
                    for (v, (x1, x0)) in c.fhat.iter_mut().zip(f1.iter().zip(f0)) {
                        *v = w1 * x1 + w0 * x0;
                    }
                    for (v, (x1, x0)) in c.alpha.iter_mut().zip(a1.iter().zip(a0)) {
                        *v = w1 * x1 + w0 * x0;
                    }
                }
            }
            let (load, base) = c.body.load_at(t, steps);
            c.load = load;
            c.base = base;
            c.fresh = false;
            c.step = (t, steps);
        }
    }

    /// Remember the solved state at pseudo-time `t` for the next increment's start.
    pub(crate) fn solved(&mut self, t: Real) {
        for c in self.bodies.iter_mut() {
            if c.history.len() == 2 {
                c.history.remove(0);
            }
            c.history.push((t, c.fhat.clone(), c.alpha.clone()));
        }
    }

    /// The condensed state of the last converged increment, to undo a failed one with
    /// [`CondensedSolver::restore`].
    pub(crate) fn saved(&self) -> CondensedState {
        CondensedState {
            bodies: self
                .bodies
                .iter()
                .map(|c| SavedCondensation {
                    fhat: c.fhat.clone(),
                    alpha: c.alpha.clone(),
                    expanded: c.expanded.clone(),
                    alpha_expanded: c.alpha_expanded.clone(),
                    rhs_expanded: c.rhs_expanded.clone(),
                    candidates: c.body.len(),
                })
                .collect(),
        }
    }

    /// Undo a failed increment: back to `saved` (the kept Jacobian, made at the failed
    /// attempt's placements, is dropped). `false` when a body's candidates grew since (its
    /// saved forces no longer fit): the caller then leaves the condensed path.
    pub(crate) fn restore(&mut self, saved: CondensedState) -> bool {
        if saved
            .bodies
            .iter()
            .zip(&self.bodies)
            .any(|(s, c)| s.candidates != c.body.len())
        {
            return false;
        }
        for (c, s) in self.bodies.iter_mut().zip(saved.bodies) {
            c.fhat = s.fhat;
            c.alpha = s.alpha;
            c.expanded = s.expanded;
            c.alpha_expanded = s.alpha_expanded;
            c.rhs_expanded = s.rhs_expanded;
            c.fresh = false;
        }
        self.jacobian = None;
        true
    }

    /// Write the condensed state into the bodies' displacements: exact at the candidates,
    /// the last full solve plus the rigid motion since elsewhere.
    fn place(&mut self, parts: &mut [BodyPart]) {
        // The bodies side by side (each body's compliance product reads its whole dense
        // compliance); each body's arithmetic is the same as alone.
        parts
            .par_iter_mut()
            .zip(self.bodies.par_iter_mut())
            .for_each(|(part, c)| {
                c.fresh = false;
                let moved: Vec<Real> = c
                    .alpha
                    .iter()
                    .zip(&c.alpha_expanded)
                    .map(|(a, b)| a - b)
                    .collect();
                let rigid = moved.iter().any(|&a| a != 0.0);
                for (i, &dof) in part.dofs.free.iter().enumerate() {
                    if c.body.slot[i] == NOT_CANDIDATE {
                        let mut u = c.expanded[dof];
                        if rigid {
                            u += c
                                .body
                                .modes
                                .iter()
                                .zip(&moved)
                                .map(|(r, a)| a * r[i])
                                .sum::<Real>();
                        }
                        part.u[dof] = u;
                    }
                }
                let mut u = c.body.comply(&c.fhat);
                for (s, v) in u.iter_mut().enumerate() {
                    *v += c.base[s]
                        + c.body
                            .modes_c
                            .iter()
                            .zip(&c.alpha)
                            .map(|(r, a)| a * r[s])
                            .sum::<Real>();
                }
                for (s, &i) in c.body.cand.iter().enumerate() {
                    part.u[part.dofs.free[i]] = u[s];
                }
            });
    }

    /// The full displacement of every body (one solve each), kept for the next placements.
    /// The dense compliance places the candidates to its own round-off (which grows with the
    /// condition of the body's stiffness); the difference to the solve is folded into the
    /// base displacement so that later placements reproduce the solve exactly. Returns that
    /// difference as a force, the largest stiffness times the largest difference, relative to
    /// the largest load or contact force norm of a body (0 when nothing changed). The
    /// candidates keep their placed values, so the contact forces are Newton's; the difference
    /// only unbalances the members next to them.
    pub(crate) fn expand(&mut self, parts: &mut [BodyPart], times: &mut PhaseTimes) -> Real {
        let t = Instant::now();
        if self.bodies.iter().all(|c| c.fresh) {
            return 0.0;
        }
        // One solve per body, the bodies side by side.
        let each: Vec<(Real, Real)> = parts
            .par_iter_mut()
            .zip(self.bodies.par_iter_mut())
            .map(|(part, c)| {
                let mut differs: Real = 0.0;
                c.fresh = true;
                let mut rhs = c.load.clone();
                for (s, &i) in c.body.cand.iter().enumerate() {
                    rhs[i] += c.fhat[s];
                }
                let change: Vec<Real> = rhs
                    .iter()
                    .zip(&c.rhs_expanded)
                    .map(|(a, b)| a - b)
                    .collect();
                let dalpha: Vec<Real> = c
                    .alpha
                    .iter()
                    .zip(&c.alpha_expanded)
                    .map(|(a, b)| a - b)
                    .collect();
                let du = c.body.expand(&change, &dalpha);
                let u: Vec<Real> = part
                    .dofs
                    .free
                    .iter()
                    .zip(&du)
                    .map(|(&dof, d)| c.expanded[dof] + d)
                    .collect();
                c.rhs_expanded = rhs;
                // The candidates keep their placed values: the contact forces were balanced
                // there, and a penalty turns a last-bit difference of a position into a force.
                let largest = norm(&c.load).max(norm(&c.fhat));
                for (s, &i) in c.body.cand.iter().enumerate() {
                    let placed = part.u[part.dofs.free[i]];
                    differs = differs.max(c.body.stiffness * (u[i] - placed).abs());
                    c.base[s] += u[i] - placed;
                }
                for (i, &dof) in part.dofs.free.iter().enumerate() {
                    if c.body.slot[i] == NOT_CANDIDATE {
                        part.u[dof] = u[i];
                    }
                }
                // The next solve adds to the solved displacement (placed values aside).
                c.expanded.clone_from(&part.u);
                for &i in &c.body.cand {
                    c.expanded[part.dofs.free[i]] = u[i];
                }
                c.alpha_expanded.clone_from(&c.alpha);
                (differs, largest)
            })
            .collect();
        let differs = each.iter().map(|e| e.0).fold(0.0, Real::max);
        let largest = each.iter().map(|e| e.1).fold(0.0, Real::max);
        times.solve += t.elapsed().as_secs_f64();
        if largest > 0.0 {
            differs / largest
        } else {
            0.0
        }
    }

    /// Residuals of the condensed problem at the current placement (see [`Residual`]), the
    /// contacts evaluated once there. `Err` with the (body, node) pairs a contact reaches
    /// outside the candidates.
    fn residual(
        &mut self,
        p: &Problem,
        parts: &mut [BodyPart],
        normals: &mut HashMap<ActiveContact, Vector3<Real>>,
    ) -> Result<Residual, Vec<(usize, usize)>> {
        self.place(parts);
        let evaluated = p.evaluate(normals, parts);
        let fc = &evaluated.forces;
        let mut missing = Vec::new();
        let mut rows = Vec::with_capacity(evaluated.list.len());
        let mut friction = Vec::new();
        for e in &evaluated.list {
            let Some(n) = e.normal else { continue };
            if let (Some(t), Some(h)) = (&e.tangential, p.friction) {
                let (key, _) = friction_key(&e.contact);
                let limit = h.law(&key).0 * e.normal_force().max(0.0);
                let size = t.force.norm();
                friction.push(FrictionState {
                    key,
                    direction: if size > 0.0 { t.force / size } else { t.force },
                    slipping: t.state == SlipState::Slip,
                    beyond: t.state == SlipState::Stick && size > limit,
                });
            }
            let row = |direction: &Vector3<Real>, missing: &mut Vec<(usize, usize)>| {
                let mut entries = Vec::with_capacity(12);
                for &(b, node, w) in &e.nodes {
                    let dofs = &parts[b].dofs;
                    for k in 0..dofs.dofs_per_node {
                        if let Some(i) = dofs.free_index(node, k) {
                            match self.bodies[b].body.slot[i] {
                                NOT_CANDIDATE => missing.push((b, node)),
                                s => entries.push((b, s, w * direction[k])),
                            }
                        }
                    }
                }
                entries
            };
            let (Some(stiffness), Some(tangential)) = (e.stiffness(), &e.tangential) else {
                let entries = row(&n, &mut missing);
                if !entries.is_empty() && e.penalty.stiffness > 0.0 {
                    rows.push(ContactRow {
                        penalty: e.penalty.stiffness,
                        entries,
                        friction: None,
                    });
                }
                continue;
            };
            // With friction: a row along the normal and one along each tangent direction. A
            // sticking contact's stiffness is `k_n` along its normal and `k_t` along its
            // tangents; a slipping one's is the whole block (unsymmetric), kept in Cartesian
            // form so that a Jacobian kept for later iterations can turn it into its own axes.
            let slipping = (tangential.state == SlipState::Slip).then(|| {
                let mut k3 = stiffness;
                if let Some((a, b)) = e.rank_one() {
                    k3 += a * b.transpose();
                }
                k3
            });
            // A slipping contact's tangent rows follow its slip (see `slip_axes`).
            let dims = parts[e.contact.body].dofs.dofs_per_node;
            let axes = match slipping {
                Some(_) if self.follow_slip => slip_axes(&n, &tangential.force, dims),
                _ => contact_axes(&n, dims),
            };
            let (key, _) = friction_key(&e.contact);
            let first = rows.len();
            let mut added = Vec::with_capacity(axes.len());
            for axis in &axes {
                added.push(row(axis, &mut missing));
            }
            if added.iter().all(|r| r.is_empty()) {
                continue;
            }
            for (i, (entries, axis)) in added.into_iter().zip(&axes).enumerate() {
                rows.push(ContactRow {
                    penalty: if i == 0 {
                        e.penalty.stiffness
                    } else {
                        tangential.stick_stiffness
                    },
                    entries,
                    friction: Some(FrictionRow {
                        first,
                        count: axes.len(),
                        axis: *axis,
                        slipping,
                        contact: Some(key),
                    }),
                });
            }
        }
        self.follow_slip = rows.len() >= approximate_from();
        if !missing.is_empty() {
            missing.sort_unstable();
            missing.dedup();
            return Err(missing);
        }
        let (mut sum, mut applied, mut contact) = (0.0, 0.0, 0.0);
        let mut phi1 = Vec::with_capacity(self.bodies.len());
        let mut phi2 = Vec::with_capacity(self.bodies.len());
        for (b, c) in self.bodies.iter().enumerate() {
            let free = &parts[b].dofs.free;
            let p1: Vec<Real> = c
                .body
                .cand
                .iter()
                .zip(&c.fhat)
                .map(|(&i, f)| fc[b][free[i]] - f)
                .collect();
            let p2: Vec<Real> = c
                .body
                .modes
                .iter()
                .zip(&c.body.modes_c)
                .map(|(r, rc)| {
                    r.iter().zip(&c.load).map(|(a, l)| a * l).sum::<Real>()
                        + rc.iter().zip(&c.fhat).map(|(a, f)| a * f).sum::<Real>()
                })
                .collect();
            sum += p1.iter().chain(&p2).map(|v| v * v).sum::<Real>();
            applied += p.forces[b].iter().map(|f| f * f).sum::<Real>();
            contact += fc[b].iter().map(|f| f * f).sum::<Real>();
            phi1.push(p1);
            phi2.push(p2);
        }
        let scale = applied.sqrt().max(contact.sqrt()).max(p.force_floor);
        Ok(Residual {
            phi1,
            phi2,
            norm: sum.sqrt(),
            scale,
            rows,
            friction,
        })
    }

    /// The condensed state as one vector, in [`flatten`]'s layout.
    fn state(&self) -> Vec<Real> {
        let forces = self.bodies.iter().flat_map(|c| c.fhat.iter());
        forces
            .chain(self.bodies.iter().flat_map(|c| c.alpha.iter()))
            .copied()
            .collect()
    }

    /// Set the condensed state to `base` plus `s` times a correction.
    fn apply(&mut self, base: &[(Vec<Real>, Vec<Real>)], corr: &Correction, s: Real) {
        for ((c, (f0, a0)), (df, da)) in self
            .bodies
            .iter_mut()
            .zip(base)
            .zip(corr.fhat.iter().zip(&corr.alpha))
        {
            for (v, (x, d)) in c.fhat.iter_mut().zip(f0.iter().zip(df)) {
                *v = x + s * d;
            }
            for (v, (x, d)) in c.alpha.iter_mut().zip(a0.iter().zip(da)) {
                *v = x + s * d;
            }
        }
    }

    /// The displacements at every body's candidates as placed, m.
    fn candidate_displacements(&self, parts: &[BodyPart]) -> Vec<Vec<Real>> {
        self.bodies
            .iter()
            .zip(parts)
            .map(|(c, part)| {
                c.body
                    .cand
                    .iter()
                    .map(|&i| part.u[part.dofs.free[i]])
                    .collect()
            })
            .collect()
    }

    /// The largest nodal displacement at the candidates, m.
    fn candidate_norm(&self, parts: &[BodyPart]) -> Real {
        let mut largest: Real = 0.0;
        for (c, part) in self.bodies.iter().zip(parts) {
            for &i in &c.body.cand {
                largest = largest.max(part.u[part.dofs.free[i]].abs());
            }
        }
        largest
    }

    /// The largest nodal move of a correction at the candidates and, rigidly, anywhere, m.
    fn largest_move(&self, parts: &[BodyPart], corr: &Correction) -> Real {
        let mut largest: Real = 0.0;
        for ((c, part), (df, da)) in self
            .bodies
            .iter()
            .zip(parts)
            .zip(corr.fhat.iter().zip(&corr.alpha))
        {
            let flexible = c.body.comply(df);
            let moved = |i: usize| {
                let mut m: Real = c.body.modes.iter().zip(da).map(|(r, a)| a * r[i]).sum();
                if c.body.slot[i] != NOT_CANDIDATE {
                    m += flexible[c.body.slot[i]];
                }
                m
            };
            largest = largest.max(largest_nodal_move(part, moved));
        }
        largest
    }

    /// Add the nodes in `missing` (and two rings of neighbours) to their bodies' candidates and
    /// condense those bodies again. `false` if one cannot be condensed.
    fn grow(
        &mut self,
        bodies: &[Body],
        parts: &[BodyPart],
        missing: &[(usize, usize)],
        times: &mut PhaseTimes,
    ) -> bool {
        for (b, body) in bodies.iter().enumerate() {
            if !missing.iter().any(|&(mb, _)| mb == b) {
                continue;
            }
            let mut mark = self.bodies[b].body.nodes.clone();
            for &(_, node) in missing.iter().filter(|&&(mb, _)| mb == b) {
                mark[node] = true;
            }
            widen(body, &mut mark, 2);
            let part = &parts[b];
            let Ok(grown) = CondensedBody::new(body, &part.dofs, &part.assembly, mark) else {
                return false;
            };
            add_seconds(times, &grown);
            let c = &mut self.bodies[b];
            let mut fhat = vec![0.0; grown.len()];
            for (s, &i) in c.body.cand.iter().enumerate() {
                fhat[grown.slot[i]] = c.fhat[s];
            }
            c.fhat = fhat;
            c.history.clear();
            c.fresh = false;
            c.body = grown;
            let (load, base) = c.body.load_at(c.step.0, c.step.1);
            c.load = load;
            c.base = base;
        }
        true
    }

    /// Newton on the candidates with the contact set of `p` fixed: `Some` with the iterations
    /// and whether it converged (`false` after one stabilised move, as the coupled Newton);
    /// `None` when a body cannot be condensed on the nodes the contacts reach (the caller then
    /// solves coupled from the displacements left in `parts`). The factored Jacobian of a set
    /// is kept for the next call with the same set (the next step, or a refinement after the
    /// full solve).
    pub(crate) fn newton(
        &mut self,
        p: &Problem,
        parts: &mut [BodyPart],
        normals: &mut HashMap<ActiveContact, Vector3<Real>>,
        times: &mut PhaseTimes,
    ) -> Result<Option<(usize, bool)>, ContactError> {
        // A large set's Jacobian with friction is kept across contact sets too: the rows of
        // contacts that come or go are taken into its factor (see `ContactJacobian::adopt`).
        let mut jacobian = self
            .jacobian
            .take()
            .filter(|(s, j)| s == p.set || carries(j))
            .map(|(_, j)| j);
        let result = self.newton_with(p, parts, normals, times, &mut jacobian);
        self.jacobian = jacobian.map(|j| (p.set.clone(), j));
        result
    }

    fn newton_with(
        &mut self,
        p: &Problem,
        parts: &mut [BodyPart],
        normals: &mut HashMap<ActiveContact, Vector3<Real>>,
        times: &mut PhaseTimes,
        jacobian: &mut Option<ContactJacobian>,
    ) -> Result<Option<(usize, bool)>, ContactError> {
        let stabilisation = STABILISATION
            * parts
                .iter()
                .map(|p| p.penalty.stiffness)
                .fold(0.0, Real::max);
        let tolerance = p.tolerance;
        let mut monitor = Convergence::new(tolerance);
        let mut iterations = 0;
        let mut last_step = Real::INFINITY;
        let fresh = self.bodies.iter().all(|c| c.fresh);
        // The residual of the state the line search accepted (evaluated there already).
        let mut pending = None;
        // Slow iterations (see `FRICTION_SLOW_ITERATIONS`) with the kept friction Jacobian.
        let mut slow = 0;
        let mut holding = p.friction.map(|h| Holding {
            history: FrictionHistory {
                held: HashSet::new(),
                ..h.clone()
            },
            count: HashMap::new(),
            releases: 0,
        });
        let mut flips = Flips::default();
        // Whether the last correction came from a kept Jacobian with friction, and whether
        // one was formed afresh at an apparent floor already.
        let (mut kept_friction, mut refreshed) = (false, false);
        // Anderson mixing of the kept approximate factor's iteration (large sets only).
        let fitted: usize = self.bodies.iter().map(|c| c.fhat.len()).sum();
        let mut mixing = Anderson::new(MIXING_DEPTH, fitted);

        // Iterations since the held contacts last changed (the law Newton solves changed).
        let mut counted = 0;
        // A frictionless Newton that converged only linearly with a factor formed afresh keeps
        // that factor and mixes its iterates (see [`CHORD_RATE`]).
        let mut chord = false;
        loop {
            // The problem with the held contacts, as they are now.
            let q = match &holding {
                Some(h) => Problem {
                    friction: Some(&h.history),
                    ..*p
                },
                None => Problem { ..*p },
            };
            let p = &q;
            let t = Instant::now();
            let evaluated = match pending.take() {
                Some(e) => Ok(e),
                None => self.residual(p, parts, normals),
            };
            times.assembly += t.elapsed().as_secs_f64();
            let residual = match evaluated {
                Ok(e) => e,
                Err(missing) => {
                    if !missing.is_empty() && self.grow(p.bodies, parts, &missing, times) {
                        *jacobian = None;
                        continue;
                    }
                    // A body could not be condensed again: the coupled solve from here.
                    return Ok(None);
                }
            };
            // With friction: contacts to hold from this iterate on (those that turned from
            // sticking to slipping and back, then once more), and the iterate solved again
            // with them held.
            if let Some(h) = holding.as_ref() {
                let hold = to_hold(h, &flips, &residual.friction);
                if !hold.is_empty() {
                    if let Some(h) = holding.as_mut() {
                        for k in hold {
                            h.history.held.insert(k);
                            *h.count.entry(k).or_default() += 1;
                            flips.slipped.remove(&k);
                            flips.flips.remove(&k);
                        }
                    }
                    monitor = Convergence::new(tolerance);
                    mixing.reset();
                    counted = 0;
                    last_step = Real::INFINITY;
                    continue;
                }
            }
            if let Some(h) = holding.as_ref() {
                for f in residual.friction.iter() {
                    if h.history.held.contains(&f.key) {
                        continue;
                    }
                    if let Some(was) = flips.slipped.insert(f.key, f.slipping) {
                        if was != f.slipping {
                            *flips.flips.entry(f.key).or_default() += 1;
                        }
                    }
                }
            }
            let size = self.candidate_norm(parts);
            let mut converged = p.converged(
                &mut monitor,
                residual.norm,
                residual.scale,
                counted,
                last_step,
                size,
            )?;
            // A kept Jacobian with friction converges linearly (see `FrictionInverse`), which
            // can look like the round-off floor: above [`FLOOR_CHECKED`] tolerances, one more
            // iteration with a fresh Jacobian decides.
            if converged
                && kept_friction
                && !refreshed
                && monitor
                    .last()
                    .is_some_and(|r| r > FLOOR_CHECKED * tolerance)
                && jacobian.as_ref().is_some_and(|j| j.has_friction())
            {
                refreshed = true;
                *jacobian = None;
                converged = false;
            }
            // Large sets (a kept approximate factor): held contacts beyond μ f_N are let go
            // once the residual is below [`LOOSE_RELEASE`] tolerances, not at convergence (each
            // round of letting go starts the residual again near 1e-3; the last round still
            // converges to the tolerance, so the answer is the exact law's).
            let loose = !converged
                && jacobian.as_ref().is_some_and(|j| j.is_approximate())
                && monitor
                    .last()
                    .is_some_and(|r| r < LOOSE_RELEASE * tolerance)
                && residual.friction.iter().any(|f| f.beyond);
            if converged || loose {
                let beyond: Vec<FrictionKey> = residual
                    .friction
                    .iter()
                    .filter(|f| f.beyond)
                    .map(|f| f.key)
                    .collect();
                if !beyond.is_empty() {
                    // Converged with held contacts beyond μ f_N: they slip, Newton goes on.
                    if let Some(h) = holding.as_mut() {
                        h.releases += 1;
                        if h.releases > MOST_RELEASES {
                            h.history.held.clear();
                        }
                        for k in &beyond {
                            h.history.held.remove(k);
                        }
                    }
                    monitor = Convergence::new(tolerance);
                    mixing.reset();
                    counted = 0;
                    last_step = Real::INFINITY;
                    continue;
                }
                if iterations == 0 && fresh {
                    // Nothing moved: the displacements are still those of the last solve.
                    self.bodies.iter_mut().for_each(|c| c.fresh = true);
                }
                return Ok(Some((iterations, true)));
            }
            let t = Instant::now();
            let views: Vec<&CondensedBody> = self.bodies.iter().map(|c| &c.body).collect();
            // Modified Newton: keep the factored Jacobian while it converges fast (the contacts'
            // normals and weights move little within one contact set).
            // Near the round-off floor the Jacobian's age no longer matters.
            // A Jacobian carried over from an earlier call is tried once.
            let near_floor = monitor.last().is_some_and(|r| r < 1e3 * p.tolerance);
            let fast = monitor.len() < 2 || monitor.converging_fast() || near_floor;
            // With friction the kept Jacobian is a modified Newton's in the slipping
            // contacts' tangents (see `FrictionInverse`): a steady linear rate is fast enough.
            let steady = monitor.history.len() >= 2 && {
                let h = &monitor.history;
                h[h.len() - 1] < FRICTION_STEADY_RATE * h[h.len() - 2]
            };
            // A chord that no longer brings the residual down is given up for a fresh factor.
            if chord && {
                let h = &monitor.history;
                h.len() >= 2 && h[h.len() - 1] > CHORD_RATE * h[h.len() - 2]
            } {
                chord = false;
            }
            let mut reuse = jacobian.as_ref().is_some_and(|j: &ContactJacobian| {
                j.rows().len() == residual.rows.len() && (fast || chord)
            });
            // With friction, contacts that start or stop slipping change only the contacts'
            // stiffness: taken into the kept Jacobian (a Schur complement on the slipping
            // rows), its `G C Gᵀ` and factor are formed again only after slow iterations.
            if let Some(j) = jacobian.as_mut().filter(|j| j.has_friction()) {
                if !(fast || steady && j.is_approximate()) {
                    slow += 1;
                }
                // While Newton converges fast and no contact starts or stops slipping, the
                // slipping contacts' stiffnesses are kept too (their Schur complement costs
                // the cube of their rows).
                reuse = slow < slow_limit(j)
                    && ((fast && j.same_states(&residual.rows))
                        || j.restiffen(&views, &residual.rows)
                        || j.adopt(&views, &residual.rows, fast));
            }
            let fresh_factor = !reuse;
            if !reuse {
                slow = 0;
                mixing.reset();
                // Many friction rows: the slipping contacts' tangents approximately (their
                // exact Schur complement would cost more than the factor, see
                // `FrictionInverse`); few: exactly, Newton's quadratic convergence.
                let exact = exact_for(&residual.rows);
                *jacobian = ContactJacobian::new(&views, residual.rows, stabilisation, exact).ok();
                // Formed afresh where Newton already converged slowly: the frozen-normal
                // tangent itself is off, so the next ones would be no better (see
                // [`CHORD_RATE`]).
                chord = monitor.len() >= 2
                    && !fast
                    && residual.friction.is_empty()
                    && jacobian.as_ref().is_some_and(|j| !j.has_friction());
            }
            let Some(jac) = jacobian.as_ref() else {
                return Ok(self.fall_back(parts, times));
            };
            kept_friction = reuse && jac.is_approximate();
            let t_jac = t.elapsed().as_secs_f64();
            let corr = jac.correction(&views, &residual.phi1, &residual.phi2);
            let t_corr = t.elapsed().as_secs_f64() - t_jac;
            let rel = residual.norm / residual.scale;
            let nrows = jac.rows().len();
            let approx = jac.is_approximate();
            let base: Vec<(Vec<Real>, Vec<Real>)> = self
                .bodies
                .iter()
                .map(|c| (c.fhat.clone(), c.alpha.clone()))
                .collect();
            times.solve += t.elapsed().as_secs_f64();
            iterations += 1;
            counted += 1;
            if corr.stabilised
                && !p.set.is_empty()
                && self.bodies.iter().any(|c| c.body.modes.len() > 1)
            {
                // A body with several free rigid motions that its contacts leave one of free:
                // the coupled solve moves it (here its stabilised moves and the contacts they
                // find repeat without end: a cube pushed along a floor, tests/friction.rs).
                return Ok(self.fall_back(parts, times));
            }
            if corr.stabilised {
                if let Some(s) = p.capped(self.largest_move(parts, &corr)) {
                    self.apply(&base, &corr, s);
                    self.place(parts);
                    return Ok(Some((iterations, false)));
                }
            }
            let before = self.candidate_displacements(parts);
            // A kept approximate factor (large sets) or a chord: the Anderson-mixed step,
            // taken when the exact residual falls with it; else the plain correction and a new
            // history.
            let mut mixed = false;
            if jac.is_approximate() || chord {
                let x = self.state();
                let g = flatten(&corr);
                if let Some(d) = mixing.step(&x, &g) {
                    let step = unflatten(&d, &corr);
                    self.apply(&base, &step, 1.0);
                    match self.residual(p, parts, normals) {
                        Ok(trial) if trial.norm <= (1.0 - 1e-4) * residual.norm => {
                            pending = Some(trial);
                            mixed = true;
                        }
                        _ => {
                            mixing.reset();
                            mixing.step(&x, &g);
                            self.apply(&base, &corr, 0.0);
                        }
                    }
                }
            }
            let (mut s, mut evals) = (1.0, 0);
            let t_ls = Instant::now();
            if !mixed {
                // With friction, Newton's full step is looked at first: contacts whose tangential
                // force it turns back and makes slip are held sticking, and the iteration is made
                // again from the same iterate with them held.
                let mut full = None;
                if holding.is_some() && !residual.friction.is_empty() {
                    self.apply(&base, &corr, 1.0);
                    let trial = self.residual(p, parts, normals).ok();
                    let reversed = match (&trial, &holding) {
                        (Some(trial), Some(h)) => reversals(h, &residual.friction, &trial.friction),
                        _ => Vec::new(),
                    };
                    if !reversed.is_empty() {
                        if let Some(h) = holding.as_mut() {
                            for k in reversed {
                                h.history.held.insert(k);
                                *h.count.entry(k).or_default() += 1;
                            }
                        }
                        self.apply(&base, &corr, 0.0);
                        monitor = Convergence::new(tolerance);
                        mixing.reset();
                        counted = 0;
                        last_step = Real::INFINITY;
                        continue;
                    }
                    full = trial;
                }
                // The residual of the accepted trial is the next iteration's: kept, not recomputed.
                let mut last = None;
                let (s_taken, accepted) = backtrack(residual.norm, |s| {
                    evals += 1;
                    if s == 1.0 {
                        if let Some(e) = full.take() {
                            last = Some(e);
                            return last.as_ref().map_or(Real::INFINITY, |e| e.norm);
                        }
                    }
                    self.apply(&base, &corr, s);
                    last = self.residual(p, parts, normals).ok();
                    last.as_ref().map_or(Real::INFINITY, |e| e.norm)
                });
                s = s_taken;
                if accepted {
                    pending = last;
                } else {
                    self.apply(&base, &corr, s);
                    self.place(parts);
                    if corr.stabilised && rel > LOADED_RIGID_MOTION {
                        // A loaded rigid motion that no contact of this set holds (a body
                        // resting on a surface at a depth of round-off): moving it cannot
                        // reduce the residual with the set fixed. Look for contacts again.
                        return Ok(Some((iterations, false)));
                    }
                }
            }
            #[cfg(test)]
            RECORD.with(|r| {
                r.borrow_mut().push(Recorded {
                    approximate: approx,
                    relative: rel,
                    mixed,
                })
            });
            if trace() {
                eprintln!(
                    "friction-trace it {iterations} rel {rel:.3e} rows {nrows} fresh {fresh_factor} approx {approx} jac {t_jac:.3} corr {t_corr:.3} ls {:.3} evals {evals} step {s} mixed {mixed} depth {}",
                    t_ls.elapsed().as_secs_f64(),
                    mixing.len()
                );
            }
            last_step = before
                .iter()
                .zip(self.candidate_displacements(parts))
                .flat_map(|(a, b)| {
                    a.iter()
                        .zip(b)
                        .map(|(x, y)| (x - y).abs())
                        .collect::<Vec<_>>()
                })
                .fold(0.0, Real::max);
        }
    }

    /// Leave the condensed path: the full displacements into `parts` (`None`: solve coupled).
    fn fall_back(
        &mut self,
        parts: &mut [BodyPart],
        times: &mut PhaseTimes,
    ) -> Option<(usize, bool)> {
        self.expand(parts, times);
        None
    }
}

/// Whether a Jacobian is kept for another contact set: with friction, from
/// [`approximate_from`] rows (below, the exact path forms one per set, as it always has).
fn carries(j: &ContactJacobian) -> bool {
    j.has_friction() && j.rows().len() >= approximate_from()
}

/// A frictionless condensed Newton that converges only linearly with a factor formed afresh
/// keeps that factor and mixes its iterates ([`Anderson`]): a chord with mixing instead of a
/// factor per iteration. A chord whose residual falls by less than this factor an iteration
/// is given up for a fresh factor.
///
/// Why Newton converges only linearly there: the Jacobian takes each contact's normal and the
/// weights of its patch's corners as fixed over an iteration (`k n nᵀ` over the weights, see
/// `contact::evaluate`): it leaves out the penalty force turning with the patch and sliding over its corners, whose stiffness is of the
/// order of the contact force over a member's length. Where that force is of the order of the
/// members' `E A` (soft bodies pressed hard) and the surfaces are convex (two balls pressed pole
/// to pole: the left-out stiffness lowers the sideways stiffness of the contact), Newton
/// converges only linearly however fresh its factor: a rate of 0.4 (a ball pushed onto another
/// by 200 N) to 0.97 (two balls pressed 5 mm onto each other: 3e-8 to 1.3e-8 in 30 iterations,
/// above the stall bound, the step given up at every cut). The few directions the tangent gets
/// wrong are what the mixing of the last iterates fits (a secant model of them): 9 iterations
/// for the pushed ball, and the pressed balls converge (tests/contact_balls.rs).
const CHORD_RATE: Real = 0.99;

/// Tolerances below which a large set's held contacts beyond μ f_N are let go (see the
/// Newton loop), before convergence.
const LOOSE_RELEASE: Real = 1e4;

/// Iterations Anderson mixing looks back over (see [`Anderson`]).
const MIXING_DEPTH: usize = 8;

/// A correction as one vector: every body's forces, then every body's amplitudes.
fn flatten(c: &Correction) -> Vec<Real> {
    c.fhat.iter().chain(&c.alpha).flatten().copied().collect()
}

/// A vector of [`flatten`]'s layout as a correction shaped like `like`.
fn unflatten(v: &[Real], like: &Correction) -> Correction {
    let mut at = 0;
    let mut take = |n: usize| {
        let part = v[at..at + n].to_vec();
        at += n;
        part
    };
    let fhat = like.fhat.iter().map(|f| take(f.len())).collect();
    let alpha = like.alpha.iter().map(|a| take(a.len())).collect();
    Correction {
        fhat,
        alpha,
        stabilised: like.stabilised,
    }
}

/// One condensed Newton iteration as the tests see it.
#[cfg(test)]
#[derive(Clone, Copy, Debug)]
pub(crate) struct Recorded {
    /// Whether the correction came from an approximate factor (the large-set mode).
    pub approximate: bool,
    /// The relative residual at the iterate corrected.
    pub relative: Real,
    /// Whether the step taken was Anderson-mixed.
    pub mixed: bool,
}

#[cfg(test)]
thread_local! {
    static RECORD: std::cell::RefCell<Vec<Recorded>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// The iterations recorded on this thread since the last call.
#[cfg(test)]
pub(crate) fn take_record() -> Vec<Recorded> {
    RECORD.with(|r| std::mem::take(&mut *r.borrow_mut()))
}

/// Whether `LINKAGE_TRACE_FRICTION` is set: each condensed Newton iteration is printed.
pub(crate) fn trace() -> bool {
    static TRACE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *TRACE.get_or_init(|| std::env::var_os("LINKAGE_TRACE_FRICTION").is_some())
}

/// Contacts flipping between sticking and slipping this often are held sticking.
const FLIPS_TO_HOLD: usize = 3;

/// The contacts of the iterate `at` to hold sticking: those not held that slip again after
/// [`FLIPS_TO_HOLD`] − 1 turns between sticking and slipping, each held fewer than
/// [`MOST_HOLDS`] times.
fn to_hold(h: &Holding, flips: &Flips, at: &[FrictionState]) -> Vec<FrictionKey> {
    if h.releases > MOST_RELEASES {
        return Vec::new();
    }
    at.iter()
        .filter(|f| {
            !h.history.held.contains(&f.key)
                && h.count.get(&f.key).copied().unwrap_or(0) < MOST_HOLDS
                && f.slipping
                && flips.slipped.get(&f.key) == Some(&false)
                && flips.flips.get(&f.key).copied().unwrap_or(0) + 1 >= FLIPS_TO_HOLD
        })
        .map(|f| f.key)
        .collect()
}

/// The contacts of `trial` (Newton's full step from the iterate of `at`) to hold sticking:
/// not held yet, held fewer than [`MOST_HOLDS`] times, slipping at the trial with their
/// tangential force turned by more than a right angle from the iterate's.
fn reversals(h: &Holding, at: &[FrictionState], trial: &[FrictionState]) -> Vec<FrictionKey> {
    let before: HashMap<FrictionKey, &Vector3<Real>> =
        at.iter().map(|f| (f.key, &f.direction)).collect();
    trial
        .iter()
        .filter(|f| {
            f.slipping
                && h.releases <= MOST_RELEASES
                && !h.history.held.contains(&f.key)
                && h.count.get(&f.key).copied().unwrap_or(0) < MOST_HOLDS
                && before
                    .get(&f.key)
                    .is_some_and(|d| d.dot(&f.direction) < 0.0)
        })
        .map(|f| f.key)
        .collect()
}

/// Slow iterations (a residual not below a tenth of the one before) a Jacobian with friction
/// is kept for, its contacts' stiffnesses brought up to date, before it is formed again.
const FRICTION_SLOW_ITERATIONS: usize = 3;

/// Slow iterations a kept approximate factor (large sets) is kept for: it is kept across
/// contact sets too, and its iterations (20-50 ms at full size) cost a twentieth of a fresh
/// factor, so it is given more of them. Measured on `bench_contact --friction` (full size, load
/// 5-6): 3, 6 and 10 made 10, 7 and 5 fresh factors in steps 1-4, 35.9, 27.5 and 28.2 s.
const FRICTION_SLOW_APPROXIMATE: usize = 10;

/// How many slow iterations the kept Jacobian `j` is kept for.
fn slow_limit(j: &ContactJacobian) -> usize {
    if j.is_approximate() {
        FRICTION_SLOW_APPROXIMATE
    } else {
        FRICTION_SLOW_ITERATIONS
    }
}

/// A friction Newton that seems to stall above this many tolerances with a kept Jacobian is
/// given a fresh one first (the 20,000-node pair's floor is about 10 tolerances).
const FLOOR_CHECKED: Real = 30.0;

/// The residual ratio between iterations below which a kept Jacobian with friction counts
/// as converging (its slipping contacts' tangents are those of its factorization).
const FRICTION_STEADY_RATE: Real = 0.5;

/// Add a condensation's analysis, factorization and solve times to `times`.
fn add_seconds(times: &mut PhaseTimes, c: &CondensedBody) {
    times.symbolic += c.seconds[0];
    times.numeric += c.seconds[1];
    times.solve += c.seconds[2];
}

/// The directions of a slipping contact's rows: its normal `n`, its tangential force's
/// direction (from `force`, N), then in 3D the direction across both; those of
/// [`contact_axes`] when the force has no tangential direction. In these axes the slip tangent
/// is diagonal but for its coupling `μ k_n t nᵀ` (see `FrictionInverse`'s reference).
fn slip_axes(n: &Vector3<Real>, force: &Vector3<Real>, d: usize) -> Vec<Vector3<Real>> {
    let along = force - n * n.dot(force);
    let size = along.norm();
    if !(size > 0.0 && size.is_finite()) {
        return contact_axes(n, d);
    }
    let t = along / size;
    if d < 3 {
        return vec![*n, t];
    }
    vec![*n, t, n.cross(&t)]
}

/// The directions of a friction contact's rows: its normal `n`, then an orthonormal basis of
/// the tangent plane (one direction in 2D, `d` = 2 DOFs per node; two in 3D).
fn contact_axes(n: &Vector3<Real>, d: usize) -> Vec<Vector3<Real>> {
    if d < 3 {
        return vec![*n, Vector3::new(-n.y, n.x, 0.0)];
    }
    // The coordinate axis least along n starts the tangent basis.
    let (mut least, mut axis) = (Real::INFINITY, 0);
    for k in 0..3 {
        if n[k].abs() < least {
            least = n[k].abs();
            axis = k;
        }
    }
    let t1 = (Vector3::ith(axis, 1.0) - n * n[axis]).normalize();
    let t2 = n.cross(&t1);
    vec![*n, t1, t2]
}
