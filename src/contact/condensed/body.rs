//! A linear body factored once per run and condensed on its contact candidates: compliance, rigid motions and the load patterns.

use crate::linalg::cholesky::{CholeskyError, SparseCholesky};
use crate::linkage::body_state::{factor_at, tangent_times};
use crate::linkage::mechanism::diagnose_mechanism;
use crate::linkage::rigid_modes::{free_rigid_modes, pinned_dofs_avoiding};
use crate::linkage::Mechanism;
use crate::linkage::{
    linear_member_block, prescribed_displacements, Body, DofMap, Schedule, StiffnessAssembly,
};
use crate::Real;
use faer::Mat;
use rayon::prelude::*;

/// A free DOF that is not a contact candidate.
pub(crate) const NOT_CANDIDATE: usize = usize::MAX;

/// The most candidate DOFs a body may have (its compliance is dense: 8,000 DOFs take 512 MB).
pub(crate) const MAX_CANDIDATE_DOFS: usize = 8_000;

/// Why a body was not condensed (the caller then solves the coupled system).
#[derive(Debug)]
pub(crate) enum CondenseFailure {
    /// Nodes move without stretching a member, with the rigid motions pinned.
    Mechanism(Box<Mechanism>),
    /// Another reason (too many candidates, a failed analysis): the coupled solve copes.
    Other,
}

impl From<String> for CondenseFailure {
    fn from(_: String) -> Self {
        CondenseFailure::Other
    }
}

impl From<&str> for CondenseFailure {
    fn from(_: &str) -> Self {
        CondenseFailure::Other
    }
}

/// One load schedule of a body: its load at full value and the displacement it gives.
struct Pattern {
    schedule: Schedule,
    /// Applied force minus the pull of the prescribed displacements, per free DOF, N.
    load: Vec<Real>,
    /// `K⁻¹ load` at the candidate slots, m.
    base: Vec<Real>,
}

/// A linear body factored once, condensed on its contact candidates.
///
/// A body with linear kinematics keeps its stiffness `K` for the whole run. Its contact
/// candidates (the surface nodes near another body or an obstacle) are ordered last in the
/// factorization, so the last block of the factor is the Cholesky factor of the Schur
/// complement `S` on the candidate DOFs; its inverse, the compliance `C = S⁻¹` (m/N), is
/// formed once per run. A body free to move rigidly (held only by contact) is pinned at one
/// DOF per free rigid motion, which makes `K` regular and its inverse a generalized inverse;
/// the rigid motions `R` are then unknowns of the contact problem, with the condition that the
/// forces on the body balance along them.
///
/// With contact forces `f̂` on the candidates and rigid motions `α`, the displacements of the
/// candidates are `u_C = u₀ + C f̂ + R_C α`, where `u₀ = K⁻¹ b` for the step's load `b`, summed
/// from one solve per load schedule. A Newton iteration of the contact problem is then a dense
/// problem of the size of the active contacts (see [`ContactJacobian`](super::ContactJacobian)); the whole
/// displacement field costs one solve per body per load step ([`CondensedBody::expand`]).
pub(crate) struct CondensedBody {
    /// Free index of each candidate slot (the compliance's rows), in factor order.
    pub cand: Vec<usize>,
    /// Candidate slot of each free index, or [`NOT_CANDIDATE`].
    pub slot: Vec<usize>,
    /// Which nodes are candidates.
    pub nodes: Vec<bool>,
    /// `C = S⁻¹` on the candidates, column-major, full, m/N.
    compliance: Vec<Real>,
    /// The rigid motions left free by the supports, over free DOFs, each scaled to a largest
    /// entry of one.
    pub modes: Vec<Vec<Real>>,
    /// The same at the candidate slots.
    pub modes_c: Vec<Vec<Real>>,
    /// Free indices held to make the stiffness regular (one per rigid motion).
    pins: Vec<usize>,
    /// The rigid motions, orthonormal (the projection `P = I − Q Qᵀ` of inertia relief).
    basis: Vec<Vec<Real>>,
    cholesky: SparseCholesky,
    patterns: Vec<Pattern>,
    /// Time of ordering and symbolic analysis, of the factorization and compliance, and of the
    /// pattern solves, s.
    pub seconds: [Real; 3],
    /// The largest diagonal entry of the stiffness, N/m: the force a displacement error of the
    /// interior makes.
    pub stiffness: Real,
}

