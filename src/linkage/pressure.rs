//! Pressure on a body's surface as nodal loads: on patches (3D, Pa) or on boundary segments
//! (2D, N/m), and, for a body under large displacements, its load stiffness.
//!
//! A patch `[a, b, c]` (outward by the right-hand rule) carries the force `−p · n A`, with
//! `n A = (x_b − x_a) × (x_c − x_a) / 2` its area vector, one third to each node. A 2D segment
//! `[a, b]` (the body on its left) carries `p` times its length along the inward normal, half
//! to each node: `f_a = f_b = (p/2) R (x_b − x_a)`, `R` the rotation by +90°.
//!
//! The load stiffness `K_L = −∂f/∂x` of a following pressure (Hibbitt, "Some follower forces
//! and load stiffness", IJNME 1979), derived here from the force above: per patch the block of node `i` and node `j`
//! is `(p/6) [e_j]×`, with `e_a = x_c − x_b`, `e_b = x_a − x_c`, `e_c = x_b − x_a` and `[e]×`
//! the cross-product matrix; per segment the blocks are `(p/2) R` (columns of `a`) and
//! `−(p/2) R` (columns of `b`). It is unsymmetric element by element, but on a closed surface
//! under one pressure (the load is then the gradient of `p V`) its skew parts cancel and the
//! sum is symmetric. The Newton tangent takes its symmetric part
//! `S_ij = (p/12) [e_j − e_i]×` (3D) or `S_ab = −(p/2) R` (2D), zero on the diagonal blocks:
//! exact, and Newton quadratic, on a closed surface (and wherever the skew rest acts only on
//! supported directions: [`load_stiffness_parts`] tells). Elsewhere the skew rest, which lives
//! on the surface's rim, is not small; the symmetric part alone can then slow Newton down, and
//! the Newton solver leaves the load stiffness out (it converges linearly).

use crate::linkage::{Body, NodalLoad, Schedule};
use crate::Real;
use nalgebra::{Matrix3, Vector3};

/// The faces a pressure acts on.
#[derive(Clone, Debug, PartialEq)]
pub enum PressureFaces {
    /// 3D: triangles `[a, b, c]` (0-based nodes), outward by the right-hand rule.
    Patches(Vec<[usize; 3]>),
    /// 2D: boundary segments `[a, b]` (0-based nodes), the body on the left of `a → b`.
    Segments(Vec<[usize; 2]>),
}

impl PressureFaces {
    /// The nodes of every face, face by face.
    pub fn nodes(&self) -> Box<dyn Iterator<Item = &[usize]> + '_> {
        match self {
            PressureFaces::Patches(p) => Box::new(p.iter().map(|f| f.as_slice())),
            PressureFaces::Segments(s) => Box::new(s.iter().map(|f| f.as_slice())),
        }
    }

    /// Number of faces.
    pub fn len(&self) -> usize {
        match self {
            PressureFaces::Patches(p) => p.len(),
            PressureFaces::Segments(s) => s.len(),
        }
    }

    /// Whether there is no face.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// A pressure that follows the deformation (a body under large displacements): applied on
/// the deformed faces, with its load stiffness in the Newton tangent.
#[derive(Clone, Debug, PartialEq)]
pub struct Pressure {
    /// At full schedule: Pa on patches (3D), N/m on segments (2D); positive pushes into the
    /// body.
    pub pressure: Real,
    /// The faces it acts on.
    pub faces: PressureFaces,
    /// How it grows over the steps.
    pub schedule: Schedule,
}

/// The cross-product matrix `[e]×` (`[e]× v = e × v`).
fn cross_matrix(e: Vector3<Real>) -> Matrix3<Real> {
    Matrix3::new(0.0, -e.z, e.y, e.z, 0.0, -e.x, -e.y, e.x, 0.0)
}

/// `R`: the rotation by +90° about z (`R (x, y) = (−y, x)`).
fn quarter_turn() -> Matrix3<Real> {
    Matrix3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0)
}

/// Call `add(node, force)` for the share of every node of every face of `faces` under
/// `pressure` (Pa or N/m), with the nodes at `position(node)` (m).
pub fn face_forces(
    faces: &PressureFaces,
    pressure: Real,
    position: impl Fn(usize) -> Vector3<Real>,
    mut add: impl FnMut(usize, Vector3<Real>),
) {
    match faces {
        PressureFaces::Patches(patches) => {
            for &[a, b, c] in patches {
                let (pa, pb, pc) = (position(a), position(b), position(c));
                let share = -(pb - pa).cross(&(pc - pa)) * (pressure / 6.0);
                for n in [a, b, c] {
                    add(n, share);
                }
            }
        }
        PressureFaces::Segments(segments) => {
            let r = quarter_turn();
            for &[a, b] in segments {
                let share = r * (position(b) - position(a)) * (pressure / 2.0);
                add(a, share);
                add(b, share);
            }
        }
    }
}

