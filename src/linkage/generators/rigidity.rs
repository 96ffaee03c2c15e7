//! Test-only checks shared by the generators.
//!
//! Rigidity once supported, small solves, outward patches, patch edges being members.

use crate::linkage::{check_members, Geometry};
use crate::Real;
use nalgebra::{DMatrix, DVector, SymmetricEigen, Vector3};
use std::collections::HashSet;

/// The stiffness of `g` with every member at `k = 1`: per member the blocks
/// `k[nnᵀ −nnᵀ; −nnᵀ nnᵀ]`, n its unit direction (2×2 blocks in 2D).
fn unit_stiffness(g: &Geometry) -> DMatrix<Real> {
    let d = g.dimension.dofs_per_node();
    let size = g.nodes.len() * d;
    let mut k = DMatrix::<Real>::zeros(size, size);
    for &[a, b] in &g.members {
        let n = (g.nodes[b] - g.nodes[a]).normalize();
        for (p, q, sign) in [(a, a, 1.0), (b, b, 1.0), (a, b, -1.0), (b, a, -1.0)] {
            for i in 0..d {
                for j in 0..d {
                    k[(p * d + i, q * d + j)] += sign * n[i] * n[j];
                }
            }
        }
    }
    k
}

/// The DOFs (node · dofs_per_node + direction) not listed in `fixed` (`(node, direction)` pairs).
fn free_dofs(g: &Geometry, fixed: &[(usize, usize)]) -> Vec<usize> {
    let d = g.dimension.dofs_per_node();
    let held: HashSet<usize> = fixed.iter().map(|&(node, dir)| node * d + dir).collect();
    (0..g.nodes.len() * d)
        .filter(|i| !held.contains(i))
        .collect()
}

/// `K_ff`: the unit stiffness restricted to the DOFs not in `fixed`.
fn free_stiffness(g: &Geometry, free: &[usize]) -> DMatrix<Real> {
    let k = unit_stiffness(g);
    DMatrix::from_fn(free.len(), free.len(), |i, j| k[(free[i], free[j])])
}

/// The smallest and largest eigenvalue of `K_ff` with every member at `k = 1`.
pub fn free_stiffness_extremes(g: &Geometry, fixed: &[(usize, usize)]) -> (Real, Real) {
    let eigen = SymmetricEigen::new(free_stiffness(g, &free_dofs(g, fixed))).eigenvalues;
    (eigen.min(), eigen.max())
}

/// The displacements of the nodes under `forces` (one per node) with every member at
/// `k = 1` and the DOFs in `fixed` held at zero.
pub fn solve_unit_truss(
    g: &Geometry,
    fixed: &[(usize, usize)],
    forces: &[Vector3<Real>],
) -> Vec<Vector3<Real>> {
    let d = g.dimension.dofs_per_node();
    let free = free_dofs(g, fixed);
    let f = DVector::from_fn(free.len(), |i, _| forces[free[i] / d][free[i] % d]);
    let u = free_stiffness(g, &free)
        .cholesky()
        .expect("K_ff is positive definite")
        .solve(&f);
    let mut out = vec![Vector3::zeros(); g.nodes.len()];
    for (i, &dof) in free.iter().enumerate() {
        out[dof / d][dof % d] = u[i];
    }
    out
}

/// Panic unless `K_ff` is positive definite with a condition number below 1e8.
pub fn assert_rigid(g: &Geometry, fixed: &[(usize, usize)], what: &str) {
    let (lo, hi) = free_stiffness_extremes(g, fixed);
    assert!(
        lo > 1e-8 * hi,
        "{what}: K_ff eigenvalues {lo:e} .. {hi:e}: a mechanism"
    );
}

/// Panic unless the member list passes [`check_members`].
pub fn assert_members_valid(g: &Geometry) {
    if let Err(p) = check_members(&g.nodes, g.members.iter().copied()) {
        panic!("{p:?}");
    }
}

/// Panic unless every edge of every patch is a member.
pub fn assert_patch_edges_are_members(g: &Geometry) {
    let members: HashSet<[usize; 2]> = g
        .members
        .iter()
        .map(|&[a, b]| [a.min(b), a.max(b)])
        .collect();
    for t in &g.patches {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            assert!(
                members.contains(&[a.min(b), a.max(b)]),
                "patch {t:?}: edge {a}-{b} is not a member"
            );
        }
    }
}

/// The unnormalised normal of a patch, `(b − a) × (c − a)`: outward for a counter-clockwise patch.
pub fn patch_normal(g: &Geometry, t: [usize; 3]) -> Vector3<Real> {
    let [a, b, c] = t.map(|n| g.nodes[n]);
    (b - a).cross(&(c - a))
}

/// The centroid of a patch.
pub fn patch_centroid(g: &Geometry, t: [usize; 3]) -> Vector3<Real> {
    t.iter().map(|&n| g.nodes[n]).sum::<Vector3<Real>>() / 3.0
}