impl CondensedBody {
    /// Factor `body` with the nodes marked in `nodes` last, form the compliance on them and
    /// solve each load schedule once. `Err` with the reason when the body cannot be condensed
    /// (a mechanism beyond rigid motions, too many candidates): the caller then solves the
    /// coupled system instead.
    pub fn new(
        body: &Body,
        dofs: &DofMap,
        assembly: &StiffnessAssembly,
        nodes: Vec<bool>,
    ) -> Result<Self, CondenseFailure> {
        let t = std::time::Instant::now();
        let n = assembly.n;
        let d = dofs.dofs_per_node;
        let mut slot = vec![NOT_CANDIDATE; n];
        let m = assembly.groups.iter().filter(|&&g| nodes[g]).count();
        if m > MAX_CANDIDATE_DOFS {
            return Err(format!("{m} candidate DOFs (at most {MAX_CANDIDATE_DOFS})").into());
        }
        // Each rigid motion scaled to move the farthest DOF by one: its amplitude is a length
        // and its stiffness `Bᵀ A⁻¹ B` compares with the penalties.
        let basis = free_rigid_modes(body, dofs);
        let mut modes = basis.clone();
        for r in &mut modes {
            let largest = r.iter().fold(0.0, |a: Real, v| a.max(v.abs()));
            if largest > 0.0 {
                r.iter_mut().for_each(|v| *v /= largest);
            }
        }
        // Pins as far from the candidates as the body allows (over its member graph): the
        // pinned solution of an unbalanced load bends the body around the pin.
        let far = far_from(body, &nodes);
        let avoid: Vec<bool> = assembly.groups.iter().map(|&g| !far[g]).collect();
        let pins = pinned_dofs_avoiding(&modes, &avoid);
        if pins.len() != modes.len() {
            return Err("the rigid motions cannot be pinned".into());
        }
        let mut cholesky = SparseCholesky::analyze_trailing(
            n,
            &assembly.col_ptr,
            &assembly.row_idx,
            &assembly.groups,
            &nodes,
            0,
        )
        .map_err(|e| e.to_string())?;
        let symbolic = t.elapsed().as_secs_f64();
        let t = std::time::Instant::now();
        let mut values = Vec::new();
        assembly.fill(body, |k| linear_member_block(body, k), &mut values);
        let mut pinned = vec![false; n];
        for &p in &pins {
            pinned[p] = true;
        }
        for c in 0..n {
            let range = assembly.col_ptr[c]..assembly.col_ptr[c + 1];
            for (&r, v) in assembly.row_idx[range.clone()]
                .iter()
                .zip(&mut values[range])
            {
                if r != c && (pinned[r] || pinned[c]) {
                    *v = 0.0;
                }
            }
        }
        let largest_diagonal = (0..n)
            .map(|c| values[assembly.col_ptr[c]])
            .fold(0.0, Real::max);
        match cholesky.factorize(&values) {
            Ok(()) => {}
            // The rigid motions are pinned: what is left singular moves inside the body.
            Err(CholeskyError::NonPositivePivot { dof })
            | Err(CholeskyError::NearlySingular { dof, .. }) => {
                let mechanism =
                    diagnose_mechanism(body, dofs, assembly, &values, &mut cholesky, dof);
                return Err(CondenseFailure::Mechanism(Box::new(mechanism)));
            }
            Err(_) => return Err(CondenseFailure::Other),
        }
        let (order, factor) = cholesky
            .trailing_factor(m)
            .ok_or("the factor has no trailing block")?;
        for (s, &i) in order.iter().enumerate() {
            if !nodes[assembly.groups[i]] {
                return Err("the candidates are not last in the factor".into());
            }
            slot[i] = s;
        }
        let mut compliance = inverse_from_factor(&factor);
        // A pinned DOF does not move: its row and column (only its own diagonal, as pinning
        // cut its couplings) are zero in the generalized inverse.
        for &p in &pins {
            let s = slot[p];
            if s != NOT_CANDIDATE {
                for j in 0..m {
                    compliance[s * m + j] = 0.0;
                    compliance[j * m + s] = 0.0;
                }
            }
        }
        let modes_c = modes
            .iter()
            .map(|r| order.iter().map(|&i| r[i]).collect())
            .collect();
        let numeric = t.elapsed().as_secs_f64();
        let t = std::time::Instant::now();
        // Inertia relief: with P = I − Q Qᵀ (Q the orthonormal rigid motions) the compliance is
        // Pᵀ K⁻¹ P on the candidates, C − Z_C Q_Cᵀ − Q_C Z_Cᵀ + Q_C (Qᵀ Z) Q_Cᵀ with Z = K⁻¹ Q:
        // an unbalanced load is balanced by a body force spread over every DOF instead of
        // being carried by the pins.
        let mut z = Vec::with_capacity(basis.len());
        for q in &basis {
            let mut x = q.clone();
            for &p in &pins {
                x[p] = 0.0;
            }
            cholesky.solve_in_place(&mut x);
            z.push(x);
        }
        let at = |v: &Vec<Real>| -> Vec<Real> { order.iter().map(|&i| v[i]).collect() };
        let zc: Vec<Vec<Real>> = z.iter().map(at).collect();
        let qc: Vec<Vec<Real>> = basis.iter().map(at).collect();
        for a in 0..basis.len() {
            for b in 0..basis.len() {
                let h: Real = basis[a].iter().zip(&z[b]).map(|(x, y)| x * y).sum();
                // `− Z_C Q_Cᵀ − Q_C Z_Cᵀ` pairs each rigid motion with its own `K⁻¹ q`: only
                // where a = b (with every pair, the compliance lost its symmetry's meaning
                // and became indefinite for more than one free rigid motion).
                let own = if a == b { 1.0 } else { 0.0 };
                let (za, qa, zb, qb) = (&zc[a], &qc[a], &zc[b], &qc[b]);
                // Columns side by side: the last body to finish its set-up runs this alone.
                compliance
                    .par_chunks_mut(m.max(1))
                    .enumerate()
                    .for_each(|(j, column)| {
                        for (i, c) in column.iter_mut().enumerate() {
                            *c += own * (-za[i] * qb[j] - qa[i] * zb[j]) + qa[i] * h * qb[j];
                        }
                    });
            }
        }
        let relief = t.elapsed().as_secs_f64();
        let t = std::time::Instant::now();
        let mut condensed = CondensedBody {
            cand: order,
            slot,
            nodes,
            compliance,
            modes,
            modes_c,
            pins,
            basis,
            cholesky,
            patterns: Vec::new(),
            seconds: [symbolic, numeric + relief, 0.0],
            stiffness: largest_diagonal,
        };
        // One solve per schedule of loads and prescribed displacements.
        let mut schedules: Vec<Schedule> = Vec::new();
        let prescribed = body
            .supports
            .iter()
            .filter(|s| s.displacement != nalgebra::Vector3::zeros());
        for s in body
            .loads
            .iter()
            .map(|l| &l.schedule)
            .chain(prescribed.map(|s| &s.schedule))
        {
            if !schedules.contains(s) {
                schedules.push(s.clone());
            }
        }
        for schedule in schedules {
            let mut full = vec![0.0; body.dof_count()];
            for l in body.loads.iter().filter(|l| l.schedule == schedule) {
                for k in 0..d {
                    full[l.node * d + k] += l.force[k];
                }
            }
            let u_s = prescribed_displacements(body, |s| Real::from(u8::from(*s == schedule)));
            // `K u_s` with the linear stiffness: the linear tangent at the undeformed state.
            let mut pull = vec![0.0; body.dof_count()];
            tangent_times(body, &vec![0.0; body.dof_count()], &u_s, &mut pull);
            let load: Vec<Real> = dofs.free.iter().map(|&f| full[f] - pull[f]).collect();
            let x = condensed.solve(&load);
            let base = condensed.cand.iter().map(|&i| x[i]).collect();
            condensed.patterns.push(Pattern {
                schedule,
                load,
                base,
            });
        }
        condensed.seconds[2] = t.elapsed().as_secs_f64();
        Ok(condensed)
    }

