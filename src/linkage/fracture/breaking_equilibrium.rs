//! The linear equilibrium of a body whose members break, event by event (sequentially linear
//! analysis): within each load step the member that reaches its strength first as the load
//! grows breaks, the solution is corrected, and so on until every intact member is within its
//! strength at the step's load.
//!
//! `K_ff` is factored once; a break is the rank-one change `K_ff − k g gᵀ` (`g` the member's
//! axis at its free DOFs), taken into the solves by the Woodbury identity
//! ([`LowRankUpdate`]), and `K_ff` is refactored only after `refactor_every` breaks or when a
//! piece falls off. A load pattern's solution `u` becomes `u + w e / s` after a break
//! (Sherman–Morrison, with prescribed displacements too: `e` is the member's elongation,
//! `w = K⁻¹ g`, `s = 1/k − gᵀ w`), so a break costs one solve with the factor, not a solve per
//! pattern.
//!
//! On a large supernodal factor (20,000 free DOFs or more) the update is kept in the factor's
//! space instead ([`FactorLowRankUpdate`]): `L⁻¹ P g` is nonzero only on the paths from the
//! member's two nodes to the root of the elimination tree, so a break costs a forward solve
//! over those paths, sparse products with the earlier breaks' columns and one backward solve
//! (independent subtrees side by side, the same bits on any number of threads), about half a
//! full solve on the benchmark lattice (docs/performance-history.md, "A break in the factor's
//! space").
//!
//! A softening member (its material's `softening`, see [`saw_tooth`]) passes through its
//! teeth the same way: each tooth is an event found like a break, and the drop of its
//! stiffness from `kᵢ` to `kᵢ₊₁` is the rank-one removal of `(kᵢ − kᵢ₊₁) g gᵀ`; the last tooth
//! breaks it.

use crate::linalg::{CholeskyError, FactorLowRankUpdate, LowRankUpdate, SparseCholesky};
use crate::linkage::body_state::{linear_internal_forces, linear_stretch, undeformed_axis};
use crate::linkage::fracture::{
    critical_fraction, member_limits, released_pieces, saw_tooth, BreakEvent, FallenPiece,
    FractureState, Tooth,
};
use crate::linkage::load_patterns::{solve_load_patterns, LoadPattern};
use crate::linkage::mechanism::diagnose_mechanism;
use crate::linkage::step_state::{force_scale, free_out_of_balance};
use crate::linkage::{
    member_block, member_stiffnesses, post_process, Body, Convergence, DofMap, DofSlot, PhaseTimes,
    SolveError, StepState, StiffnessAssembly,
};
use crate::Real;
use nalgebra::Vector3;
use rayon::prelude::*;
use std::time::Instant;

/// Breaks between refactorizations of `K_ff` by default: the Woodbury correction of a solve
/// costs `O(n r)` on top of the triangular solves, so `r` is kept well below the factor's fill.
/// On the 108,860-member benchmark lattice a correction at r = 128 still costs a few percent
/// of a solve, while a refactorization costs 16–23 solves: 128 halves the refactorizations of
/// 64 for little more per break (see docs/performance-history.md, "Fracture").
pub const DEFAULT_REFACTOR_EVERY: usize = 128;

/// A break whose `1 − k gᵀ K⁻¹ g` is at most this leaves `K_ff` singular: a piece falls off
/// or the structure collapses. Not far below 1: a part left on a hinge is singular only up to
/// the rounding of the factor, and passing it on gives displacements of no meaning; a member
/// whose removal makes the body a million times more flexible along its axis is taken to hold
/// a mechanism.
const SINGULAR_RATIO: Real = 1e-6;

/// Members whose critical fractions of a load increment differ by at most this (relative to
/// the fraction, at least 1) reach their strength together: they break in one event, before
/// the solution is corrected, as symmetric members do (breaking one of them first would break
/// the symmetry by rounding and let its twin carry what it left).
pub const TIE: Real = 1e-9;

/// Per member its tensile and compressive strength (Pa, positive, infinite for none), or
/// `None` when it does not break.
pub type MemberLimits = Vec<Option<(Real, Real)>>;

