//! The settle loop's Newton iteration when every body is linear: on the contact candidates
//! only, with each body factored once per run (see [`crate::contact::condensed`]).

use super::{newton_limits, ContactSolver, STABILISATION};
use crate::contact::boundary::Surface;
use crate::contact::condensed::{
    CondenseFailure, CondensedBody, ContactJacobian, ContactRow, Correction, NOT_CANDIDATE,
};
use crate::contact::patch_surface::PatchSurface;
use crate::contact::{penetration_tolerance, ContactError, ContactSet, Obstacles};
use crate::linkage::line_search::backtrack;
use crate::linkage::{Body, DofMap, StiffnessAssembly};
use crate::Real;
use nalgebra::Vector3;
use rayon::prelude::*;
use std::time::Instant;

/// A linear body's condensed state within the settle loop.
pub(super) struct Condensation {
    pub(super) body: CondensedBody,
    /// Contact forces assumed at the candidate slots, N.
    pub(super) fhat: Vec<Real>,
    /// Rigid-motion amplitudes, m.
    pub(super) alpha: Vec<Real>,
    /// The step's load per free DOF, N, and `K⁻¹` of it at the candidates, m.
    pub(super) load: Vec<Real>,
    pub(super) base: Vec<Real>,
    /// Body displacements of the last full solve, m, and the amplitudes then.
    pub(super) expanded: Vec<Real>,
    pub(super) alpha_expanded: Vec<Real>,
    /// Load plus contact forces per free DOF at the last full solve, N.
    pub(super) rhs_expanded: Vec<Real>,
    /// The step being solved and the number of steps (the load of a body condensed again).
    pub(super) step: (usize, usize),
    /// The last two solved steps: (step, f̂, α), oldest first (the next step starts from their
    /// extrapolation).
    pub(super) history: Vec<(usize, Vec<Real>, Vec<Real>)>,
    /// Whether the bodies' displacements are those of the last full solve (no placement since).
    pub(super) fresh: bool,
}

/// Candidates lie within this many mean member lengths of another body's bounding box or of
/// an obstacle (anywhere along its travel).
const MARGIN_MEMBERS: Real = 2.0;

/// Per body, the nodes that may touch something: surface nodes (3D: of its patches; 2D: of its
/// boundary loop; all nodes when it has neither) near another body's bounding box or near an
/// obstacle anywhere along its travel.
pub(super) fn candidate_nodes(
    bodies: &[Body],
    surfaces: &[Option<Surface>],
    patch_surfaces: &[Option<PatchSurface>],
    obstacles: &Obstacles,
    travels: &[Vec<Vector3<Real>>],
) -> Vec<Vec<bool>> {
    let margin: Vec<Real> = bodies
        .iter()
        .map(|b| MARGIN_MEMBERS * 100.0 * penetration_tolerance(b))
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
        let surface: Vec<usize> = match (&patch_surfaces[b], &surfaces[b]) {
            (Some(p), _) => p.nodes.clone(),
            (None, Some(s)) => s.nodes.clone(),
            (None, None) => (0..body.nodes.len()).collect(),
        };
        let mut mark = vec![false; body.nodes.len()];
        for node in surface {
            let x = body.nodes[node];
            let near_body = boxes.iter().enumerate().any(|(o, (lo, hi))| {
                let m = margin[b].max(margin[o]);
                o != b && (0..3).all(|k| x[k] >= lo[k] - m && x[k] <= hi[k] + m)
            });
            let near_obstacle = || {
                travels.iter().enumerate().any(|(o, offsets)| {
                    offsets.iter().any(|offset| {
                        obstacles
                            .project(o, &x, offset)
                            .is_some_and(|p| p.depth >= -margin[b])
                    })
                })
            };
            mark[node] = near_body || near_obstacle();
        }
        out.push(mark);
    }
    out
}

