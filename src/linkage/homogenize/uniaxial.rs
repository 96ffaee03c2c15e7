//! The body's own uniaxial tests along x, y and z: its Young's moduli and Poisson's ratios as
//! a solid (see the module README for the formulas and why).

use crate::linalg::{CholeskyError, SparseCholesky};
use crate::linkage::prepare::enclosed_volume;
use crate::linkage::{member_axial_stiffness, Body, Dimension};
use crate::Real;
use nalgebra::{Matrix4, Vector3, Vector4};

/// Spring on every lateral degree of freedom, relative to the mean diagonal stiffness: holds
/// the rigid motions the uniaxial test leaves free (see the README).
const LATERAL_SPRING: Real = 1e-10;

/// A body's elastic constants as a solid, from its own uniaxial tests.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EffectiveElasticity {
    /// Young's modulus along x, y and z, Pa: `E_d = F_d L_d / (V ε)`.
    pub youngs_moduli: [Real; 3],
    /// Their mean, Pa.
    pub youngs_modulus: Real,
    /// Poisson's ratio, the mean of the six `ν_dj = −ε_jj / ε_dd` (j ≠ d).
    pub poisson_ratio: Real,
    /// The smallest and largest of the six `ν_dj`.
    pub poisson_range: [Real; 2],
    /// The volume of the solid the body models, m³ (patches' or bounding box's).
    pub volume: Real,
}

impl std::fmt::Display for EffectiveElasticity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [x, y, z] = self.youngs_moduli;
        write!(
            f,
            "as a solid (uniaxial tests of the lattice): Young's modulus {:.4e} Pa (x {x:.4e}, y {y:.4e}, z {z:.4e}), Poisson's ratio {:.3} ({:.3} to {:.3})",
            self.youngs_modulus, self.poisson_ratio, self.poisson_range[0], self.poisson_range[1]
        )
    }
}

/// Why a body's elasticity as a solid cannot be computed.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum HomogenizeError {
    /// Only 3D bodies are read as solids.
    #[error("body '{body}' is 2D: the modulus of a lattice as a solid is computed for 3D bodies (a plane lattice has no thickness)")]
    NotThreeD {
        /// Body name.
        body: String,
    },
    /// The body is flat along an axis, has no members, or no volume.
    #[error("body '{body}' is not a solid: {why}")]
    NotSolid {
        /// Body name.
        body: String,
        /// What is missing.
        why: String,
    },
    /// The test's stiffness matrix could not be factored.
    #[error("body '{body}': the uniaxial test along {axis} cannot be solved: {source} (a lattice with a mechanism is not a solid)")]
    Solve {
        /// Body name.
        body: String,
        /// "x", "y" or "z".
        axis: &'static str,
        /// The factorization's error.
        source: CholeskyError,
    },
}

/// The volume (m³) of the solid `body` models: what its patches enclose when it has patches
/// enclosing a positive volume, else its nodes' bounding box.
pub fn continuum_volume(body: &Body) -> Real {
    let enclosed = if body.patches.is_empty() {
        0.0
    } else {
        enclosed_volume(&body.nodes, &body.patches).abs()
    };
    if enclosed > 0.0 {
        return enclosed;
    }
    let (lo, hi) = bounds(body);
    (hi - lo).product()
}