/// The linear equilibrium of a body with breaking members (see the module documentation).
pub struct BreakingEquilibrium {
    /// The free/support partition.
    pub dofs: DofMap,
    /// The pattern of `K_ff`.
    pub assembly: StiffnessAssembly,
    /// Time spent in each phase, s (refactorizations in `numeric`).
    pub times: PhaseTimes,
    /// Numeric factorizations of `K_ff` so far (the first included).
    pub factorizations: usize,
    /// Breaks between refactorizations.
    pub refactor_every: usize,
    values: Vec<Real>,
    cholesky: Option<SparseCholesky>,
    update: LowRankUpdate,
    /// The update in the factor's space, used instead of `update` for large supernodal
    /// factors: a break then costs a forward solve over its two nodes' paths in the
    /// elimination tree and one backward solve, not a full solve and `O(n r)`.
    factor_update: Option<FactorLowRankUpdate>,
    /// Per member its current `A Eᵢ / L`, N/m; 0 once broken or fallen off.
    stiffness: Vec<Real>,
    /// Per member `A E / L` of its material, N/m.
    full_stiffness: Vec<Real>,
    /// Per member its Young's modulus as a fraction of its material's (its tooth's; 1 for a
    /// member that does not soften).
    modulus_factor: Vec<Real>,
    /// Per softening member its teeth; empty for the others.
    teeth: Vec<Vec<Tooth>>,
    /// Per member the index of its current tooth.
    tooth: Vec<usize>,
    /// Per member its first tooth's strengths (tensile, compressive), Pa.
    first_limits: MemberLimits,
    axes: Vec<Vector3<Real>>,
    /// Per member its undeformed length, m.
    lengths: Vec<Real>,
    /// Per member its tensile and compressive strength (Pa, infinite for none) when its
    /// material breaks.
    limits: MemberLimits,
    patterns: Vec<LoadPattern>,
    /// Members broken so far, in order.
    broken: Vec<usize>,
    /// Per member, whether it broke in tension (its ends apart at the break).
    in_tension: Vec<bool>,
    /// The step being broken and the largest fraction of its load increment its events
    /// reached: the load of a collapse state.
    reached: (usize, Real),
    /// Per node, whether it fell off with a piece.
    fallen_node: Vec<bool>,
    supported_node: Vec<bool>,
}

impl BreakingEquilibrium {
    /// Validate, assemble, factor and solve every load pattern of the (linear) `body`, each
    /// member's strength from its material (scattered when it has `scatter`).
    pub fn new(body: &Body) -> Result<Self, SolveError> {
        let limits = member_limits(body);
        Self::with_limits(body, limits)
    }

    /// [`BreakingEquilibrium::new`] with each member's strengths given (tensile, compressive,
    /// Pa; `None`: the member does not break), e.g. drawn with scatter.
    pub fn with_limits(body: &Body, limits: MemberLimits) -> Result<Self, SolveError> {
        body.validate()?;
        let teeth = member_teeth(body, &limits)?;
        let t = Instant::now();
        let dofs = DofMap::new(body);
        let assembly = StiffnessAssembly::new(body, &dofs)?;
        let stiffness = member_stiffnesses(body);
        let axes = body
            .members
            .iter()
            .map(|m| undeformed_axis(body, m.nodes[0], m.nodes[1]))
            .collect();
        let lengths = (0..body.members.len())
            .map(|m| body.member_length(m))
            .collect();
        let mut supported_node = vec![false; body.nodes.len()];
        for &dof in &dofs.supported {
            supported_node[dof / dofs.dofs_per_node] = true;
        }
        let n = assembly.n;
        let mut eq = BreakingEquilibrium {
            dofs,
            assembly,
            times: PhaseTimes::default(),
            factorizations: 0,
            refactor_every: DEFAULT_REFACTOR_EVERY,
            values: Vec::new(),
            cholesky: None,
            update: LowRankUpdate::new(n, SINGULAR_RATIO),
            factor_update: None,
            full_stiffness: stiffness.clone(),
            stiffness,
            modulus_factor: vec![1.0; body.members.len()],
            teeth,
            tooth: vec![0; body.members.len()],
            first_limits: limits.clone(),
            axes,
            lengths,
            limits,
            patterns: Vec::new(),
            broken: Vec::new(),
            in_tension: vec![false; body.members.len()],
            reached: (0, 0.0),
            fallen_node: vec![false; body.nodes.len()],
            supported_node,
        };
        eq.fill(body);
        eq.times.assembly = t.elapsed().as_secs_f64();
        if n > 0 {
            let t = Instant::now();
            let a = &eq.assembly;
            let c = SparseCholesky::analyze(a.n, &a.col_ptr, &a.row_idx, Some(&a.groups))
                .map_err(|e| factorization_error(body, e))?;
            eq.times.symbolic = t.elapsed().as_secs_f64();
            eq.factor_update = FactorLowRankUpdate::new(&c, SINGULAR_RATIO);
            eq.cholesky = Some(c);
            if let Err(e) = eq.factorize() {
                return Err(eq.singular(body, e));
            }
        }
        let t = Instant::now();
        let BreakingEquilibrium {
            dofs,
            stiffness,
            cholesky,
            update,
            ..
        } = &mut eq;
        let patterns = solve_load_patterns(body, dofs, n, stiffness, &mut |rhs| {
            if let Some(c) = cholesky.as_mut() {
                update.solve(&mut |x| c.solve_in_place(x), rhs);
            }
            true
        });
        eq.patterns = patterns.unwrap_or_default();
        eq.times.solve += t.elapsed().as_secs_f64();
        Ok(eq)
    }