/// Call `add(i, j, block)` with every node block `K_L(i, j)` (3×3, N/m) of the exact load
/// stiffness `−∂f_i/∂x_j` of `pressure` on `faces` at `position` (unsymmetric in general).
pub fn load_stiffness_blocks(
    faces: &PressureFaces,
    pressure: Real,
    position: impl Fn(usize) -> Vector3<Real>,
    mut add: impl FnMut(usize, usize, Matrix3<Real>),
) {
    match faces {
        PressureFaces::Patches(patches) => {
            for &[a, b, c] in patches {
                let (pa, pb, pc) = (position(a), position(b), position(c));
                let e = [pc - pb, pa - pc, pb - pa];
                for i in [a, b, c] {
                    for (j, ej) in [a, b, c].into_iter().zip(e) {
                        add(i, j, cross_matrix(ej) * (pressure / 6.0));
                    }
                }
            }
        }
        PressureFaces::Segments(segments) => {
            let r = quarter_turn() * (pressure / 2.0);
            for &[a, b] in segments {
                for i in [a, b] {
                    add(i, a, r);
                    add(i, b, -r);
                }
            }
        }
    }
}

/// Call `add(i, j, block)` with the symmetric part `S(i, j)` (N/m) of the load stiffness for
/// every pair of distinct nodes `i`, `j` of a face (each ordered pair once per face; the
/// diagonal blocks of the symmetric part are zero). `S(j, i) = S(i, j)ᵀ`.
pub fn symmetric_load_stiffness_blocks(
    faces: &PressureFaces,
    pressure: Real,
    position: impl Fn(usize) -> Vector3<Real>,
    mut add: impl FnMut(usize, usize, Matrix3<Real>),
) {
    match faces {
        PressureFaces::Patches(patches) => {
            for &[a, b, c] in patches {
                let (pa, pb, pc) = (position(a), position(b), position(c));
                let nodes = [a, b, c];
                let e = [pc - pb, pa - pc, pb - pa];
                for i in 0..3 {
                    for j in 0..3 {
                        if i != j {
                            add(
                                nodes[i],
                                nodes[j],
                                cross_matrix(e[j] - e[i]) * (pressure / 12.0),
                            );
                        }
                    }
                }
            }
        }
        PressureFaces::Segments(segments) => {
            let r = quarter_turn() * (pressure / 2.0);
            for &[a, b] in segments {
                add(a, b, -r);
                add(b, a, r);
            }
        }
    }
}

/// The Frobenius norms (N/m) of the skew and of the symmetric part of the load stiffness of
/// `pressures` (each `(faces, pressure)`) at `position`, over the entries whose row and column
/// directions are both `free(node, direction)`: the tangent may take the symmetric part alone
/// only where the skew part there vanishes (a closed surface, or a rim moving only in supported
/// directions).
pub fn load_stiffness_parts<'a>(
    pressures: impl Iterator<Item = (&'a PressureFaces, Real)>,
    position: impl Fn(usize) -> Vector3<Real> + Copy,
    free: impl Fn(usize, usize) -> bool,
) -> (Real, Real) {
    let mut blocks: std::collections::HashMap<(usize, usize), Matrix3<Real>> =
        std::collections::HashMap::new();
    for (faces, pressure) in pressures {
        load_stiffness_blocks(faces, pressure, position, |i, j, k| {
            *blocks.entry((i, j)).or_insert_with(Matrix3::zeros) += k;
        });
    }
    let (mut skew, mut symmetric) = (0.0, 0.0);
    for (&(i, j), k) in &blocks {
        let kt = blocks
            .get(&(j, i))
            .map_or(Matrix3::zeros(), |m| m.transpose());
        let (a, s) = ((k - kt) * 0.5, (k + kt) * 0.5);
        for p in 0..3 {
            for q in 0..3 {
                if free(i, p) && free(j, q) {
                    skew += a[(p, q)] * a[(p, q)];
                    symmetric += s[(p, q)] * s[(p, q)];
                }
            }
        }
    }
    (skew.sqrt(), symmetric.sqrt())
}

/// The nodal loads of `pressure` on `faces` of the undeformed `body` (the pressure of a body
/// under small displacements, which does not follow the deformation): per node the sum of
/// its faces' shares, in node order, growing by `schedule`. On a closed surface they sum to
/// zero; on a flat face to `p` times its area (3D) or length (2D).
pub fn pressure_loads_on(
    body: &Body,
    faces: &PressureFaces,
    pressure: Real,
    schedule: &Schedule,
) -> Vec<NodalLoad> {
    let mut force = vec![Vector3::zeros(); body.nodes.len()];
    let mut loaded = vec![false; body.nodes.len()];
    face_forces(
        faces,
        pressure,
        |n| body.nodes[n],
        |n, f| {
            force[n] += f;
            loaded[n] = true;
        },
    );
    (0..body.nodes.len())
        .filter(|&n| loaded[n])
        .map(|node| NodalLoad {
            node,
            force: force[node],
            schedule: schedule.clone(),
        })
        .collect()
}