fn bounds(body: &Body) -> (Vector3<Real>, Vector3<Real>) {
    let mut lo = Vector3::repeat(Real::INFINITY);
    let mut hi = Vector3::repeat(Real::NEG_INFINITY);
    for p in &body.nodes {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    (lo, hi)
}

/// `body`'s Young's moduli and Poisson's ratios as a solid of `volume` m³, from its three
/// uniaxial tests (every member linear elastic with its `A E / L`; supports and loads of the
/// body are not used).
pub fn effective_elasticity(
    body: &Body,
    volume: Real,
) -> Result<EffectiveElasticity, HomogenizeError> {
    if body.dimension != Dimension::Three {
        return Err(HomogenizeError::NotThreeD {
            body: body.name.clone(),
        });
    }
    let not_solid = |why: String| HomogenizeError::NotSolid {
        body: body.name.clone(),
        why,
    };
    if body.members.is_empty() {
        return Err(not_solid("it has no members".to_string()));
    }
    if !(volume.is_finite() && volume > 0.0) {
        return Err(not_solid(format!("its volume is {volume} m³")));
    }
    let stiffness: Vec<Real> = (0..body.members.len())
        .map(|m| member_axial_stiffness(body, m))
        .collect();
    let mut moduli = [0.0; 3];
    let mut ratios = Vec::with_capacity(6);
    for (d, modulus) in moduli.iter_mut().enumerate() {
        let test = uniaxial_test(body, &stiffness, d)?;
        *modulus = test.force * test.length / volume;
        for j in (0..3).filter(|&j| j != d) {
            ratios.push(-test.gradient[j]);
        }
    }
    let poisson = ratios.iter().sum::<Real>() / ratios.len() as Real;
    let range = ratios
        .iter()
        .fold([Real::INFINITY, Real::NEG_INFINITY], |r, &v| {
            [r[0].min(v), r[1].max(v)]
        });
    Ok(EffectiveElasticity {
        youngs_moduli: moduli,
        youngs_modulus: moduli.iter().sum::<Real>() / 3.0,
        poisson_ratio: poisson,
        poisson_range: range,
        volume,
    })
}

/// What one uniaxial test at unit strain gives.
struct Uniaxial {
    /// The force on the moved face, N (at strain 1).
    force: Real,
    /// The body's length along the axis, m.
    length: Real,
    /// The fitted normal strains `G_jj` of the three axes (at strain 1 along the axis).
    gradient: [Real; 3],
}

const AXES: [&str; 3] = ["x", "y", "z"];

/// The test along axis `d` at strain 1: faces normal to `d` held in `d`, one moved by its length.
fn uniaxial_test(body: &Body, stiffness: &[Real], d: usize) -> Result<Uniaxial, HomogenizeError> {
    let (lo, hi) = bounds(body);
    let length = hi[d] - lo[d];
    let tolerance = 1e-6 * body.size();
    if length.is_nan() || length <= tolerance {
        return Err(HomogenizeError::NotSolid {
            body: body.name.clone(),
            why: format!("it is flat along {}", AXES[d]),
        });
    }
    let n = body.nodes.len();
    // Prescribed value of each DOF (node * 3 + j), or None when free.
    let mut prescribed: Vec<Option<Real>> = vec![None; 3 * n];
    let mut top = vec![false; n];
    for (i, p) in body.nodes.iter().enumerate() {
        if (p[d] - lo[d]).abs() <= tolerance {
            prescribed[3 * i + d] = Some(0.0);
        } else if (hi[d] - p[d]).abs() <= tolerance {
            prescribed[3 * i + d] = Some(length);
            top[i] = true;
        }
    }
    let mut index = vec![usize::MAX; 3 * n];
    let mut free = 0;
    for (k, p) in prescribed.iter().enumerate() {
        if p.is_none() {
            index[k] = free;
            free += 1;
        }
    }
    // Lower-triangle triplets of K_ff and the right-hand side −K_fp u_p.
    let mut triplets: Vec<(usize, usize, Real)> = Vec::with_capacity(body.members.len() * 36);
    let mut rhs = vec![0.0; free];
    let mut diagonal_sum = 0.0;
    for (m, member) in body.members.iter().enumerate() {
        let [a, b] = member.nodes;
        let axis = body.nodes[b] - body.nodes[a];
        let e = axis / axis.norm();
        for (p, sp) in [(a, 1.0), (b, -1.0)] {
            for (q, sq) in [(a, 1.0), (b, -1.0)] {
                for i in 0..3 {
                    for j in 0..3 {
                        let v = sp * sq * stiffness[m] * e[i] * e[j];
                        let (r, c) = (3 * p + i, 3 * q + j);
                        if r == c {
                            diagonal_sum += v;
                        }
                        match (index[r], prescribed[c]) {
                            (fr, None) => {
                                let fc = index[c];
                                if fr != usize::MAX && fr >= fc {
                                    triplets.push((fc, fr, v));
                                }
                            }
                            (fr, Some(u)) if fr != usize::MAX => rhs[fr] -= v * u,
                            _ => {}
                        }
                    }
                }
            }
        }
    }
    let spring = LATERAL_SPRING * diagonal_sum / (3 * n) as Real;
    for (k, &f) in index.iter().enumerate() {
        if f != usize::MAX && k % 3 != d {
            triplets.push((f, f, spring));
        } else if f != usize::MAX {
            // Every diagonal entry present, as the factorization requires.
            triplets.push((f, f, 0.0));
        }
    }
    triplets.sort_unstable_by_key(|&(c, r, _)| (c, r));
    let mut col_ptr = vec![0usize; free + 1];
    let mut row_idx: Vec<usize> = Vec::with_capacity(triplets.len() / 2);
    let mut values: Vec<Real> = Vec::with_capacity(triplets.len() / 2);
    let mut last = (usize::MAX, usize::MAX);
    for (c, r, v) in triplets {
        if (c, r) == last {
            if let Some(x) = values.last_mut() {
                *x += v;
            }
        } else {
            row_idx.push(r);
            values.push(v);
            col_ptr[c + 1] += 1;
            last = (c, r);
        }
    }
    for c in 0..free {
        col_ptr[c + 1] += col_ptr[c];
    }
    let fail = |source| HomogenizeError::Solve {
        body: body.name.clone(),
        axis: AXES[d],
        source,
    };
    let mut cholesky = SparseCholesky::analyze(free, &col_ptr, &row_idx, None).map_err(fail)?;
    cholesky.set_pivot_tolerance(0.0);
    cholesky.factorize(&values).map_err(fail)?;
    cholesky.solve_in_place(&mut rhs);
    let u: Vec<Real> = prescribed
        .iter()
        .zip(&index)
        .map(|(p, &f)| p.unwrap_or_else(|| rhs[f]))
        .collect();
    // The force the moved face needs: Σ over its nodes of (K u)_d.
    let mut force = 0.0;
    for (m, member) in body.members.iter().enumerate() {
        let [a, b] = member.nodes;
        let axis = body.nodes[b] - body.nodes[a];
        let e = axis / axis.norm();
        let du = Vector3::from_fn(|i, _| u[3 * b + i] - u[3 * a + i]);
        let tension = stiffness[m] * e.dot(&du);
        // (K u) at b is +tension·e, at a −tension·e.
        if top[b] {
            force += tension * e[d];
        }
        if top[a] {
            force -= tension * e[d];
        }
    }
    Ok(Uniaxial {
        force,
        length,
        gradient: affine_strains(body, &u, &lo),
    })
}

/// The normal strains `G_jj` of the least-squares affine fit `u_j ≈ a_j + G_j · (x − lo)`.
fn affine_strains(body: &Body, u: &[Real], lo: &Vector3<Real>) -> [Real; 3] {
    let mut normal = Matrix4::<Real>::zeros();
    let mut right = [Vector4::<Real>::zeros(); 3];
    let scale = body.size();
    for (i, p) in body.nodes.iter().enumerate() {
        let x = (p - lo) / scale;
        let row = Vector4::new(1.0, x[0], x[1], x[2]);
        normal += row * row.transpose();
        for j in 0..3 {
            right[j] += row * u[3 * i + j];
        }
    }
    let Some(inverse) = normal.try_inverse() else {
        return [Real::NAN; 3];
    };
    [0, 1, 2].map(|j| (inverse * right[j])[j + 1] / scale)
}