    /// Rank-one changes taken into the solves since the last factorization.
    fn rank(&self) -> usize {
        match &self.factor_update {
            Some(u) => u.rank(),
            None => self.update.rank(),
        }
    }

    /// Whether breaks are taken in the factor's space ([`FactorLowRankUpdate`]: large
    /// supernodal factors) rather than by full solves.
    pub fn updates_in_factor_space(&self) -> bool {
        self.factor_update.is_some()
    }

    /// Time in the sparse forward and in the backward solves of breaks, s, when they are taken
    /// in the factor's space.
    pub fn factor_space_seconds(&self) -> Option<(Real, Real)> {
        self.factor_update
            .as_ref()
            .map(|u| (u.forward_seconds, u.backward_seconds))
    }

    /// Members broken so far, 0-based, in order.
    pub fn broken(&self) -> &[usize] {
        &self.broken
    }

    /// Whether member `m` broke in tension (its ends apart at the break, so that its crack
    /// can close again); `false` for a member crushed, or not broken.
    pub fn broke_in_tension(&self, m: usize) -> bool {
        self.in_tension.get(m).copied().unwrap_or(false)
    }

    /// Fill `K_ff` with the intact members; a free DOF of a node left without members is held
    /// by a diagonal entry (it carries no load and stays in place).
    fn fill(&mut self, body: &Body) {
        let stiffness = &self.stiffness;
        self.assembly.fill(
            body,
            |m| {
                let [a, b] = body.members[m].nodes;
                member_block(&body.nodes[a], &body.nodes[b], stiffness[m])
            },
            &mut self.values,
        );
        let mut has_member = vec![false; body.nodes.len()];
        for (m, member) in body.members.iter().enumerate() {
            if self.stiffness[m] > 0.0 {
                member.nodes.iter().for_each(|&n| has_member[n] = true);
            }
        }
        // The hold is as stiff as the stiffest member, so the factor's pivot test does not
        // take it for a singular pivot.
        let hold = self.stiffness.iter().copied().fold(0.0, Real::max).max(1.0);
        let d = self.dofs.dofs_per_node;
        for (node, _) in has_member.iter().enumerate().filter(|(_, h)| !**h) {
            for dir in 0..d {
                if let Some(place) = self.assembly.diagonal_place(node, dir) {
                    self.values[place] = hold;
                }
            }
        }
    }

    fn factorize(&mut self) -> Result<(), CholeskyError> {
        let t = Instant::now();
        let result = match self.cholesky.as_mut() {
            Some(c) => c.factorize(&self.values),
            None => Ok(()),
        };
        self.times.numeric += t.elapsed().as_secs_f64();
        self.factorizations += 1;
        self.update.clear();
        if let Some(u) = self.factor_update.as_mut() {
            u.clear();
        }
        result
    }