/// `mark` plus every node within `rings` members of a marked one.
fn widen(body: &Body, mark: &mut [bool], rings: usize) {
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

impl Condensation {
    pub(super) fn new(body: CondensedBody, dofs: usize) -> Self {
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
            step: (0, 1),
            fresh: false,
            body,
        }
    }

    /// Condense `body` on `nodes`; `Err` if it cannot be (the caller solves coupled).
    pub(super) fn build(
        body: &Body,
        dofs: &DofMap,
        assembly: &StiffnessAssembly,
        nodes: Vec<bool>,
    ) -> Result<CondensedBody, CondenseFailure> {
        CondensedBody::new(body, dofs, assembly, nodes)
    }
}

impl ContactSolver {
    /// Start a step on the condensed path: each body's load and base displacement.
    pub(super) fn condensed_step(&mut self, step: usize, steps: usize, restart: bool) {
        let Some(condensed) = self.condensed.as_mut() else {
            return;
        };
        for c in condensed.iter_mut() {
            if restart {
                c.fhat.iter_mut().for_each(|v| *v = 0.0);
                c.alpha.iter_mut().for_each(|v| *v = 0.0);
                c.alpha_expanded.iter_mut().for_each(|v| *v = 0.0);
                c.expanded.iter_mut().for_each(|v| *v = 0.0);
                c.rhs_expanded.iter_mut().for_each(|v| *v = 0.0);
                c.history.clear();
            }
            // Start from the straight line through the last two solved steps (exact for loads
            // that grow in proportion while the contacts stay): Newton then only corrects.
            if let [(s0, f0, a0), (s1, f1, a1)] = &c.history[..] {
                if *s1 + 1 == step && *s0 + 1 == *s1 && f1.len() == c.fhat.len() {
                    for (v, (x1, x0)) in c.fhat.iter_mut().zip(f1.iter().zip(f0)) {
                        *v = 2.0 * x1 - x0;
                    }
                    for (v, (x1, x0)) in c.alpha.iter_mut().zip(a1.iter().zip(a0)) {
                        *v = 2.0 * x1 - x0;
                    }
                }
            }
            let (load, base) = c.body.step_load(step, steps);
            c.load = load;
            c.base = base;
            c.fresh = false;
            c.step = (step, steps);
        }
    }

    /// Remember the solved state of `step` for the next step's start.
    pub(super) fn condensed_solved(&mut self, step: usize) {
        if let Some(condensed) = self.condensed.as_mut() {
            for c in condensed.iter_mut() {
                if c.history.len() == 2 {
                    c.history.remove(0);
                }
                c.history.push((step, c.fhat.clone(), c.alpha.clone()));
            }
        }
    }

    /// Write the condensed state into the bodies' displacements: exact at the candidates,
    /// the last full solve plus the rigid motion since elsewhere.
    fn place_condensed(&mut self) {
        let Some(condensed) = self.condensed.as_mut() else {
            return;
        };
        for (part, c) in self.parts.iter_mut().zip(condensed.iter_mut()) {
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
        }
    }

    /// The full displacement of every body (one solve each), kept for the next placements.
    /// The dense compliance places the candidates to its own round-off (which grows with the
    /// condition of the body's stiffness); the difference to the solve is folded into the
    /// base displacement so that later placements reproduce the solve exactly. Returns that
    /// difference as a force, the largest stiffness times the largest difference, relative to
    /// the largest load or contact force norm of a body (0 when nothing changed). The
    /// candidates keep their placed values, so the contact forces are Newton's; the difference
    /// only unbalances the members next to them.
    pub(super) fn expand_condensed(&mut self) -> Real {
        let t = Instant::now();
        let Some(condensed) = self.condensed.as_mut() else {
            return 0.0;
        };
        if condensed.iter().all(|c| c.fresh) {
            return 0.0;
        }
        let norm = |v: &[Real]| v.iter().map(|x| x * x).sum::<Real>().sqrt();
        // One solve per body, the bodies side by side.
        let each: Vec<(Real, Real)> = self
            .parts
            .par_iter_mut()
            .zip(condensed.par_iter_mut())
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
        self.times.solve += t.elapsed().as_secs_f64();
        if largest > 0.0 {
            differs / largest
        } else {
            0.0
        }
    }