/// The patches of `body` whose three nodes are all `chosen`.
pub fn chosen_patches(body: &Body, chosen: &[bool]) -> Vec<[usize; 3]> {
    body.patches
        .iter()
        .copied()
        .filter(|p| p.iter().all(|&n| chosen[n]))
        .collect()
}

/// The nodal loads of `pressure` (Pa, positive pushing into the body) on every patch of `body`
/// whose three nodes are all `chosen`, on the undeformed patches (see [`pressure_loads_on`]).
pub fn pressure_loads(
    body: &Body,
    chosen: &[bool],
    pressure: Real,
    schedule: &Schedule,
) -> Vec<NodalLoad> {
    let faces = PressureFaces::Patches(chosen_patches(body, chosen));
    pressure_loads_on(body, &faces, pressure, schedule)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linkage::generators::box_lattice;
    use crate::linkage::Dimension;
    use std::ops::AddAssign;

    fn lattice_body() -> Body {
        let g = box_lattice([0.3, 0.2, 0.1], [3, 2, 2]).unwrap();
        let mut body = Body::new("box", Dimension::Three);
        body.nodes = g.nodes;
        body.patches = g.patches;
        body
    }

    #[test]
    fn on_a_closed_surface_it_sums_to_zero_and_on_a_face_to_p_times_its_area() {
        let body = lattice_body();
        let all = vec![true; body.nodes.len()];
        let total: Vector3<Real> = pressure_loads(&body, &all, 1e5, &Schedule::Linear)
            .iter()
            .map(|l| l.force)
            .sum();
        assert!(total.norm() < 1e-9, "{total:?}");
        // The top face y = 0.2: 0.3 m × 0.1 m, pushed down by p A = 1e5 · 0.03 = 3000 N.
        let top: Vec<bool> = body.nodes.iter().map(|p| p.y > 0.2 - 1e-12).collect();
        let loads = pressure_loads(&body, &top, 1e5, &Schedule::Linear);
        let total: Vector3<Real> = loads.iter().map(|l| l.force).sum();
        assert!((total.y + 3000.0).abs() < 1e-9, "{total:?}");
        assert!(total.x.abs() < 1e-9 && total.z.abs() < 1e-9);
        assert_eq!(loads.len(), 4 * 3);
    }

    /// A distorted position of every node (so that no block vanishes by symmetry).
    fn distorted(body: &Body) -> Vec<Vector3<Real>> {
        body.nodes
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let t = i as Real;
                p + Vector3::new(
                    0.01 * (1.3 * t).sin(),
                    0.02 * (0.7 * t).cos(),
                    0.015 * t.sin(),
                )
            })
            .collect()
    }

    /// `K v` from blocks given by `blocks`, over 3 components per node.
    fn times(
        nodes: usize,
        v: &[Vector3<Real>],
        blocks: impl FnOnce(&mut dyn FnMut(usize, usize, Matrix3<Real>)),
    ) -> Vec<Vector3<Real>> {
        let mut out = vec![Vector3::zeros(); nodes];
        blocks(&mut |i, j, k| out[i] += k * v[j]);
        out
    }

    fn forces_at(faces: &PressureFaces, p: Real, x: &[Vector3<Real>]) -> Vec<Vector3<Real>> {
        let mut f = vec![Vector3::zeros(); x.len()];
        face_forces(faces, p, |n| x[n], |n, v| f[n] += v);
        f
    }

    /// Central differences of the forces along `v`: `−(f(x + h v) − f(x − h v)) / 2h`.
    fn finite_difference(
        faces: &PressureFaces,
        p: Real,
        x: &[Vector3<Real>],
        v: &[Vector3<Real>],
    ) -> Vec<Vector3<Real>> {
        let h = 1e-6;
        let shift = |s: Real| -> Vec<Vector3<Real>> {
            x.iter().zip(v).map(|(x, v)| x + v * (s * h)).collect()
        };
        let plus = forces_at(faces, p, &shift(1.0));
        let minus = forces_at(faces, p, &shift(-1.0));
        plus.iter()
            .zip(&minus)
            .map(|(a, b)| -(a - b) / (2.0 * h))
            .collect()
    }

    fn largest_difference(a: &[Vector3<Real>], b: &[Vector3<Real>]) -> (Real, Real) {
        let diff = a
            .iter()
            .zip(b)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, Real::max);
        let scale = a.iter().map(|a| a.norm()).fold(0.0, Real::max);
        (diff, scale)
    }

    #[test]
    fn the_load_stiffness_of_patches_is_the_derivative_of_their_forces() {
        // Forces are quadratic in the positions, so central differences are exact up to
        // round-off: 1e-7 relative.
        let body = lattice_body();
        let x = distorted(&body);
        let v: Vec<Vector3<Real>> = (0..x.len())
            .map(|i| Vector3::new((i as Real).cos(), (2.0 * i as Real).sin(), 0.5))
            .collect();
        let top: Vec<bool> = body.nodes.iter().map(|p| p.y > 0.2 - 1e-12).collect();
        for chosen in [vec![true; x.len()], top] {
            let faces = PressureFaces::Patches(chosen_patches(&body, &chosen));
            let exact = times(x.len(), &v, |add| {
                load_stiffness_blocks(&faces, 2e5, |n| x[n], add)
            });
            let fd = finite_difference(&faces, 2e5, &x, &v);
            let (diff, scale) = largest_difference(&exact, &fd);
            assert!(diff <= 1e-7 * scale, "{diff} of {scale}");
        }
    }

    #[test]
    fn on_a_closed_surface_the_load_stiffness_is_symmetric_and_equals_its_symmetric_part() {
        let body = lattice_body();
        let x = distorted(&body);
        let faces = PressureFaces::Patches(body.patches.clone());
        let n = x.len();
        let mut k = nalgebra::DMatrix::<Real>::zeros(3 * n, 3 * n);
        load_stiffness_blocks(
            &faces,
            2e5,
            |i| x[i],
            |i, j, b| k.view_mut((3 * i, 3 * j), (3, 3)).add_assign(&b),
        );
        let mut s = nalgebra::DMatrix::<Real>::zeros(3 * n, 3 * n);
        symmetric_load_stiffness_blocks(
            &faces,
            2e5,
            |i| x[i],
            |i, j, b| s.view_mut((3 * i, 3 * j), (3, 3)).add_assign(&b),
        );
        let scale = k.amax();
        assert!(scale > 0.0);
        assert!((&k - k.transpose()).amax() <= 1e-12 * scale);
        assert!((&k - &s).amax() <= 1e-12 * scale);
        // One face alone is not symmetric: the skew rest is what the tangent leaves out there.
        let top: Vec<bool> = body.nodes.iter().map(|p| p.y > 0.2 - 1e-12).collect();
        let faces = PressureFaces::Patches(chosen_patches(&body, &top));
        let mut k = nalgebra::DMatrix::<Real>::zeros(3 * n, 3 * n);
        load_stiffness_blocks(
            &faces,
            2e5,
            |i| x[i],
            |i, j, b| k.view_mut((3 * i, 3 * j), (3, 3)).add_assign(&b),
        );
        assert!((&k - k.transpose()).amax() > 1e-3 * k.amax());
    }

    #[test]
    fn segments_carry_p_times_their_length_and_their_load_stiffness_is_the_derivative() {
        // A unit square loop, counter-clockwise (the body inside, on the left): p = 300 N/m
        // pushes every side inward with 300 N; the sum is zero. One side alone: 300 N.
        let x = vec![
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(1.0, 1.0, 0.0),
            Vector3::new(0.0, 1.0, 0.0),
        ];
        let loop_faces = PressureFaces::Segments(vec![[0, 1], [1, 2], [2, 3], [3, 0]]);
        let f = forces_at(&loop_faces, 300.0, &x);
        assert!(f.iter().sum::<Vector3<Real>>().norm() < 1e-12);
        let bottom = PressureFaces::Segments(vec![[0, 1]]);
        let f = forces_at(&bottom, 300.0, &x);
        assert_eq!(f[0], Vector3::new(0.0, 150.0, 0.0));
        assert_eq!(f[1], Vector3::new(0.0, 150.0, 0.0));
        let x: Vec<Vector3<Real>> = x
            .iter()
            .enumerate()
            .map(|(i, p)| p + Vector3::new(0.1 * (i as Real).sin(), 0.05 * i as Real, 0.0))
            .collect();
        let v: Vec<Vector3<Real>> = (0..4)
            .map(|i| Vector3::new((i as Real).cos(), 1.0 - i as Real, 0.0))
            .collect();
        let exact = times(4, &v, |add| {
            load_stiffness_blocks(&loop_faces, 300.0, |n| x[n], add)
        });
        let fd = finite_difference(&loop_faces, 300.0, &x, &v);
        let (diff, scale) = largest_difference(&exact, &fd);
        assert!(diff <= 1e-7 * scale, "{diff} of {scale}");
        // The closed loop: the symmetric part is the whole.
        let sym = times(4, &v, |add| {
            symmetric_load_stiffness_blocks(&loop_faces, 300.0, |n| x[n], add)
        });
        let (diff, _) = largest_difference(&exact, &sym);
        assert!(diff <= 1e-12 * scale, "{diff} of {scale}");
    }
}