    /// Turn a failed first factorization into a mechanism report naming nodes and directions.
    fn singular(&mut self, body: &Body, e: CholeskyError) -> SolveError {
        let pivot = match e {
            CholeskyError::NonPositivePivot { dof } => dof,
            CholeskyError::NearlySingular { dof, .. } => dof,
            other => return factorization_error(body, other),
        };
        match self.cholesky.as_mut() {
            Some(c) => SolveError::Mechanism(Box::new(diagnose_mechanism(
                body,
                &self.dofs,
                &self.assembly,
                &self.values,
                c,
                pivot,
            ))),
            None => factorization_error(body, e),
        }
    }

    /// Refactor `K_ff` with the members broken so far and solve every pattern again (loads on
    /// fallen nodes dropped). `false` when `K_ff` is singular: the supported part is a mechanism.
    fn refactor(&mut self, body: &Body) -> bool {
        let t = Instant::now();
        self.fill(body);
        self.times.assembly += t.elapsed().as_secs_f64();
        if self.factorize().is_err() {
            return false;
        }
        let t = Instant::now();
        let d = self.dofs.dofs_per_node;
        let n = self.assembly.n;
        let mut internal = vec![0.0; body.dof_count()];
        let mut rhs = vec![0.0; n];
        for p in &mut self.patterns {
            for (node, _) in self.fallen_node.iter().enumerate().filter(|(_, f)| **f) {
                for k in 0..d {
                    p.forces[node * d + k] = 0.0;
                }
            }
            // F_f − K_fs U_s: the prescribed displacements alone.
            for &dof in &self.dofs.free {
                p.displacements[dof] = 0.0;
            }
            linear_internal_forces(body, &self.stiffness, &p.displacements, &mut internal);
            for (i, &dof) in self.dofs.free.iter().enumerate() {
                rhs[i] = p.forces[dof] - internal[dof];
            }
            if let Some(c) = self.cholesky.as_mut() {
                c.solve_in_place(&mut rhs);
            }
            for (i, &dof) in self.dofs.free.iter().enumerate() {
                p.displacements[dof] = rhs[i];
            }
        }
        self.times.solve += t.elapsed().as_secs_f64();
        true
    }

    /// Per pattern, the elongation of member `m`, m.
    fn elongations(&self, body: &Body, m: usize) -> Vec<Real> {
        let d = self.dofs.dofs_per_node;
        self.patterns
            .iter()
            .map(|p| linear_stretch(&p.displacements, d, body.members[m].nodes, &self.axes[m]))
            .collect()
    }

    /// Displacements per body DOF with each pattern at its factor.
    fn combine(&self, factors: &[Real], field: impl Fn(&LoadPattern) -> &[Real]) -> Vec<Real> {
        let nd = self.dofs.slots.len();
        let mut u = vec![0.0; nd];
        for (p, &f) in self.patterns.iter().zip(factors) {
            if f == 0.0 {
                continue;
            }
            for (ui, v) in u.iter_mut().zip(field(p)) {
                *ui += f * v;
            }
        }
        u
    }