    /// Number of candidate DOFs.
    pub fn len(&self) -> usize {
        self.cand.len()
    }

    /// The load at pseudo-time `t` of `steps` (step units; between steps each schedule's
    /// factor is interpolated, see [`factor_at`]) per free DOF (N) and `K⁻¹` of it at the
    /// candidates (m).
    pub fn load_at(&self, t: Real, steps: usize) -> (Vec<Real>, Vec<Real>) {
        let mut load = vec![0.0; self.slot.len()];
        let mut base = vec![0.0; self.cand.len()];
        for p in &self.patterns {
            let f = factor_at(&p.schedule, t, steps);
            load.iter_mut().zip(&p.load).for_each(|(a, b)| *a += f * b);
            base.iter_mut().zip(&p.base).for_each(|(a, b)| *a += f * b);
        }
        (load, base)
    }

    /// `Pᵀ K⁻¹ P rhs` per free DOF, with `K⁻¹` the inverse with the pins held and
    /// `P = I − Q Qᵀ`: the displacement under the balanced part of `rhs`, without rigid motion.
    fn solve(&mut self, rhs: &[Real]) -> Vec<Real> {
        let mut x = rhs.to_vec();
        self.project(&mut x);
        for &p in &self.pins {
            x[p] = 0.0;
        }
        self.cholesky.solve_in_place(&mut x);
        self.project(&mut x);
        x
    }

