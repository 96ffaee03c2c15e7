//! A lattice stiffness system for the solver tests: one fixture instead of one per test module.

use crate::bench::lattice_body;
use crate::linkage::{
    axial_stiffness, member_block, Body, DofMap, StiffnessAssembly, SymmetricCsr,
};
use crate::Real;

/// `K_ff` of a lattice of `cells` with its bottom face fixed (see [`lattice_body`]).
pub(crate) struct LatticeSystem {
    pub body: Body,
    pub assembly: StiffnessAssembly,
    /// Lower-triangle values in the assembly's pattern.
    pub values: Vec<Real>,
    /// The same matrix in full rows.
    pub matrix: SymmetricCsr,
    /// Direction (0, 1, 2) of every free DOF.
    pub directions: Vec<usize>,
}

pub(crate) fn lattice_system(cells: [usize; 3]) -> LatticeSystem {
    let body = lattice_body(cells).expect("valid lattice");
    let dofs = DofMap::new(&body);
    let assembly = StiffnessAssembly::new(&body, &dofs).expect("small lattice");
    let mut values = Vec::new();
    assembly.fill(
        &body,
        |m| {
            let [a, b] = body.members[m].nodes;
            let k = axial_stiffness(&body.materials[0], body.member_length(m));
            member_block(&body.nodes[a], &body.nodes[b], k)
        },
        &mut values,
    );
    let mut matrix = SymmetricCsr::from_lower(assembly.n, &assembly.col_ptr, &assembly.row_idx);
    matrix.refill(&values);
    let directions = dofs.free.iter().map(|d| d % dofs.dofs_per_node).collect();
    LatticeSystem {
        body,
        assembly,
        values,
        matrix,
        directions,
    }
}