    /// The next members to break between the loads at pattern factors `f0` (t = 0) and `f1`
    /// (t = 1): the one of smallest critical fraction and every member that ties with it
    /// (within [`TIE`]: symmetric members reach their strength together and break in one
    /// event), in member order; empty when none is beyond its strength at `f1`.
    fn next_breaks(&self, body: &Body, f0: &[Real], f1: &[Real]) -> Vec<BreakEvent> {
        let d = self.dofs.dofs_per_node;
        let u0 = self.combine(f0, |p| &p.displacements);
        let u1 = self.combine(f1, |p| &p.displacements);
        let start_unloaded = f0.iter().all(|&f| f == 0.0);
        // Each member's critical fraction on its own (in parallel: no sums cross members),
        // then the smallest found in member order, so the answer does not depend on threads.
        let fractions: Vec<Option<Real>> = (0..body.members.len())
            .into_par_iter()
            .with_min_len(4096)
            .map(|m| {
                let (tensile, compressive) = self.limits[m]?;
                if self.stiffness[m] == 0.0 {
                    return None;
                }
                let member = &body.members[m];
                let material = &body.materials[member.material];
                // The stress as the step's results report it (E A ε / A).
                let stress = |u: &[Real]| {
                    let strain =
                        linear_stretch(u, d, member.nodes, &self.axes[m]) / self.lengths[m];
                    material.youngs_modulus * self.modulus_factor[m] * strain * material.area
                        / material.area
                };
                let end = stress(&u1);
                if end <= tensile && end >= -compressive {
                    return None;
                }
                let a = if start_unloaded { 0.0 } else { stress(&u0) };
                critical_fraction(a, end - a, tensile, compressive)
            })
            .collect();
        let Some(least) = fractions.iter().flatten().copied().reduce(Real::min) else {
            return Vec::new();
        };
        let tie = TIE * least.abs().max(1.0);
        fractions
            .into_iter()
            .enumerate()
            .filter_map(|(m, t)| {
                let t = t?;
                (t - least <= tie).then_some(BreakEvent {
                    member: m,
                    fraction: t,
                    tooth: None,
                })
            })
            .collect()
    }

    /// Member `m` reached its strength: move it to its next tooth (returned, 1-based: the
    /// tooth it passed) when it has one, else break it. Every pattern's solution is corrected
    /// by the rank-one update, unless `stale` (an earlier member of the same event left `K_ff`
    /// singular: the stiffness only is changed, and the refactorization after the event solves
    /// the patterns again). Returns the tooth passed and whether the update found `K_ff`
    /// singular; `Err(())` when a refactorization due by the update's rank finds the
    /// supported part a mechanism.
    fn remove_member(
        &mut self,
        body: &Body,
        m: usize,
        stale: bool,
    ) -> Result<(Option<usize>, bool), ()> {
        let d = self.dofs.dofs_per_node;
        let next = self.tooth[m] + 1;
        let softened = self.teeth[m].get(next).copied();
        let k_after = softened.map_or(0.0, |t| self.full_stiffness[m] * t.stiffness_factor);
        let k = self.stiffness[m] - k_after;
        let mut g = Vec::with_capacity(2 * d);
        for (sign, &node) in [-1.0, 1.0].iter().zip(&body.members[m].nodes) {
            for dir in 0..d {
                if let DofSlot::Free(i) = self.dofs.slots[node * d + dir] {
                    g.push((i, sign * self.axes[m][dir]));
                }
            }
        }
        let elongations = if stale {
            Vec::new()
        } else {
            self.elongations(body, m)
        };
        if let Some(t) = softened {
            self.tooth[m] = next;
            self.modulus_factor[m] = t.stiffness_factor;
            let (tensile, compressive) = self.first_limits[m].unwrap_or((1.0, 1.0));
            self.limits[m] = Some((
                t.tensile_strength,
                compressive * (t.tensile_strength / tensile),
            ));
        } else {
            self.broken.push(m);
        }
        let passed = softened.map(|_| next);
        if stale {
            self.stiffness[m] = k_after;
            return Ok((passed, false));
        }
        let t = Instant::now();
        let removal = match (self.cholesky.as_mut(), self.factor_update.as_mut()) {
            (Some(c), Some(u)) if !g.is_empty() => u.remove(c, &g, k).map(Some),
            (Some(c), None) if !g.is_empty() => self
                .update
                .remove(&mut |x| c.solve_in_place(x), &g, k)
                .map(Some),
            _ => Ok(None),
        };
        self.times.solve += t.elapsed().as_secs_f64();
        self.stiffness[m] = k_after;
        match removal {
            Ok(Some(r)) => {
                for (p, e) in self.patterns.iter_mut().zip(&elongations) {
                    let coef = e / r.s;
                    for (i, &dof) in self.dofs.free.iter().enumerate() {
                        p.displacements[dof] += coef * r.w[i];
                    }
                }
                if self.rank() >= self.refactor_every && !self.refactor(body) {
                    return Err(());
                }
                Ok((passed, false))
            }
            Ok(None) => Ok((passed, false)),
            Err(_) => Ok((passed, true)),
        }
    }