    /// `x ← (I − Q Qᵀ) x`.
    fn project(&self, x: &mut [Real]) {
        for q in &self.basis {
            let p: Real = q.iter().zip(x.iter()).map(|(a, b)| a * b).sum();
            x.iter_mut().zip(q).for_each(|(v, a)| *v -= p * a);
        }
    }

    /// `C f` at the candidate slots, m, for contact forces `f` (N) at the slots (mostly zero).
    pub fn comply(&self, f: &[Real]) -> Vec<Real> {
        let m = self.cand.len();
        let mut y = vec![0.0; m];
        for (j, &fj) in f.iter().enumerate() {
            if fj != 0.0 {
                let column = &self.compliance[j * m..(j + 1) * m];
                y.iter_mut().zip(column).for_each(|(a, c)| *a += fj * c);
            }
        }
        y
    }

    /// Column `j` of the compliance.
    pub fn compliance_column(&self, j: usize) -> &[Real] {
        let m = self.cand.len();
        &self.compliance[j * m..(j + 1) * m]
    }

    /// The change of displacement of every free DOF, m, for a change `rhs` of the load and
    /// contact forces per free DOF (N) and `alpha` of the rigid amplitudes: `K⁻¹ rhs + R α`
    /// (one solve). Solving for changes keeps the solve's round-off relative to the change,
    /// as Newton's corrections do, not to the whole displacement.
    /// No change (the first step from rest) gives zeros without a solve: the exact zeros a
    /// solve of a zero load gives.
    pub fn expand(&mut self, rhs: &[Real], alpha: &[Real]) -> Vec<Real> {
        if rhs.iter().chain(alpha).all(|&v| v == 0.0) {
            return vec![0.0; rhs.len()];
        }
        let mut x = self.solve(rhs);
        for (r, &a) in self.modes.iter().zip(alpha) {
            x.iter_mut().zip(r).for_each(|(u, m)| *u += a * m);
        }
        x
    }
}

/// The nodes at least three quarters of the largest member-graph distance away from the
/// marked nodes (all nodes when none is marked).
fn far_from(body: &Body, marked: &[bool]) -> Vec<bool> {
    let n = body.nodes.len();
    let mut adjacency: Vec<Vec<usize>> = vec![Vec::new(); n];
    for member in &body.members {
        let [a, b] = member.nodes;
        adjacency[a].push(b);
        adjacency[b].push(a);
    }
    let mut distance = vec![usize::MAX; n];
    let mut queue: std::collections::VecDeque<usize> = (0..n).filter(|&i| marked[i]).collect();
    if queue.is_empty() {
        return vec![true; n];
    }
    for &i in &queue {
        distance[i] = 0;
    }
    while let Some(i) = queue.pop_front() {
        for &j in &adjacency[i] {
            if distance[j] == usize::MAX {
                distance[j] = distance[i] + 1;
                queue.push_back(j);
            }
        }
    }
    let largest = distance
        .iter()
        .filter(|&&d| d != usize::MAX)
        .max()
        .copied()
        .unwrap_or(0);
    distance
        .iter()
        .map(|&d| d != usize::MAX && 4 * d >= 3 * largest)
        .collect()
}

/// `(L Lᵀ)⁻¹` for a dense lower-triangular `L`, full and column-major.
fn inverse_from_factor(l: &Mat<Real>) -> Vec<Real> {
    let m = l.nrows();
    if m == 0 {
        return Vec::new();
    }
    let par = faer::Par::rayon(0);
    let mut out = Mat::<Real>::zeros(m, m);
    let mut mem =
        faer::dyn_stack::MemBuffer::new(faer::linalg::cholesky::llt::inverse::inverse_scratch::<
            Real,
        >(m, par));
    faer::linalg::cholesky::llt::inverse::inverse(
        out.as_mut(),
        l.as_ref(),
        par,
        faer::dyn_stack::MemStack::new(&mut mem),
    );
    // Column j of the full matrix: row j of the lower triangle above the diagonal, then
    // column j of it; the columns side by side.
    let mut full = vec![0.0; m * m];
    let lower = out.as_ref();
    full.par_chunks_mut(m).enumerate().for_each(|(j, column)| {
        for (i, c) in column.iter_mut().enumerate().take(j) {
            *c = lower[(j, i)];
        }
        for (i, c) in column.iter_mut().enumerate().skip(j) {
            *c = lower[(i, j)];
        }
    });
    full
}
