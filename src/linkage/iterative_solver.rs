//! `K_ff x = b` by conjugate gradients with a smoothed-aggregation multigrid preconditioner:
//! the pattern in full rows is built once, the values refilled, the hierarchy rebuilt only when
//! the matrix has drifted far enough that the iterations grow, every solve warm-started.

use crate::linalg::multigrid::MODES;
use crate::linalg::{
    conjugate_gradient, dot, CgReport, CgSettings, MultigridError, SmoothedAggregation,
    SymmetricCsr,
};
use crate::linkage::rigid_modes::rigid_body_rows;
use crate::linkage::{DofMap, IterativeSettings, StiffnessAssembly};
use crate::Real;
use nalgebra::Vector3;

/// Past solutions kept for warm starts.
const WARM_START_VECTORS: usize = 6;

/// The iterative solver of one body's `K_ff`.
pub(crate) struct IterativeSolver {
    matrix: SymmetricCsr,
    multigrid: Option<SmoothedAggregation>,
    groups: Vec<usize>,
    /// The multigrid's near-null space: the rigid-body rows of every free DOF.
    near_null_space: Vec<[Real; MODES]>,
    settings: IterativeSettings,
    /// Iterations of the first solve with the current hierarchy: the yardstick for rebuilding.
    fresh_iterations: Option<usize>,
    /// Whether the values changed since the hierarchy was built.
    stale: bool,
    /// Recent solutions, newest last: the warm start is their best combination for the new
    /// right-hand side under the current matrix.
    history: std::collections::VecDeque<Vec<Real>>,
    /// Conjugate-gradient iterations, all solves.
    pub iterations: usize,
    /// Wall time of building multigrid hierarchies, all solves, s.
    pub setup_seconds: Real,
}

impl IterativeSolver {
    /// The full-row pattern of `K_ff` for `assembly` (values zero until [`Self::refill`]).
    pub(crate) fn new(
        assembly: &StiffnessAssembly,
        dofs: &DofMap,
        nodes: &[Vector3<Real>],
        settings: IterativeSettings,
    ) -> Self {
        let matrix = SymmetricCsr::from_lower(assembly.n, &assembly.col_ptr, &assembly.row_idx);
        Self::with_matrix(matrix, assembly, dofs, nodes, settings)
    }

    fn with_matrix(
        matrix: SymmetricCsr,
        assembly: &StiffnessAssembly,
        dofs: &DofMap,
        nodes: &[Vector3<Real>],
        settings: IterativeSettings,
    ) -> Self {
        IterativeSolver {
            matrix,
            multigrid: None,
            groups: assembly.groups.clone(),
            near_null_space: rigid_body_rows(nodes, dofs),
            settings,
            fresh_iterations: None,
            stale: false,
            history: std::collections::VecDeque::new(),
            iterations: 0,
            setup_seconds: 0.0,
        }
    }

    /// The iterative solver of a `K_ff` filled once (`lower_values` in the assembly's order):
    /// it keeps no refill map, so [`Self::refill`] and [`Self::lower_values`] do not apply.
    pub(crate) fn with_values(
        assembly: &StiffnessAssembly,
        lower_values: &[Real],
        dofs: &DofMap,
        nodes: &[Vector3<Real>],
        settings: IterativeSettings,
    ) -> Self {
        let matrix = SymmetricCsr::from_lower_values(
            assembly.n,
            &assembly.col_ptr,
            &assembly.row_idx,
            lower_values,
        );
        Self::with_matrix(matrix, assembly, dofs, nodes, settings)
    }

    /// New values of `K_ff` (lower triangle in the assembly's order). The hierarchy is kept: it
    /// still preconditions a nearby matrix well, and is rebuilt when the iterations say so.
    pub(crate) fn refill(&mut self, lower_values: &[Real]) {
        self.matrix.refill(lower_values);
        self.stale = self.multigrid.is_some();
    }

    fn rebuild(&mut self) -> Result<(), MultigridError> {
        let started = std::time::Instant::now();
        self.multigrid = None;
        self.multigrid = Some(SmoothedAggregation::new(
            &self.matrix,
            &self.groups,
            &self.near_null_space,
        )?);
        self.fresh_iterations = None;
        self.stale = false;
        self.setup_seconds += started.elapsed().as_secs_f64();
        Ok(())
    }