    /// The members of one event (tied at their strength) break, or pass a tooth, together
    /// (see [`Self::remove_member`]); returns per member the tooth passed. When the event
    /// leaves `K_ff` singular: a tooth (which leaves the member some stiffness) is taken as it
    /// is, by refactoring; after a break the pieces it left unsupported are removed (returned)
    /// and `K_ff` refactored. `Err` with the member that made it a mechanism when the
    /// supported part is one, or when what came loose is a collapse (see
    /// [`Self::release_pieces`]).
    #[allow(clippy::type_complexity)]
    fn break_members(
        &mut self,
        body: &Body,
        members: &[usize],
    ) -> Result<(Vec<Option<usize>>, Vec<FallenPiece>), usize> {
        let mut passed = Vec::with_capacity(members.len());
        // The first member whose removal left K_ff singular, and whether it broke.
        let mut singular: Option<(usize, bool)> = None;
        for &m in members {
            let (tooth, found) = self
                .remove_member(body, m, singular.is_some())
                .map_err(|()| m)?;
            if found && singular.is_none() {
                singular = Some((m, tooth.is_none()));
            }
            passed.push(tooth);
        }
        match singular {
            None => Ok((passed, Vec::new())),
            Some((m, false)) => {
                if !self.refactor(body) {
                    return Err(m);
                }
                Ok((passed, Vec::new()))
            }
            Some((m, true)) => {
                let pieces = self.release_pieces(body).ok_or(m)?;
                if pieces.is_empty() || !self.refactor(body) {
                    return Err(m);
                }
                Ok((
                    passed,
                    pieces
                        .into_iter()
                        .map(|nodes| FallenPiece { member: m, nodes })
                        .collect(),
                ))
            }
        }
    }

    /// After a break that left `K_ff` singular: remove what no longer holds on. A piece is a
    /// connected part without supports; a node without supports on fewer intact members than
    /// its dimension (a 2D node hanging on one member, a 3D node on two) turns freely about
    /// them and goes with its members. Repeated until nothing more comes loose; the pieces
    /// found (nodes ascending, by first node), empty when the singular mode is elsewhere.
    ///
    /// `None` (nothing removed) when what came loose is the structure's collapse rather than a
    /// piece falling off: a loaded piece still hanging on the rest by members (a mechanism
    /// under load: it would swing, not fall), or a loss that leaves the rest carrying no load
    /// at all (every load went with the pieces: nothing is left to hold them).
    fn release_pieces(&mut self, body: &Body) -> Option<Vec<Vec<usize>>> {
        let members: Vec<[usize; 2]> = body.members.iter().map(|x| x.nodes).collect();
        let intact: Vec<bool> = self.stiffness.iter().map(|&s| s > 0.0).collect();
        let pieces = released_pieces(
            &members,
            &intact,
            &self.supported_node,
            &self.fallen_node,
            self.dofs.dofs_per_node,
        );
        let mut released = self.fallen_node.clone();
        for &n in pieces.iter().flatten() {
            released[n] = true;
        }
        let d = self.dofs.dofs_per_node;
        let loaded = |n: usize| {
            self.patterns
                .iter()
                .any(|p| p.forces[n * d..(n + 1) * d].iter().any(|&f| f != 0.0))
        };
        let hanging = |piece: &[usize]| {
            members.iter().zip(&intact).any(|(&[a, b], &i)| {
                i && (piece.binary_search(&a).is_ok() && !released[b]
                    || piece.binary_search(&b).is_ok() && !released[a])
            })
        };
        if pieces
            .iter()
            .any(|piece| hanging(piece) && piece.iter().any(|&n| loaded(n)))
        {
            return None;
        }
        let rest_loaded = self.patterns.iter().any(|p| {
            (0..self.supported_node.len()).any(|n| {
                !released[n]
                    && (0..d).any(|k| match self.dofs.slots[n * d + k] {
                        DofSlot::Free(_) => p.forces[n * d + k] != 0.0,
                        _ => p.displacements[n * d + k] != 0.0,
                    })
            })
        });
        if !pieces.is_empty() && !rest_loaded {
            return None;
        }
        self.fallen_node = released;
        for (j, &[a, b]) in members.iter().enumerate() {
            if self.fallen_node[a] || self.fallen_node[b] {
                self.stiffness[j] = 0.0;
            }
        }
        Some(pieces)
    }

