//! Naming the nodes of a mechanism when `K_ff` is singular.
//!
//! Find a displacement mode that stretches no member and report which nodes it moves, in
//! which directions.

use crate::linalg::cholesky::SparseCholesky;
use crate::linkage::{direction_name, Body, DofMap, StiffnessAssembly};
use crate::Real;
use nalgebra::{DMatrix, DVector, Vector3};
use std::fmt;

/// Nodes that can move without stretching any member: why `K_ff` is singular.
#[derive(Clone, Debug, PartialEq)]
pub struct Mechanism {
    /// Body name.
    pub body: String,
    /// The node (0-based) and direction where the factorization met the zero pivot.
    pub pivot: (usize, usize),
    /// Nodes (0-based) the mode moves, largest motion first, with the directions they move in.
    pub moving: Vec<(usize, Vec<usize>)>,
    /// Whether the mode is a rigid motion of the whole body (its supports do not hold it).
    pub rigid: bool,
    /// Whether a zero-energy mode was found (false: the matrix is only nearly singular).
    pub mode_found: bool,
}

impl fmt::Display for Mechanism {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (node, dir) = self.pivot;
        if !self.mode_found {
            return write!(
                f,
                "body '{}': the stiffness matrix is singular to working precision at node {} ({}): \
                 the structure there is (nearly) a mechanism; check the members around that node",
                self.body,
                node + 1,
                direction_name(dir)
            );
        }
        let list: Vec<String> = self
            .moving
            .iter()
            .take(12)
            .map(|(n, dirs)| {
                let d: Vec<&str> = dirs.iter().map(|&d| direction_name(d)).collect();
                format!("{} ({})", n + 1, d.join(", "))
            })
            .collect();
        let more = if self.moving.len() > 12 {
            format!(" and {} more", self.moving.len() - 12)
        } else {
            String::new()
        };
        if self.rigid {
            write!(
                f,
                "body '{}' is a mechanism: its supports leave a rigid-body motion free (a translation \
                 or a rotation of the whole body); moving nodes: {}{}. Add supports that fix more \
                 directions (a 2D body needs 3 independent fixed directions, a 3D body 6)",
                self.body,
                list.join(", "),
                more
            )
        } else {
            write!(
                f,
                "body '{}' is a mechanism: nodes {}{} can move without stretching any member \
                 (zero pivot at node {} ({})). Add members or supports that hold them",
                self.body,
                list.join(", "),
                more,
                node + 1,
                direction_name(dir)
            )
        }
    }
}

