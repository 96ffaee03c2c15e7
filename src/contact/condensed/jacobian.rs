//! The condensed contact problem's Jacobian: one row per active contact, factored once and reused while Newton converges with it.

use crate::contact::condensed::CondensedBody;
use crate::Real;
use faer::linalg::solvers::Solve;
use faer::{Mat, Side};

/// One row of the condensed problem: an active contact's normal (or, with friction, one of
/// its tangent directions): its stiffness (N/m) and its row of `G`, the relative motion along
/// the direction per unit displacement, as (body, candidate slot, coefficient).
pub(crate) struct ContactRow {
    /// Stiffness of the row against its own motion, N/m (the penalty for a normal row).
    pub penalty: Real,
    /// The row's nonzero entries, as (body, candidate slot, coefficient).
    pub entries: Vec<(usize, usize, Real)>,
    /// Stiffness against the motion of other rows of the same contact (friction), as (row,
    /// N/m): the contact's `κ` is then a block, unsymmetric while it slips.
    pub coupling: Vec<(usize, Real)>,
}

/// `κ⁻¹ + G C Gᵀ` factored, or, when some contact's `κ` is a block (friction), `I + κ G C Gᵀ`
/// and `κ`: `apply` gives `(κ⁻¹ + G C Gᵀ)⁻¹ x = (I + κ G C Gᵀ)⁻¹ κ x` either way.
enum Inverse {
    Symmetric(faer::linalg::solvers::Llt<Real>),
    General {
        lu: faer::linalg::solvers::PartialPivLu<Real>,
        kappa: Vec<Vec<(usize, Real)>>,
    },
}

impl Inverse {
    fn solve_in_place(&self, mut x: faer::MatMut<'_, Real>) {
        match self {
            Inverse::Symmetric(llt) => llt.solve_in_place(x),
            Inverse::General { lu, kappa } => {
                let mut y = Mat::<Real>::zeros(x.nrows(), x.ncols());
                for (i, row) in kappa.iter().enumerate() {
                    for j in 0..x.ncols() {
                        y[(i, j)] = row.iter().map(|&(c, k)| k * x[(c, j)]).sum();
                    }
                }
                lu.solve_in_place(y.as_mut());
                x.copy_from(&y);
            }
        }
    }
}

/// A Newton correction of the condensed contact problem.
pub(crate) struct Correction {
    /// Change of the contact forces at each body's candidate slots, N.
    pub fhat: Vec<Vec<Real>>,
    /// Change of each body's rigid-motion amplitudes, m.
    pub alpha: Vec<Vec<Real>>,
    /// Whether a rigid motion had nothing holding it (moved by the stabilisation).
    pub stabilised: bool,
}

/// The factored Jacobian of the condensed contact problem for a list of contact rows:
///
/// `δf̂ = Φ₁ − Gᵀμ`, `(κ⁻¹ + G C Gᵀ) μ = G C Φ₁ + B δα`, `Bᵀ μ = R_Cᵀ Φ₁ + Φ₂`, `B = G R_C`,
///
/// for residuals `Φ₁` (contact force found minus assumed at each body's candidates, N) and
/// `Φ₂` (out-of-balance of each body along its rigid motions, N): a dense problem of the size
/// of the active contacts, factored once and reused while Newton converges with it (a modified
/// Newton step when the contacts' normals and weights have moved a little). Rigid motions the
/// contacts do not hold (an eigenvalue of `Bᵀ A⁻¹ B` below 1000 `stabilisation`, N/m) are moved
/// by their out-of-balance over `stabilisation`, as the coupled solve does.
pub(crate) struct ContactJacobian {
    rows: Vec<ContactRow>,
    llt: Inverse,
    /// `[B | A⁻¹ B]`, k × 2r.
    b_psi: Mat<Real>,
    /// First rigid amplitude of each body in the global list.
    first: Vec<usize>,
    /// Eigenvalues and eigenvectors of `Bᵀ A⁻¹ B` (none without rigid motions).
    eigen: Option<nalgebra::SymmetricEigen<Real, nalgebra::Dyn>>,
    /// LU of `Bᵀ A⁻¹ B` itself when it is unsymmetric (friction).
    rigid_lu: Option<nalgebra::LU<Real, nalgebra::Dyn, nalgebra::Dyn>>,
    stabilisation: Real,
}

