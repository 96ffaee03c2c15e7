//! The rigid motions a body's supports leave free, the DOFs that pin them, and the rigid-body
//! rows of the multigrid's near-null space.
//!
//! A body held only by contact (no supports, or supports that leave it free to slide) has a
//! singular stiffness matrix whose null space is those rigid motions. Fixing one DOF per free
//! motion, chosen so that the motions are independent on them (a statically determinate
//! pinning), gives a regular matrix whose inverse is a generalized inverse of the singular one:
//! for a self-equilibrated load it returns one of its solutions.

use crate::linalg::multigrid::MODES;
use crate::linkage::{Body, Dimension, DofMap};
use crate::Real;
use nalgebra::{DMatrix, SymmetricEigen, Vector3};

/// The rigid motions of `body` that its supports allow, over its free DOFs (in the order of
/// `dofs.free`), orthonormal: translations and rotations about the centroid (6 in 3D, 3 in 2D)
/// combined so that every supported DOF stays still. Empty for a body held in place.
pub fn free_rigid_modes(body: &Body, dofs: &DofMap) -> Vec<Vec<Real>> {
    let d = dofs.dofs_per_node;
    if body.nodes.is_empty() {
        return Vec::new();
    }
    let centroid =
        body.nodes.iter().fold(Vector3::zeros(), |s, x| s + x) / body.nodes.len() as Real;
    let size = body
        .nodes
        .iter()
        .map(|x| (x - centroid).norm())
        .fold(0.0, Real::max)
        .max(Real::MIN_POSITIVE);
    // Rotations scaled by the body's size so that every mode has entries of order one.
    let axes: Vec<Vector3<Real>> = match body.dimension {
        Dimension::Two => vec![Vector3::z()],
        Dimension::Three => vec![Vector3::x(), Vector3::y(), Vector3::z()],
    };
    let count = d + axes.len();
    let value = |dof: usize, mode: usize| -> Real {
        let (node, k) = (dof / d, dof % d);
        if mode < d {
            Real::from(u8::from(mode == k))
        } else {
            axes[mode - d].cross(&((body.nodes[node] - centroid) / size))[k]
        }
    };
    // Coefficients c with Σ c_j mode_j = 0 on every supported DOF: the null space of QᵀQ.
    let mut qtq = DMatrix::<Real>::zeros(count, count);
    for &dof in &dofs.supported {
        for i in 0..count {
            for j in 0..count {
                qtq[(i, j)] += value(dof, i) * value(dof, j);
            }
        }
    }
    let eigen = SymmetricEigen::new(qtq);
    let mut modes: Vec<Vec<Real>> = Vec::new();
    for (e, &lambda) in eigen.eigenvalues.iter().enumerate() {
        if lambda > 1e-9 {
            continue;
        }
        let c = eigen.eigenvectors.column(e);
        let mut v: Vec<Real> = dofs
            .free
            .iter()
            .map(|&dof| (0..count).map(|j| c[j] * value(dof, j)).sum())
            .collect();
        // Gram–Schmidt against the modes kept so far (twice, for round-off).
        for _ in 0..2 {
            for m in &modes {
                let p: Real = m.iter().zip(&v).map(|(a, b)| a * b).sum();
                v.iter_mut().zip(m).for_each(|(x, y)| *x -= p * y);
            }
        }
        let norm = v.iter().map(|x| x * x).sum::<Real>().sqrt();
        if norm > 1e-9 {
            v.iter_mut().for_each(|x| *x /= norm);
            modes.push(v);
        }
    }
    modes
}

/// The rigid-body motions about the centroid of `nodes` (positions, m) as the multigrid's
/// near-null space: one row per free DOF of `dofs` (in the order of `dofs.free`), the
/// translation along the DOF's direction first, then the rotations (about z in 2D, in row
/// 2; about x, y, z in 3D, in rows 3 to 5: the axis × the position about the centroid, m);
/// the other values zero. Not normalised: the multigrid orthonormalises per aggregate.
pub fn rigid_body_rows(nodes: &[Vector3<Real>], dofs: &DofMap) -> Vec<[Real; MODES]> {
    let centre = nodes.iter().sum::<Vector3<Real>>() / nodes.len().max(1) as Real;
    let mut rows = vec![[0.0; MODES]; dofs.free.len()];
    for (row, &dof) in rows.iter_mut().zip(&dofs.free) {
        let (node, d) = dofs.node_and_direction(dof);
        let p = nodes[node] - centre;
        row[d] = 1.0;
        if dofs.dofs_per_node == 2 {
            // Rotation about z: (−y, x).
            row[2] = if d == 0 { -p.y } else { p.x };
        } else {
            // Rotations about x, y, z: a × p.
            let rx = Vector3::new(0.0, -p.z, p.y);
            let ry = Vector3::new(p.z, 0.0, -p.x);
            let rz = Vector3::new(-p.y, p.x, 0.0);
            row[3] = rx[d];
            row[4] = ry[d];
            row[5] = rz[d];
        }
    }
    rows
}

