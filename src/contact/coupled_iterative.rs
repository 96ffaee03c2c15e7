//! The coupled tangent of bodies in contact solved by conjugate gradients when a body asks for the iterative solver: one CG on the whole coupled matrix (members, penalties, couplings between bodies), preconditioned block by block.
//!
//! Each body's diagonal block of the coupled matrix (its members plus the penalties of its
//! contacts) is the preconditioner of its rows: a smoothed-aggregation multigrid for a body
//! solved iteratively, its sparse Cholesky factor for one solved directly. The blocks are
//! built for a contact set and kept while the set stays (their values refilled each Newton
//! iteration, the multigrid hierarchy and the direct factors kept: they still precondition a
//! nearby tangent well); a solve that does not converge with old blocks rebuilds them once.
//! The couplings between bodies are left to the outer conjugate gradients, which always work
//! on the true coupled matrix, so the answer is that of the direct solve to the tolerance.
//! When they cannot converge (a singular block: a body held only by contacts it has not
//! reached) the caller factors the coupled matrix directly for that iteration.

use crate::contact::coupled_system::CoupledSystem;
use crate::contact::ContactSet;
use crate::linalg::multigrid::MODES;
use crate::linalg::{
    conjugate_gradient, CgSettings, Preconditioner, SmoothedAggregation, SparseCholesky,
    SymmetricCsr,
};
use crate::linkage::rigid_modes::rigid_body_rows;
use crate::linkage::{Body, DofMap, IterativeSettings, StiffnessAssembly};
use crate::Real;

/// How one body's rows are preconditioned.
enum BlockSolver {
    /// Not built yet (or the build failed).
    None,
    /// Smoothed-aggregation multigrid on the block.
    Multigrid(SmoothedAggregation),
    /// The block's Cholesky factor (a body solved directly).
    Direct(SparseCholesky),
}

/// One body's diagonal block of the coupled matrix.
struct Block {
    /// First global row and rows.
    start: usize,
    n: usize,
    /// The block's lower triangle (compressed columns) and the place of each entry in the
    /// coupled values.
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    source: Vec<usize>,
    /// The block in full rows (the multigrid's finest matrix), refilled each iteration.
    matrix: SymmetricCsr,
    /// Node of each row (a node's rows consecutive).
    groups: Vec<usize>,
    /// Rigid-body rows: the multigrid's near-null space.
    near_null_space: Vec<[Real; MODES]>,
    iterative: bool,
    solver: BlockSolver,
}

/// The blocks applied side by side: `z_b = M_b⁻¹ r_b`.
struct BlockPreconditioner<'a>(&'a mut [Block]);

impl Preconditioner for BlockPreconditioner<'_> {
    fn apply(&mut self, _a: &SymmetricCsr, r: &[Real], z: &mut [Real]) {
        for block in self.0.iter_mut() {
            let range = block.start..block.start + block.n;
            let (rb, zb) = (&r[range.clone()], &mut z[range]);
            match &mut block.solver {
                BlockSolver::Multigrid(m) => m.apply(&block.matrix, rb, zb),
                BlockSolver::Direct(c) => {
                    zb.copy_from_slice(rb);
                    c.solve_in_place(zb);
                }
                BlockSolver::None => zb.copy_from_slice(rb),
            }
        }
    }
}

/// Conjugate gradients on the coupled tangent of a contact scene (see the module notes).
pub(crate) struct CoupledIterative {
    /// Per body, whether it is solved iteratively.
    pub(crate) iterative: Vec<bool>,
    /// Per body, the free DOFs' nodes and rigid-body rows.
    groups: Vec<Vec<usize>>,
    near_null_space: Vec<Vec<[Real; MODES]>>,
    settings: IterativeSettings,
    /// The coupled matrix in full rows and the pattern size it was built for.
    matrix: Option<(SymmetricCsr, usize)>,
    blocks: Vec<Block>,
    /// The contact set the blocks' preconditioners were built for.
    built_for: Option<ContactSet>,
    /// Conjugate-gradient iterations so far.
    pub(crate) iterations: usize,
}

impl CoupledIterative {
    /// For `bodies` (their free DOFs in `dofs`, patterns in `assemblies`): `None` when every
    /// body is solved directly.
    pub(crate) fn new(
        bodies: &[Body],
        dofs: &[&DofMap],
        assemblies: &[&StiffnessAssembly],
    ) -> Option<Self> {
        let iterative: Vec<bool> = bodies
            .iter()
            .zip(assemblies)
            .map(|(b, a)| {
                b.solver.use_iterative_in_contact(
                    b.dimension.dofs_per_node(),
                    a.n,
                    !b.is_nonlinear(),
                )
            })
            .collect();
        if !iterative.iter().any(|&i| i) {
            return None;
        }
        // The strictest stopping rule of the iterative bodies.
        let mut settings = IterativeSettings::default();
        let chosen = bodies.iter().zip(&iterative).filter(|(_, &i)| i);
        for (k, (b, _)) in chosen.enumerate() {
            let s = b.solver.iterative;
            if k == 0 {
                settings = s;
            } else {
                settings.tolerance = settings.tolerance.min(s.tolerance);
                settings.max_iterations = settings.max_iterations.max(s.max_iterations);
            }
        }
        Some(CoupledIterative {
            iterative,
            groups: assemblies.iter().map(|a| a.groups.clone()).collect(),
            near_null_space: bodies
                .iter()
                .zip(dofs)
                .map(|(b, d)| rigid_body_rows(&b.nodes, d))
                .collect(),
            settings,
            matrix: None,
            blocks: Vec::new(),
            built_for: None,
            iterations: 0,
        })
    }