impl ContactJacobian {
    /// Form and factor the Jacobian for `rows`.
    pub(crate) fn new(
        bodies: &[&CondensedBody],
        rows: Vec<ContactRow>,
        stabilisation: Real,
    ) -> Result<Self, String> {
        let k = rows.len();
        // W_b = C_b G_bᵀ, one column per contact (zero where the contact does not touch b).
        let mut w: Vec<Option<Mat<Real>>> = bodies.iter().map(|_| None).collect();
        for (e, row) in rows.iter().enumerate() {
            for &(b, s, v) in &row.entries {
                let c = bodies[b].compliance_column(s);
                let wb = w[b].get_or_insert_with(|| Mat::zeros(bodies[b].len(), k));
                let mut col = wb.col_mut(e);
                for (i, &ci) in c.iter().enumerate() {
                    col[i] += v * ci;
                }
            }
        }
        let general = rows
            .iter()
            .any(|r| !r.coupling.is_empty() || r.penalty.is_nan() || r.penalty <= 0.0);
        // A = κ⁻¹ + G W, column by column (W's columns are contiguous); G W alone with blocks.
        let mut a = Mat::<Real>::zeros(k, k);
        for e2 in 0..k {
            let columns: Vec<Option<&[Real]>> = w
                .iter()
                .map(|wb| {
                    wb.as_ref()
                        .and_then(|m| m.col(e2).try_as_col_major().map(|c| c.as_slice()))
                })
                .collect();
            let mut col = a.col_mut(e2);
            for (e1, row) in rows.iter().enumerate() {
                let mut sum = 0.0;
                for &(b, s, v) in &row.entries {
                    if let Some(c) = columns[b] {
                        sum += v * c[s];
                    }
                }
                col[e1] += sum;
            }
            if !general {
                col[e2] += 1.0 / rows[e2].penalty;
            }
        }
        drop(w);
        // Symmetrize round-off before the factorization.
        for i in 0..k {
            for j in 0..i {
                let v = 0.5 * (a[(i, j)] + a[(j, i)]);
                a[(i, j)] = v;
                a[(j, i)] = v;
            }
        }
        if general {
            // The frictionless path finds `κ⁻¹ + G C Gᵀ` not positive definite where the
            // candidates' compliance is not (then the coupled solve takes over): with friction,
            // the same test on the rows' own stiffnesses.
            let largest = rows.iter().map(|r| r.penalty).fold(0.0, Real::max);
            let mut test = a.clone();
            for (i, row) in rows.iter().enumerate() {
                test[(i, i)] += 1.0
                    / if row.penalty > 0.0 {
                        row.penalty
                    } else {
                        largest
                    };
            }
            test.llt(Side::Lower)
                .map_err(|e| format!("the contact matrix is not positive definite: {e:?}"))?;
        }
        let llt = if general {
            // κ per row: its own stiffness and those against the contact's other rows.
            let kappa: Vec<Vec<(usize, Real)>> = rows
                .iter()
                .enumerate()
                .map(|(i, r)| {
                    std::iter::once((i, r.penalty))
                        .chain(r.coupling.iter().copied())
                        .filter(|&(_, v)| v != 0.0)
                        .collect()
                })
                .collect();
            // M = I + κ (G W).
            let mut m = Mat::<Real>::identity(k, k);
            for (i, row) in kappa.iter().enumerate() {
                for j in 0..k {
                    m[(i, j)] += row.iter().map(|&(c, v)| v * a[(c, j)]).sum::<Real>();
                }
            }
            Inverse::General {
                lu: m.partial_piv_lu(),
                kappa,
            }
        } else {
            Inverse::Symmetric(
                a.llt(Side::Lower)
                    .map_err(|e| format!("the contact matrix is not positive definite: {e:?}"))?,
            )
        };
        let mut first = Vec::with_capacity(bodies.len());
        let mut r = 0;
        for b in bodies {
            first.push(r);
            r += b.modes.len();
        }
        // B = G R_C, then A⁻¹ B beside it.
        let mut b_psi = Mat::<Real>::zeros(k, 2 * r);
        for (e, row) in rows.iter().enumerate() {
            for &(b, s, v) in &row.entries {
                for (j, mode) in bodies[b].modes_c.iter().enumerate() {
                    b_psi[(e, first[b] + j)] += v * mode[s];
                    b_psi[(e, r + first[b] + j)] += v * mode[s];
                }
            }
        }
        llt.solve_in_place(b_psi.subcols_mut(r, r));
        let mut m = nalgebra::DMatrix::<Real>::zeros(r, r);
        for i in 0..r {
            for j in 0..r {
                m[(i, j)] = (0..k).map(|e| b_psi[(e, i)] * b_psi[(e, r + j)]).sum();
            }
        }
        // With slipping contacts `Bᵀ A⁻¹ B` is unsymmetric: the held rigid motions are decided
        // on its symmetric part and, when all are held, solved with the whole of it.
        let full = matches!(llt, Inverse::General { .. }).then(|| m.clone().lu());
        let m = (&m + m.transpose()) * 0.5;
        Ok(ContactJacobian {
            rows,
            llt,
            b_psi,
            first,
            eigen: (r > 0).then(|| m.symmetric_eigen()),
            rigid_lu: full,
            stabilisation,
        })
    }