    /// Break the next members the load of `step` (of `steps`) breaks, if any: the first to
    /// reach its strength and those tied with it (one event), and return their events, in
    /// member order (empty: none); pieces that fall off are appended to `fallen`.
    /// [`SolveError::Collapse`] (its `breaks` holding this event alone) when the event leaves
    /// the supported part a mechanism, or loses the structure's load path (see
    /// [`Self::release_pieces`]).
    pub fn next_event(
        &mut self,
        body: &Body,
        step: usize,
        steps: usize,
        fallen: &mut Vec<FallenPiece>,
    ) -> Result<Vec<BreakEvent>, SolveError> {
        if step == 0 {
            self.reached = (0, 0.0);
            return Ok(Vec::new());
        }
        let factors = |s: usize| -> Vec<Real> {
            self.patterns
                .iter()
                .map(|p| p.schedule.factor(s, steps))
                .collect()
        };
        let (f0, f1) = (factors(step - 1), factors(step));
        let mut events = self.next_breaks(body, &f0, &f1);
        // The load the step reached: a cascade's later breaks may be reported at a lower load
        // (where the weakened structure would have broken), but the load does not go back.
        if self.reached.0 != step {
            self.reached = (step, 0.0);
        }
        if let Some(e) = events.first() {
            self.reached.1 = self.reached.1.max(e.fraction);
        }
        // Each member's elongation at its break, before the removals change the patterns.
        for event in &events {
            let t = event.fraction;
            let elongation: Real = self
                .elongations(body, event.member)
                .iter()
                .zip(f0.iter().zip(&f1))
                .map(|(e, (a, b))| e * (a + t * (b - a)))
                .sum();
            self.in_tension[event.member] = elongation > 0.0;
        }
        let members: Vec<usize> = events.iter().map(|e| e.member).collect();
        // The state at the event, before the removals change the patterns: the collapse
        // state should the event be the structure's collapse.
        let t = self.reached.1;
        let at_event: Vec<Real> = f0.iter().zip(&f1).map(|(a, b)| a + t * (b - a)).collect();
        let u = self.combine(&at_event, |p| &p.displacements);
        let forces = self.combine(&at_event, |p| &p.forces);
        match self.break_members(body, &members) {
            Ok((teeth, pieces)) => {
                fallen.extend(pieces);
                for (event, tooth) in events.iter_mut().zip(teeth) {
                    event.tooth = tooth;
                }
                Ok(events)
            }
            Err(member) => {
                // Brittle members of the event break (the removals may have stopped before
                // them); a softening one keeps its tooth.
                let mut broken = self.broken.clone();
                for &m in &members {
                    if self.teeth[m].is_empty() && !broken.contains(&m) {
                        broken.push(m);
                        self.stiffness[m] = 0.0;
                    }
                }
                let (mut state, _) = self.state_of(body, &u, &forces);
                state.iterations = 1;
                state.fracture = Some(FractureState {
                    broken,
                    breaks: events.clone(),
                    fallen: Vec::new(),
                });
                Err(SolveError::Collapse {
                    body: body.name.clone(),
                    step,
                    member,
                    breaks: events,
                    state: Some(Box::new(state)),
                })
            }
        }
    }