    /// Body `b`'s free DOFs changed (a piece of it removed, or given back): its rows' nodes
    /// and rigid-body rows anew from `body`, `dofs` and `assembly`; the coupled matrix and
    /// every block are built again at the next solve.
    pub(crate) fn renumber(
        &mut self,
        b: usize,
        body: &Body,
        dofs: &DofMap,
        assembly: &StiffnessAssembly,
    ) {
        self.groups[b] = assembly.groups.clone();
        self.near_null_space[b] = rigid_body_rows(&body.nodes, dofs);
        self.matrix = None;
        self.blocks.clear();
        self.built_for = None;
    }

    /// Solve `K δ = r` for the values now in `system` (filled for the contact set `set`), to
    /// `min(tolerance, settings) · max(‖r‖, reference)` with `reference` the force scale (N).
    /// `None` when conjugate gradients do not get there (the caller factors directly).
    pub(crate) fn solve(
        &mut self,
        system: &CoupledSystem,
        set: &ContactSet,
        r: &[Real],
        reference: Real,
        tolerance: Real,
    ) -> Option<Vec<Real>> {
        let nnz = system.row_idx().len();
        if self.matrix.as_ref().is_none_or(|(_, k)| *k != nnz) {
            // A new pattern (a contact between bodies added entries): new blocks.
            let m = SymmetricCsr::from_lower(system.n, system.col_ptr(), system.row_idx());
            self.matrix = Some((m, nnz));
            self.blocks = self.block_patterns(system);
            self.built_for = None;
        }
        let (matrix, _) = self.matrix.as_mut()?;
        matrix.refill(&system.values);
        for block in &mut self.blocks {
            let values: Vec<Real> = block.source.iter().map(|&p| system.values[p]).collect();
            block.matrix.refill(&values);
        }
        let settings = CgSettings {
            tolerance: tolerance.min(self.settings.tolerance),
            max_iterations: self.settings.max_iterations,
            reference_norm: reference,
        };
        let fresh = self.built_for.as_ref() != Some(set);
        if fresh {
            self.build(system);
            self.built_for = Some(set.clone());
        }
        let mut x = vec![0.0; r.len()];
        let (matrix, nnz) = self.matrix.take()?;
        let mut report = conjugate_gradient(
            &matrix,
            &mut BlockPreconditioner(&mut self.blocks),
            r,
            &mut x,
            settings,
        );
        self.iterations += report.iterations;
        if !report.converged && !fresh {
            // Blocks built for an older tangent: once more with blocks of this one.
            self.build(system);
            x.iter_mut().for_each(|v| *v = 0.0);
            report = conjugate_gradient(
                &matrix,
                &mut BlockPreconditioner(&mut self.blocks),
                r,
                &mut x,
                settings,
            );
            self.iterations += report.iterations;
        }
        self.matrix = Some((matrix, nnz));
        report.converged.then_some(x)
    }

    /// Each body's diagonal block pattern in the coupled pattern of `system`.
    fn block_patterns(&self, system: &CoupledSystem) -> Vec<Block> {
        let (col_ptr, row_idx) = (system.col_ptr(), system.row_idx());
        let mut blocks = Vec::with_capacity(self.iterative.len());
        for (b, &iterative) in self.iterative.iter().enumerate() {
            let start = system.offsets[b];
            let end = system.offsets.get(b + 1).copied().unwrap_or(system.n);
            let n = end - start;
            let mut bc = Vec::with_capacity(n + 1);
            let mut br = Vec::new();
            let mut source = Vec::new();
            bc.push(0);
            for c in start..end {
                let range = col_ptr[c]..col_ptr[c + 1];
                for (p, &r) in range.clone().zip(&row_idx[range]) {
                    if r < end {
                        br.push(r - start);
                        source.push(p);
                    }
                }
                bc.push(br.len());
            }
            blocks.push(Block {
                start,
                n,
                matrix: SymmetricCsr::from_lower(n, &bc, &br),
                col_ptr: bc,
                row_idx: br,
                source,
                groups: self.groups[b].clone(),
                near_null_space: self.near_null_space[b].clone(),
                iterative,
                solver: BlockSolver::None,
            });
        }
        blocks
    }

    /// Build every block's preconditioner for its current values (a block that cannot be
    /// built, singular, leaves its rows unpreconditioned: the outer solve then likely fails
    /// and the caller factors directly).
    fn build(&mut self, system: &CoupledSystem) {
        for block in &mut self.blocks {
            if block.n == 0 {
                continue;
            }
            let previous = std::mem::replace(&mut block.solver, BlockSolver::None);
            block.solver = if block.iterative {
                SmoothedAggregation::new(&block.matrix, &block.groups, &block.near_null_space)
                    .map_or(BlockSolver::None, BlockSolver::Multigrid)
            } else {
                let values: Vec<Real> = block.source.iter().map(|&p| system.values[p]).collect();
                let analyzed = match previous {
                    BlockSolver::Direct(c) => Ok(c),
                    _ => SparseCholesky::analyze(
                        block.n,
                        &block.col_ptr,
                        &block.row_idx,
                        Some(&block.groups),
                    ),
                };
                match analyzed {
                    Ok(mut c) => match c.factorize(&values) {
                        Ok(()) => BlockSolver::Direct(c),
                        Err(_) => BlockSolver::None,
                    },
                    Err(_) => BlockSolver::None,
                }
            };
        }
    }
}