    /// The contact rows the Jacobian was formed with.
    pub(crate) fn rows(&self) -> &[ContactRow] {
        &self.rows
    }

    /// The Newton correction for residuals `phi1` and `phi2` (see the type).
    pub(crate) fn correction(
        &self,
        bodies: &[&CondensedBody],
        phi1: &[Vec<Real>],
        phi2: &[Vec<Real>],
    ) -> Correction {
        let k = self.rows.len();
        let r = self.eigen.as_ref().map_or(0, |e| e.eigenvalues.len());
        let cphi: Vec<Vec<Real>> = bodies.iter().zip(phi1).map(|(b, p)| b.comply(p)).collect();
        // μ₀ = A⁻¹ G C Φ₁.
        let mut mu = Mat::<Real>::zeros(k, 1);
        for (e, row) in self.rows.iter().enumerate() {
            mu[(e, 0)] = row.entries.iter().map(|&(b, s, v)| v * cphi[b][s]).sum();
        }
        self.llt.solve_in_place(mu.as_mut());
        let mut dalpha = vec![0.0; r];
        let mut stabilised = false;
        if let Some(eigen) = &self.eigen {
            let mut g = nalgebra::DVector::<Real>::zeros(r);
            for (b, body) in bodies.iter().enumerate() {
                for (j, mode) in body.modes_c.iter().enumerate() {
                    g[self.first[b] + j] =
                        phi2[b][j] + mode.iter().zip(&phi1[b]).map(|(a, p)| a * p).sum::<Real>();
                }
            }
            for i in 0..r {
                g[i] -= (0..k)
                    .map(|e| self.b_psi[(e, i)] * mu[(e, 0)])
                    .sum::<Real>();
            }
            let mut x = nalgebra::DVector::<Real>::zeros(r);
            for (i, &lambda) in eigen.eigenvalues.iter().enumerate() {
                let v = eigen.eigenvectors.column(i);
                let p = v.dot(&g);
                // Held: a Newton step. Not held (no contact restrains it): a stabilised move.
                let held = lambda > 1e3 * self.stabilisation;
                if !held && p != 0.0 {
                    stabilised = true;
                }
                let stiffness = if held {
                    lambda
                } else {
                    lambda.max(0.0) + self.stabilisation
                };
                x += v * (p / stiffness);
            }
            if !stabilised {
                if let Some(x) = self.rigid_lu.as_ref().and_then(|lu| lu.solve(&g)) {
                    dalpha.copy_from_slice(x.as_slice());
                } else {
                    dalpha.copy_from_slice(x.as_slice());
                }
            } else {
                dalpha.copy_from_slice(x.as_slice());
            }
        }
        // μ = μ₀ + Ψ δα; δf̂ = Φ₁ − Gᵀ μ.
        let mut fhat: Vec<Vec<Real>> = phi1.to_vec();
        for (e, row) in self.rows.iter().enumerate() {
            let m = mu[(e, 0)]
                + (0..r)
                    .map(|j| self.b_psi[(e, r + j)] * dalpha[j])
                    .sum::<Real>();
            for &(b, s, v) in &row.entries {
                fhat[b][s] -= v * m;
            }
        }
        let alpha = bodies
            .iter()
            .enumerate()
            .map(|(b, body)| dalpha[self.first[b]..self.first[b] + body.modes.len()].to_vec())
            .collect();
        Correction {
            fhat,
            alpha,
            stabilised,
        }
    }
}
