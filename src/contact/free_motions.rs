//! The rigid motions of a body that neither its supports nor its contacts hold, in words ("slide along x and z and turn about y").
//!
//! A rigid motion of a body is a translation `t` and a rotation `ω` (about the centroid `c`
//! of its nodes, scaled by its size `L` so both parameters are lengths): node `x` moves by
//! `v = t + ω × (x − c) / L`. A support fixing direction `d` at node `x`, a contact pressing
//! along its normal `n` at `x` (and, with friction, along the two tangents) each hold the
//! motion along one direction `d` there: `d · v = aᵀ p` with `p = (t, ω)` and
//! `a = (d, ((x − c) × d) / L)` (as `d · (ω × r) = ω · (r × d)`). The motions none of them
//! hold are the null space of `G = Σ a aᵀ` (6 × 6 in 3D; 3 × 3 in 2D: `t_x`, `t_y`, `ω_z`):
//! the free slides are the translations in it (the null space of `G`'s translation block),
//! the free turns the rotation parts of the rest.

use crate::linkage::Dimension;
use crate::Real;
use nalgebra::{DMatrix, Vector3};

/// The motion along `direction` (unit) at `point` (m) is held (by a support or a contact).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Held {
    /// Where, m.
    pub(crate) point: Vector3<Real>,
    /// Along what, unit.
    pub(crate) direction: Vector3<Real>,
}

/// The rigid motions of a body that nothing holds.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct FreeMotions {
    /// An orthonormal basis of the free translations.
    pub(crate) slides: Vec<Vector3<Real>>,
    /// An orthonormal basis of the axes of the free rotations (each about some point).
    pub(crate) turns: Vec<Vector3<Real>>,
}

/// A null space is what `G` maps to below this fraction of its largest eigenvalue.
const NULL: Real = 1e-9;

impl FreeMotions {
    /// The motions of a body of `dimension` with nodes at `nodes` (deformed, m) that `held`
    /// leaves free.
    pub(crate) fn of(dimension: Dimension, nodes: &[Vector3<Real>], held: &[Held]) -> Self {
        let count = nodes.len().max(1) as Real;
        let centre = nodes.iter().fold(Vector3::zeros(), |s, x| s + x) / count;
        let size = nodes
            .iter()
            .map(|x| (x - centre).norm())
            .fold(0.0, Real::max)
            .max(Real::MIN_POSITIVE);
        // The parameters kept: (t_x, t_y, ω_z) in 2D, all six in 3D.
        let kept: &[usize] = match dimension {
            Dimension::Two => &[0, 1, 5],
            Dimension::Three => &[0, 1, 2, 3, 4, 5],
        };
        let r = kept.len();
        let mut g = DMatrix::<Real>::zeros(r, r);
        for h in held {
            let turn = (h.point - centre).cross(&h.direction) / size;
            let full = [
                h.direction.x,
                h.direction.y,
                h.direction.z,
                turn.x,
                turn.y,
                turn.z,
            ];
            let a: Vec<Real> = kept.iter().map(|&i| full[i]).collect();
            for i in 0..r {
                for j in 0..r {
                    g[(i, j)] += a[i] * a[j];
                }
            }
        }
        let translations = match dimension {
            Dimension::Two => 2,
            Dimension::Three => 3,
        };
        let to_vector = |v: &[Real]| match dimension {
            Dimension::Two => Vector3::new(v[0], v[1], 0.0),
            Dimension::Three => Vector3::new(v[0], v[1], v[2]),
        };
        let null = null_space(&g);
        let slides: Vec<Vector3<Real>> =
            null_space(&g.view((0, 0), (translations, translations)).into_owned())
                .iter()
                .map(|v| to_vector(v))
                .collect();
        // The rotation parts of the free motions span the free turns' axes.
        let axes: Vec<Vector3<Real>> = null
            .iter()
            .map(|v| match dimension {
                Dimension::Two => Vector3::new(0.0, 0.0, v[2]),
                Dimension::Three => Vector3::new(v[3], v[4], v[5]),
            })
            .collect();
        FreeMotions {
            slides,
            turns: span(&axes),
        }
    }

    /// Whether nothing is free.
    pub(crate) fn is_empty(&self) -> bool {
        self.slides.is_empty() && self.turns.is_empty()
    }

    /// The part of `force` (N) along the free slides, N.
    pub(crate) fn along_slides(&self, force: &Vector3<Real>) -> Vector3<Real> {
        self.slides.iter().map(|s| s * s.dot(force)).sum()
    }

    /// The direction (in words, "along x") and size (N) of the part of `force` along the
    /// free slides; `None` when it has none (at most 1e-9 of `force`).
    pub(crate) fn push(&self, force: &Vector3<Real>) -> Option<(String, Real)> {
        let along = self.along_slides(force);
        let size = along.norm();
        (size > 1e-9 * force.norm() && size > 0.0)
            .then(|| (directions(&[along / size], "along"), size))
    }

    /// In words: "slide along x and z and turn about y" ("" when nothing is free).
    pub(crate) fn describe(&self) -> String {
        let mut parts = Vec::new();
        if !self.slides.is_empty() {
            parts.push(format!("slide {}", directions(&self.slides, "along")));
        }
        if !self.turns.is_empty() {
            parts.push(format!("turn {}", directions(&self.turns, "about")));
        }
        parts.join(" and ")
    }
}