    /// The state at `step` of `steps` after every break the step's load causes (step 0:
    /// undeformed, unloaded). Steps are meant to come in order: the increment is from step
    /// `step − 1`'s loads. [`SolveError::Collapse`] when a break leaves the supported part a
    /// mechanism.
    pub fn solve_step(
        &mut self,
        body: &Body,
        step: usize,
        steps: usize,
    ) -> Result<StepState, SolveError> {
        let mut fracture = FractureState::default();
        loop {
            if body.newton.interrupt.is_raised() {
                return Err(SolveError::Interrupted {
                    body: body.name.clone(),
                    step,
                });
            }
            match self.next_event(body, step, steps, &mut fracture.fallen) {
                Ok(events) if events.is_empty() => break,
                Ok(events) => fracture.breaks.extend(events),
                Err(SolveError::Collapse {
                    body,
                    step,
                    member,
                    breaks,
                    mut state,
                }) => {
                    fracture.breaks.extend(breaks);
                    // The collapse state lists every break of the step and the pieces that
                    // fell off in it.
                    if let Some(f) = state.as_mut().and_then(|s| s.fracture.as_mut()) {
                        f.breaks = fracture.breaks.clone();
                        f.fallen = std::mem::take(&mut fracture.fallen);
                    }
                    return Err(SolveError::Collapse {
                        body,
                        step,
                        member,
                        breaks: fracture.breaks,
                        state,
                    });
                }
                Err(e) => return Err(e),
            }
        }
        fracture.broken = self.broken.clone();
        let factors: Vec<Real> = self
            .patterns
            .iter()
            .map(|p| p.schedule.factor(step, steps))
            .collect();
        let u = self.combine(&factors, |p| &p.displacements);
        let forces = self.combine(&factors, |p| &p.forces);
        let (mut state, internal) = self.state_of(body, &u, &forces);
        state.iterations = usize::from(step > 0);
        state.fracture = Some(fracture);
        // Once a body has split, its parts may carry next to nothing (each moved rigidly by
        // its supports): the residual is taken relative to the member forces the displacements
        // could give as well, k_max |u|_max, so rounding in them is not read as an error.
        let umax = u.iter().fold(0.0, |m: Real, v| m.max(v.abs()));
        let kmax = self.stiffness.iter().copied().fold(0.0, Real::max);
        let scale = force_scale(&self.dofs, &forces, &internal).max(kmax * umax);
        state.residual =
            Convergence::relative(free_out_of_balance(&self.dofs, &forces, &internal), scale);
        if !state.residual.is_finite() || state.residual > 1e-6 {
            return Err(SolveError::Inaccurate {
                body: body.name.clone(),
                residual: state.residual,
            });
        }
        Ok(state)
    }

    /// The state of the members as they are now at displacements `u` and loads `forces`
    /// (per body DOF; N), and the internal forces (per body DOF; N).
    fn state_of(&self, body: &Body, u: &[Real], forces: &[Real]) -> (StepState, Vec<Real>) {
        let d = self.dofs.dofs_per_node;
        let mut internal = vec![0.0; u.len()];
        linear_internal_forces(body, &self.stiffness, u, &mut internal);
        let members = body.members.iter().enumerate().map(|(m, member)| {
            let strain = linear_stretch(u, d, member.nodes, &self.axes[m]) / body.member_length(m);
            let material = &body.materials[member.material];
            let force = if self.stiffness[m] > 0.0 {
                material.youngs_modulus * self.modulus_factor[m] * strain * material.area
            } else {
                0.0
            };
            (strain, force)
        });
        let state = post_process(body, &self.dofs, u, forces, &internal, members);
        (state, internal)
    }
}

/// Per member its teeth when its material softens (from its first tooth's tensile strength in
/// `limits`, scattered or not), else none.
pub fn member_teeth(body: &Body, limits: &MemberLimits) -> Result<Vec<Vec<Tooth>>, SolveError> {
    body.members
        .iter()
        .enumerate()
        .map(|(m, member)| {
            let material = &body.materials[member.material];
            let (Some(softening), Some((tensile, _))) = (material.softening, limits[m]) else {
                return Ok(Vec::new());
            };
            if !tensile.is_finite() {
                return Ok(Vec::new());
            }
            let length = body.member_length(m);
            saw_tooth(
                material.youngs_modulus,
                tensile,
                length,
                softening.fracture_energy,
                softening.teeth,
            )
            .map_err(|least| SolveError::SofteningTooBrittle {
                body: body.name.clone(),
                member: m,
                fracture_energy: softening.fracture_energy,
                least,
                length,
            })
        })
        .collect()
}

fn factorization_error(body: &Body, e: CholeskyError) -> SolveError {
    SolveError::Factorization {
        body: body.name.clone(),
        message: e.to_string(),
    }
}