/// Find a zero-energy mode through the DOF `pivot` (a free index) by inverse iteration on
/// `K_ff + σ D` (D its diagonal, σ = 1e-9): the shift makes the matrix positive definite, and
/// a mode with `Kx ≈ 0` dominates after a few iterations since its eigenvalue is ~σ while
/// every stiff mode's is ~1.
pub(crate) fn diagnose_mechanism(
    body: &Body,
    dofs: &DofMap,
    assembly: &StiffnessAssembly,
    values: &[Real],
    cholesky: &mut SparseCholesky,
    pivot: usize,
) -> Mechanism {
    let pivot_dof = dofs.free[pivot.min(dofs.free.len() - 1)];
    let mut report = Mechanism {
        body: body.name.clone(),
        pivot: dofs.node_and_direction(pivot_dof),
        moving: Vec::new(),
        rigid: false,
        mode_found: false,
    };
    let n = assembly.n;
    const SHIFT: Real = 1e-9;
    let diag: Vec<Real> = (0..n)
        .map(|c| values[assembly.col_ptr[c]].abs().max(Real::MIN_POSITIVE))
        .collect();
    let mut shifted = values.to_vec();
    for c in 0..n {
        let scale = if values[assembly.col_ptr[c]] > 0.0 {
            diag[c]
        } else {
            // A DOF with no stiffness at all: shift by the typical diagonal instead.
            diag.iter().sum::<Real>() / n as Real
        };
        shifted[assembly.col_ptr[c]] += SHIFT * scale;
    }
    if cholesky.factorize(&shifted).is_err() {
        return report;
    }
    let mut x = vec![0.0; n];
    x[pivot.min(n - 1)] = 1.0;
    let mut kx = vec![0.0; n];
    for _ in 0..6 {
        for i in 0..n {
            x[i] *= diag[i];
        }
        cholesky.solve_in_place(&mut x);
        let norm = x
            .iter()
            .zip(&diag)
            .map(|(v, d)| v * v * d)
            .sum::<Real>()
            .sqrt();
        if !(norm.is_finite() && norm > 0.0) {
            return report;
        }
        x.iter_mut().for_each(|v| *v /= norm);
    }
    assembly.multiply(values, &x, &mut kx);
    let energy: Real = x.iter().zip(&kx).map(|(a, b)| a * b).sum();
    let scale: Real = x.iter().zip(&diag).map(|(v, d)| v * v * d).sum();
    if energy.is_nan() || energy.abs() > 1e-6 * scale {
        return report;
    }
    report.mode_found = true;

    let d = dofs.dofs_per_node;
    let mut u = vec![Vector3::<Real>::zeros(); body.nodes.len()];
    for (i, &dof) in dofs.free.iter().enumerate() {
        u[dof / d][dof % d] = x[i];
    }
    let largest = u.iter().map(|v| v.norm()).fold(0.0, Real::max);
    let mut moving: Vec<(usize, Real)> = u
        .iter()
        .enumerate()
        .filter(|(_, v)| v.norm() > 1e-3 * largest)
        .map(|(i, v)| (i, v.norm()))
        .collect();
    moving.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    report.moving = moving
        .iter()
        .map(|&(i, size)| {
            let dirs = (0..d).filter(|&k| u[i][k].abs() > 1e-3 * size).collect();
            (i, dirs)
        })
        .collect();
    report.rigid = report.moving.len() > 1 && is_rigid_motion(body, &u);
    report
}

/// Whether a displacement field is (to 1e-6 relative) a rigid translation plus an
/// infinitesimal rotation `t + ω × p` of the whole body.
fn is_rigid_motion(body: &Body, u: &[Vector3<Real>]) -> bool {
    let d = body.dimension.dofs_per_node();
    // Unknowns: translation (d) and rotation (1 in 2D: about z; 3 in 3D).
    let unknowns = if d == 2 { 3 } else { 6 };
    let rows = body.nodes.len() * d;
    let mut a = DMatrix::<Real>::zeros(rows, unknowns);
    let mut b = DVector::<Real>::zeros(rows);
    let c = body.nodes.iter().sum::<Vector3<Real>>() / body.nodes.len() as Real;
    for (i, p) in body.nodes.iter().enumerate() {
        let p = p - c;
        for k in 0..d {
            let r = i * d + k;
            a[(r, k)] = 1.0;
            b[r] = u[i][k];
        }
        if d == 2 {
            // ω ẑ × p = (−ω p_y, ω p_x)
            a[(i * 2, 2)] = -p.y;
            a[(i * 2 + 1, 2)] = p.x;
        } else {
            // ω × p = (ω_y p_z − ω_z p_y, ω_z p_x − ω_x p_z, ω_x p_y − ω_y p_x)
            a[(i * 3, 4)] = p.z;
            a[(i * 3, 5)] = -p.y;
            a[(i * 3 + 1, 3)] = -p.z;
            a[(i * 3 + 1, 5)] = p.x;
            a[(i * 3 + 2, 3)] = p.y;
            a[(i * 3 + 2, 4)] = -p.x;
        }
    }
    let ata = a.transpose() * &a;
    let atb = a.transpose() * &b;
    let Some(fit) = ata.cholesky().map(|ch| ch.solve(&atb)) else {
        return false;
    };
    let misfit = (&a * fit - &b).norm();
    misfit <= 1e-6 * b.norm()
}