/// An orthonormal basis of the null space of the symmetric positive semidefinite `g`:
/// eigenvectors of eigenvalues at most `NULL` times the largest (all of them when `g` is 0).
fn null_space(g: &DMatrix<Real>) -> Vec<Vec<Real>> {
    let eigen = g.clone().symmetric_eigen();
    let largest = eigen.eigenvalues.iter().copied().fold(0.0, Real::max);
    (0..g.nrows())
        .filter(|&i| eigen.eigenvalues[i] <= NULL * largest)
        .map(|i| eigen.eigenvectors.column(i).iter().copied().collect())
        .collect()
}

/// An orthonormal basis of the span of `vectors` (Gram–Schmidt, dropping what is within
/// 1e-6 of the span already found).
fn span(vectors: &[Vector3<Real>]) -> Vec<Vector3<Real>> {
    let scale = vectors.iter().map(|v| v.norm()).fold(0.0, Real::max);
    let mut basis: Vec<Vector3<Real>> = Vec::new();
    for v in vectors {
        let rest = basis.iter().fold(*v, |r, b| r - b * b.dot(&r));
        if rest.norm() > 1e-6 * scale {
            basis.push(rest.normalize());
        }
    }
    basis
}

/// The space spanned by the orthonormal `basis`, named: "along x and z" when it is spanned by
/// coordinate axes, "in every direction" for all three, else its directions as vectors.
fn directions(basis: &[Vector3<Real>], word: &str) -> String {
    if basis.len() == 3 {
        return match word {
            "along" => "in every direction".to_string(),
            _ => "about every axis".to_string(),
        };
    }
    let axes: Vec<&str> = ["x", "y", "z"]
        .iter()
        .enumerate()
        .filter(|(i, _)| {
            let e = Vector3::ith(*i, 1.0);
            let inside: Real = basis.iter().map(|b| b.dot(&e).powi(2)).sum();
            inside > 1.0 - 1e-9
        })
        .map(|(_, n)| *n)
        .collect();
    let names: Vec<String> = if axes.len() == basis.len() {
        axes.iter().map(|a| a.to_string()).collect()
    } else {
        basis
            .iter()
            .map(|b| {
                // The sign that makes the largest component positive.
                let k = b.iamax();
                let b = if b[k] < 0.0 { -b } else { *b };
                // Rounded first, then + 0.0: a round-off below zero is written 0.000, not -0.000.
                let r = |v: Real| (v * 1e3).round() / 1e3 + 0.0;
                format!("({:.3}, {:.3}, {:.3})", r(b.x), r(b.y), r(b.z))
            })
            .collect()
    };
    format!("{word} {}", names.join(" and "))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 8 corners of a unit cube on the floor y = 0.
    fn cube() -> Vec<Vector3<Real>> {
        let mut nodes = Vec::new();
        for i in 0..8 {
            nodes.push(Vector3::new(
                (i & 1) as Real,
                ((i >> 1) & 1) as Real,
                ((i >> 2) & 1) as Real,
            ));
        }
        nodes
    }

    fn floor(nodes: &[Vector3<Real>], friction: bool) -> Vec<Held> {
        let mut held = Vec::new();
        for x in nodes.iter().filter(|x| x.y == 0.0) {
            held.push(Held {
                point: *x,
                direction: Vector3::y(),
            });
            if friction {
                for d in [Vector3::x(), Vector3::z()] {
                    held.push(Held {
                        point: *x,
                        direction: d,
                    });
                }
            }
        }
        held
    }

    #[test]
    fn a_cube_on_a_frictionless_floor_slides_along_x_and_z_and_turns_about_y() {
        let nodes = cube();
        let free = FreeMotions::of(Dimension::Three, &nodes, &floor(&nodes, false));
        assert_eq!(free.describe(), "slide along x and z and turn about y");
        let along = free.along_slides(&Vector3::new(3.0, -10.0, 0.0));
        assert!((along - Vector3::new(3.0, 0.0, 0.0)).norm() < 1e-12);
    }

    #[test]
    fn friction_or_supports_hold_everything() {
        let nodes = cube();
        assert!(FreeMotions::of(Dimension::Three, &nodes, &floor(&nodes, true)).is_empty());
        // Nothing at all: every motion is free.
        let free = FreeMotions::of(Dimension::Three, &nodes, &[]);
        assert_eq!(
            free.describe(),
            "slide in every direction and turn about every axis"
        );
    }

    #[test]
    fn a_tilted_floor_names_its_directions() {
        // A 2D square on a floor tilted 30°: it slides along the floor, turns about nothing.
        let (s, c) = (30f64.to_radians().sin(), 30f64.to_radians().cos());
        let nodes = vec![
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(c, -s, 0.0),
            Vector3::new(s, c, 0.0),
            Vector3::new(c + s, c - s, 0.0),
        ];
        let normal = Vector3::new(s, c, 0.0);
        let held: Vec<Held> = nodes[..2]
            .iter()
            .map(|x| Held {
                point: *x,
                direction: normal,
            })
            .collect();
        let free = FreeMotions::of(Dimension::Two, &nodes, &held);
        assert_eq!(free.describe(), "slide along (0.866, -0.500, 0.000)");
    }
}