    /// Residuals of the condensed problem at the current placement: per body, contact force
    /// found minus assumed at the candidates and the out-of-balance along the rigid motions
    /// (N); their norm and the force scale (applied and contact forces); and the contact rows.
    /// `Err` with the (body, node) pairs a contact reaches outside the candidates.
    #[allow(clippy::type_complexity)]
    fn condensed_residual(
        &mut self,
        bodies: &[Body],
        set: &ContactSet,
        forces: &[Vec<Real>],
        offsets: &[Vector3<Real>],
    ) -> Result<(Vec<Vec<Real>>, Vec<Vec<Real>>, Real, Real, Vec<ContactRow>), Vec<(usize, usize)>>
    {
        self.place_condensed();
        let (fc, list) = self.contact_forces(bodies, set, offsets);
        let Some(condensed) = self.condensed.as_ref() else {
            return Err(Vec::new());
        };
        let mut missing = Vec::new();
        let mut rows = Vec::with_capacity(list.len());
        for e in &list {
            let Some(n) = e.normal else { continue };
            let mut entries = Vec::with_capacity(12);
            for &(b, node, w) in &e.nodes {
                let dofs = &self.parts[b].dofs;
                for k in 0..dofs.dofs_per_node {
                    if let Some(i) = dofs.free_index(node, k) {
                        match condensed[b].body.slot[i] {
                            NOT_CANDIDATE => missing.push((b, node)),
                            s => entries.push((b, s, w * n[k])),
                        }
                    }
                }
            }
            if !entries.is_empty() && e.penalty.stiffness > 0.0 {
                rows.push(ContactRow {
                    penalty: e.penalty.stiffness,
                    entries,
                });
            }
        }
        if !missing.is_empty() {
            missing.sort_unstable();
            missing.dedup();
            return Err(missing);
        }
        let (mut sum, mut applied, mut contact) = (0.0, 0.0, 0.0);
        let mut phi1 = Vec::with_capacity(condensed.len());
        let mut phi2 = Vec::with_capacity(condensed.len());
        for (b, c) in condensed.iter().enumerate() {
            let free = &self.parts[b].dofs.free;
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
            applied += forces[b].iter().map(|f| f * f).sum::<Real>();
            contact += fc[b].iter().map(|f| f * f).sum::<Real>();
            phi1.push(p1);
            phi2.push(p2);
        }
        let scale = applied.sqrt().max(contact.sqrt()).max(self.force_floor());
        Ok((phi1, phi2, sum.sqrt(), scale, rows))
    }