    /// Solve `K x = b` to `‖b − K x‖ ≤ tolerance · max(‖b‖, reference)`, starting from the best
    /// guess at hand (see [`Self::warm_start`]). Returns the report; `x` holds the answer (or
    /// the last iterate).
    ///
    /// For a Newton correction `K δ = r`, `reference` is the load's norm: this is exactly
    /// solving for the new displacement `K u_new = K u_old + r` to `tolerance` of the load,
    /// warm-started from the previous iterate `u_old`. With warm starts off, each solve starts
    /// from zero and is taken to `tolerance` of its own right-hand side, as a cold solve of the
    /// new displacement would be.
    pub(crate) fn solve(
        &mut self,
        b: &[Real],
        x: &mut [Real],
        reference: Real,
    ) -> Result<CgReport, MultigridError> {
        if self.multigrid.is_none() {
            self.rebuild()?;
        }
        self.warm_start(b, x);
        let settings = CgSettings {
            tolerance: self.settings.tolerance,
            max_iterations: self.settings.max_iterations,
            reference_norm: if self.settings.warm_start {
                reference
            } else {
                0.0
            },
        };
        let mut report = self.run(b, x, settings);
        // A hierarchy built for an older matrix that now needs many more iterations (or fails)
        // is rebuilt, and the solve continues from where it stopped.
        let yardstick = self.fresh_iterations.unwrap_or(usize::MAX);
        if self.stale && (!report.converged || report.iterations > 2 * yardstick + 4) {
            self.rebuild()?;
            let more = self.run(b, x, settings);
            report = CgReport {
                iterations: report.iterations + more.iterations,
                ..more
            };
            self.fresh_iterations = Some(more.iterations);
        } else if self.fresh_iterations.is_none() {
            self.fresh_iterations = Some(report.iterations);
        }
        if report.converged && self.settings.warm_start {
            if self.history.len() == WARM_START_VECTORS {
                self.history.pop_front();
            }
            self.history.push_back(x.to_vec());
        }
        Ok(report)
    }

    fn run(&mut self, b: &[Real], x: &mut [Real], settings: CgSettings) -> CgReport {
        let Some(m) = self.multigrid.as_mut() else {
            return CgReport {
                iterations: 0,
                residual: Real::INFINITY,
                converged: false,
                breakdown: true,
            };
        };
        let report = conjugate_gradient(&self.matrix, m, b, x, settings);
        self.iterations += report.iterations;
        report
    }

    /// The Galerkin combination of recent solutions: x = V c with (Vᵀ K V) c = Vᵀ b, K the
    /// current matrix (one product per stored solution: the matrix has changed since they
    /// were solved, and a projection with the old one can start worse than zero). This is the
    /// best start in span V in the energy norm; V holds the last step's answers and the last
    /// Newton corrections, so the new answer scaled from the old is in it. The solver starts
    /// from zero if the combination is worse.
    fn warm_start(&self, b: &[Real], x: &mut [Real]) {
        let k = self.history.len();
        if !self.settings.warm_start || k == 0 || x.iter().any(|v| *v != 0.0) {
            return;
        }
        let products: Vec<Vec<Real>> = self
            .history
            .iter()
            .map(|v| {
                let mut y = vec![0.0; v.len()];
                self.matrix.multiply(v, &mut y);
                y
            })
            .collect();
        // Vᵀ K V, symmetrised against round-off.
        let g = nalgebra::DMatrix::from_fn(k, k, |i, j| {
            0.5 * (dot(&self.history[i], &products[j]) + dot(&self.history[j], &products[i]))
        });
        let rhs = nalgebra::DVector::from_fn(k, |i, _| dot(&self.history[i], b));
        let eigen = g.symmetric_eigen();
        let largest = eigen.eigenvalues.iter().copied().fold(0.0, Real::max);
        if largest.is_nan() || largest <= 0.0 {
            return;
        }
        // Pseudo-inverse: nearly dependent past solutions add nothing but round-off.
        let mut c = nalgebra::DVector::zeros(k);
        for (m, &lambda) in eigen.eigenvalues.iter().enumerate() {
            if lambda > 1e-10 * largest {
                let q = eigen.eigenvectors.column(m);
                c += q * (q.dot(&rhs) / lambda);
            }
        }
        for (i, v) in self.history.iter().enumerate() {
            let ci = c[i];
            if ci != 0.0 && ci.is_finite() {
                x.iter_mut().zip(v).for_each(|(xi, vi)| *xi += ci * vi);
            }
        }
    }

    /// The current lower-triangle values (for a fallback to the direct solver); only for a
    /// solver made by [`Self::new`], which keeps the refill map.
    pub(crate) fn lower_values(&self, assembly: &StiffnessAssembly) -> Vec<Real> {
        self.matrix.lower_values(assembly.nnz())
    }
}