/// One free DOF per mode such that the modes restricted to them are independent (greedy:
/// each pick is the DOF where the modes differ most from the picks so far), as free indices.
pub fn pinned_dofs(modes: &[Vec<Real>]) -> Vec<usize> {
    pinned_dofs_avoiding(modes, &[])
}

/// [`pinned_dofs`] preferring the free indices not marked in `avoid` (a pin carries the whole
/// out-of-balance load of the pinned solution: kept away from the contact candidates, it
/// deforms the body only where contact does not look). Falls back to every DOF when the
/// others cannot hold all the modes.
pub fn pinned_dofs_avoiding(modes: &[Vec<Real>], avoid: &[bool]) -> Vec<usize> {
    if avoid.iter().any(|&a| a) {
        let picks = pick_pins(modes, |i| !avoid.get(i).copied().unwrap_or(false));
        if picks.len() == modes.len() {
            return picks;
        }
    }
    pick_pins(modes, |_| true)
}

fn pick_pins(modes: &[Vec<Real>], allowed: impl Fn(usize) -> bool) -> Vec<usize> {
    let r = modes.len();
    let Some(n) = modes.first().map(Vec::len) else {
        return Vec::new();
    };
    let row = |i: usize| -> Vec<Real> { modes.iter().map(|m| m[i]).collect() };
    let mut basis: Vec<Vec<Real>> = Vec::with_capacity(r);
    let mut picks = Vec::with_capacity(r);
    for _ in 0..r {
        let mut best = (0.0, 0, Vec::new());
        for i in (0..n).filter(|&i| allowed(i)) {
            let mut v = row(i);
            for b in &basis {
                let p: Real = b.iter().zip(&v).map(|(a, c)| a * c).sum();
                v.iter_mut().zip(b).for_each(|(x, y)| *x -= p * y);
            }
            let norm = v.iter().map(|x| x * x).sum::<Real>().sqrt();
            if norm > best.0 {
                best = (norm, i, v);
            }
        }
        let (norm, i, mut v) = best;
        if norm <= 1e-6 {
            break;
        }
        v.iter_mut().for_each(|x| *x /= norm);
        basis.push(v);
        picks.push(i);
    }
    picks
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linkage::{generators, Material, Support};

    fn cube() -> Body {
        let g = generators::box_lattice([1.0, 1.0, 1.0], [2, 2, 2]).unwrap();
        Body::from_geometry("cube", g, Material::new("m", 1e7, 1e-4))
    }

    #[test]
    fn a_free_body_has_six_modes_and_a_pinned_one_none() {
        let mut body = cube();
        let dofs = DofMap::new(&body);
        let modes = free_rigid_modes(&body, &dofs);
        assert_eq!(modes.len(), 6);
        // Orthonormal.
        for (i, a) in modes.iter().enumerate() {
            for (j, b) in modes.iter().enumerate() {
                let p: Real = a.iter().zip(b).map(|(x, y)| x * y).sum();
                assert!((p - Real::from(u8::from(i == j))).abs() < 1e-12);
            }
        }
        // K times every mode vanishes (to 1e-9 of K's scale).
        let assembly = crate::linkage::StiffnessAssembly::new(&body, &dofs).unwrap();
        let mut values = Vec::new();
        assembly.fill(
            &body,
            |m| {
                let [a, b] = body.members[m].nodes;
                crate::linkage::member_block(&body.nodes[a], &body.nodes[b], 1.0)
            },
            &mut values,
        );
        for m in &modes {
            let mut y = vec![0.0; m.len()];
            assembly.multiply(&values, m, &mut y);
            assert!(y.iter().all(|v| v.abs() < 1e-12), "K R ≠ 0");
        }
        let pins = pinned_dofs(&modes);
        assert_eq!(pins.len(), 6);
        // The modes restricted to the pins are independent: their 6×6 matrix is regular.
        let rp = DMatrix::from_fn(6, 6, |i, j| modes[j][pins[i]]);
        assert!(rp.determinant().abs() > 1e-6);
        // Two corners fixed on a vertical line in x and z: only the vertical slide is left.
        // Two vertical lines of nodes held in x and z (the upper box of the contact benchmark).
        let held: Vec<usize> = (0..body.nodes.len())
            .filter(|&n| {
                let p = body.nodes[n];
                (p.x == 0.0 && p.z == 0.0) || (p.x == 1.0 && p.z == 1.0)
            })
            .collect();
        for node in held {
            body.supports
                .push(Support::fixed(node, [true, false, true]));
        }
        let dofs = DofMap::new(&body);
        let modes = free_rigid_modes(&body, &dofs);
        assert_eq!(modes.len(), 1);
        let slide: Vec<Real> = dofs
            .free
            .iter()
            .map(|&dof| Real::from(u8::from(dof % 3 == 1)))
            .collect();
        let p: Real = modes[0].iter().zip(&slide).map(|(a, b)| a * b).sum();
        let norm = slide.iter().map(|x| x * x).sum::<Real>().sqrt();
        assert!(
            (p.abs() - norm).abs() < 1e-9 * norm,
            "the mode is the vertical slide"
        );
    }
}