    /// Add `s` times a correction to the condensed state.
    fn apply_correction(&mut self, base: &[(Vec<Real>, Vec<Real>)], corr: &Correction, s: Real) {
        if let Some(condensed) = self.condensed.as_mut() {
            for ((c, (f0, a0)), (df, da)) in condensed
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
    }

    /// The displacements at every body's candidates as placed, m.
    fn candidate_displacements(&self) -> Vec<Vec<Real>> {
        let Some(condensed) = self.condensed.as_ref() else {
            return Vec::new();
        };
        condensed
            .iter()
            .zip(&self.parts)
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
    fn candidate_norm(&self) -> Real {
        let mut largest: Real = 0.0;
        if let Some(condensed) = self.condensed.as_ref() {
            for (c, part) in condensed.iter().zip(&self.parts) {
                for &i in &c.body.cand {
                    largest = largest.max(part.u[part.dofs.free[i]].abs());
                }
            }
        }
        largest
    }

    /// The largest nodal move of a correction at the candidates and, rigidly, anywhere, m.
    fn condensed_move(&self, corr: &Correction) -> Real {
        let Some(condensed) = self.condensed.as_ref() else {
            return 0.0;
        };
        let mut largest: Real = 0.0;
        for ((c, part), (df, da)) in condensed
            .iter()
            .zip(&self.parts)
            .zip(corr.fhat.iter().zip(&corr.alpha))
        {
            let d = part.dofs.dofs_per_node;
            let mut moves = vec![0.0; part.u.len() / d.max(1)];
            let flexible = c.body.comply(df);
            for (i, &dof) in part.dofs.free.iter().enumerate() {
                let mut m: Real = c.body.modes.iter().zip(da).map(|(r, a)| a * r[i]).sum();
                if c.body.slot[i] != NOT_CANDIDATE {
                    m += flexible[c.body.slot[i]];
                }
                moves[dof / d] += m * m;
            }
            largest = moves.into_iter().map(Real::sqrt).fold(largest, Real::max);
        }
        largest
    }

    /// Add the nodes in `missing` (and two rings of neighbours) to their bodies' candidates and
    /// condense those bodies again. `false` if one cannot be condensed.
    fn grow_candidates(&mut self, bodies: &[Body], missing: &[(usize, usize)]) -> bool {
        let Some(mut condensed) = self.condensed.take() else {
            return false;
        };
        let mut ok = true;
        for (b, body) in bodies.iter().enumerate() {
            if !missing.iter().any(|&(mb, _)| mb == b) {
                continue;
            }
            let mut mark = condensed[b].body.nodes.clone();
            for &(_, node) in missing.iter().filter(|&&(mb, _)| mb == b) {
                mark[node] = true;
            }
            widen(body, &mut mark, 2);
            let part = &self.parts[b];
            let Ok(grown) = Condensation::build(body, &part.dofs, &part.assembly, mark) else {
                ok = false;
                break;
            };
            self.times.symbolic += grown.seconds[0];
            self.times.numeric += grown.seconds[1];
            self.times.solve += grown.seconds[2];
            let c = &mut condensed[b];
            let mut fhat = vec![0.0; grown.len()];
            for (s, &i) in c.body.cand.iter().enumerate() {
                fhat[grown.slot[i]] = c.fhat[s];
            }
            c.fhat = fhat;
            c.history.clear();
            c.fresh = false;
            c.body = grown;
            let (load, base) = c.body.step_load(c.step.0, c.step.1);
            c.load = load;
            c.base = base;
        }
        if ok {
            self.condensed = Some(condensed);
        }
        ok
    }

    /// Newton on the candidates with the contact set fixed (see [`ContactSolver::newton`] for
    /// the meaning of the result). Falls back to the coupled solve when a body cannot be
    /// condensed on the nodes the contacts reach. The factored Jacobian of a set is kept for
    /// the next call with the same set (the next step, or a refinement after the full solve).
    pub(super) fn newton_condensed(
        &mut self,
        bodies: &[Body],
        set: &ContactSet,
        forces: &[Vec<Real>],
        offsets: &[Vector3<Real>],
        step: usize,
    ) -> Result<(usize, bool), ContactError> {
        let mut jacobian = self
            .condensed_jacobian
            .take()
            .filter(|(s, _)| s == set)
            .map(|(_, j)| j);
        let result = self.newton_condensed_with(bodies, set, forces, offsets, step, &mut jacobian);
        if self.condensed.is_some() {
            self.condensed_jacobian = jacobian.map(|j| (set.clone(), j));
        }
        result
    }

    fn newton_condensed_with(
        &mut self,
        bodies: &[Body],
        set: &ContactSet,
        forces: &[Vec<Real>],
        offsets: &[Vector3<Real>],
        step: usize,
        jacobian: &mut Option<ContactJacobian>,
    ) -> Result<(usize, bool), ContactError> {
        let (tolerance, max_iterations) = newton_limits(bodies);
        let stabilisation = STABILISATION
            * self
                .parts
                .iter()
                .map(|p| p.penalty.stiffness)
                .fold(0.0, Real::max);
        let mut history: Vec<Real> = Vec::new();
        let mut iterations = 0;
        let mut last_step = Real::INFINITY;
        let fresh = self
            .condensed
            .as_ref()
            .is_some_and(|c| c.iter().all(|c| c.fresh));
        // The residual of the state the line search accepted (evaluated there already).
        let mut pending = None;
        loop {
            let t = Instant::now();
            let evaluated = match pending.take() {
                Some(e) => Ok(e),
                None => self.condensed_residual(bodies, set, forces, offsets),
            };
            self.times.assembly += t.elapsed().as_secs_f64();
            let (phi1, phi2, rnorm, scale, rows) = match evaluated {
                Ok(e) => e,
                Err(missing) => {
                    if !missing.is_empty() && self.grow_candidates(bodies, &missing) {
                        *jacobian = None;
                        continue;
                    }
                    return self.fall_back(bodies, set, forces, offsets, step);
                }
            };
            let relative = rnorm / scale;
            if !relative.is_finite() {
                return Err(ContactError::NotFinite { step });
            }
            history.push(relative);
            let stalled = history.len() >= 3
                && relative <= 100.0 * tolerance
                && relative >= 0.5 * history[history.len() - 2];
            // A correction that no longer moves anything has converged too (round-off over a
            // force scale of round-off: a node touching at a depth of 1e-17 m).
            if relative <= tolerance || stalled || last_step <= 1e-12 * self.candidate_norm() {
                if iterations == 0 && fresh {
                    // Nothing moved: the displacements are still those of the last solve.
                    if let Some(condensed) = self.condensed.as_mut() {
                        condensed.iter_mut().for_each(|c| c.fresh = true);
                    }
                }
                return Ok((iterations, true));
            }
            if iterations >= max_iterations {
                return Err(ContactError::NotConverged {
                    step,
                    iterations,
                    history,
                });
            }
            let t = Instant::now();
            let Some(condensed) = self.condensed.as_ref() else {
                return self.fall_back(bodies, set, forces, offsets, step);
            };
            let views: Vec<&CondensedBody> = condensed.iter().map(|c| &c.body).collect();
            // Modified Newton: keep the factored Jacobian while it converges fast (the contacts'
            // normals and weights move little within one contact set).
            // Near the round-off floor the Jacobian's age no longer matters.
            // A Jacobian carried over from an earlier call is tried once.
            let reuse = jacobian.as_ref().is_some_and(|j: &ContactJacobian| {
                j.rows().len() == rows.len()
                    && (history.len() < 2
                        || history[history.len() - 1] < 0.1 * history[history.len() - 2]
                        || relative < 1e3 * tolerance)
            });
            if !reuse {
                *jacobian = match ContactJacobian::new(&views, rows, stabilisation) {
                    Ok(j) => Some(j),
                    Err(_) => return self.fall_back(bodies, set, forces, offsets, step),
                };
            }
            let Some(jac) = jacobian.as_ref() else {
                return self.fall_back(bodies, set, forces, offsets, step);
            };
            let corr = jac.correction(&views, &phi1, &phi2);
            let base: Vec<(Vec<Real>, Vec<Real>)> = condensed
                .iter()
                .map(|c| (c.fhat.clone(), c.alpha.clone()))
                .collect();
            self.times.solve += t.elapsed().as_secs_f64();
            iterations += 1;
            if corr.stabilised {
                let largest = self.condensed_move(&corr);
                if largest > self.move_cap {
                    self.apply_correction(&base, &corr, self.move_cap / largest);
                    self.place_condensed();
                    return Ok((iterations, false));
                }
            }
            let before = self.candidate_displacements();
            // The residual of the accepted trial is the next iteration's: kept, not recomputed.
            let mut last = None;
            let (s, accepted) = backtrack(rnorm, |s| {
                self.apply_correction(&base, &corr, s);
                last = self.condensed_residual(bodies, set, forces, offsets).ok();
                last.as_ref().map_or(Real::INFINITY, |e| e.2)
            });
            if accepted {
                pending = last;
            } else {
                self.apply_correction(&base, &corr, s);
                self.place_condensed();
            }
            last_step = before
                .iter()
                .zip(self.candidate_displacements())
                .flat_map(|(a, b)| {
                    a.iter()
                        .zip(b)
                        .map(|(x, y)| (x - y).abs())
                        .collect::<Vec<_>>()
                })
                .fold(0.0, Real::max);
        }
    }

    /// Leave the condensed path: the full displacements, then the coupled solve from there.
    fn fall_back(
        &mut self,
        bodies: &[Body],
        set: &ContactSet,
        forces: &[Vec<Real>],
        offsets: &[Vector3<Real>],
        step: usize,
    ) -> Result<(usize, bool), ContactError> {
        self.expand_condensed();
        self.condensed = None;
        self.build_coupled()?;
        self.newton(bodies, set, forces, offsets, step)
    }
}
