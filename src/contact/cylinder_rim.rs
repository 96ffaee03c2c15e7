//! The rims of a cylinder obstacle, its sharp features: where a node crossed its surface since
//! the last solved state (a cap, the side, or the rim between them), and points along the rims
//! that press a coarse body's patches (2D: the corners of its section by z = 0).
//!
//! The side is smooth: a node that crossed only the side keeps the nearest-point projection.
//! A cap is flat: its plane and normal are fixed for the contact. At the rim the normal is the
//! normalised mean of the cap's normal and the side's radial normal there, the faces counted as
//! for polyhedra (see [`CROSSED_RATE`]).

use crate::contact::obstacle_features::{Crossing, CROSSED_RATE};
use crate::Real;
use nalgebra::{Rotation3, Vector3};

/// A cylinder in the world frame at offset 0: rapier's cylinder, its axis the local y.
pub(crate) struct CylinderRim {
    center: Vector3<Real>,
    rotation: Rotation3<Real>,
    radius: Real,
    half_height: Real,
}

impl CylinderRim {
    /// The cylinder of centre, radius, half height (m) and rotation vector (rad).
    pub(crate) fn new(
        center: Vector3<Real>,
        radius: Real,
        half_height: Real,
        rotation: Vector3<Real>,
    ) -> Self {
        CylinderRim {
            center,
            rotation: Rotation3::new(rotation),
            radius,
            half_height,
        }
    }

    fn local(&self, p: &Vector3<Real>) -> Vector3<Real> {
        self.rotation.inverse() * (p - self.center)
    }

    fn world(&self, p: &Vector3<Real>) -> Vector3<Real> {
        self.center + self.rotation * p
    }

    /// Where the segment from `from` to `to` (m, frame at offset 0) entered the cylinder, with
    /// the normal of what it crossed there; `None` when it crossed only the smooth side, did not
    /// enter (it starts inside, or misses), or the contact is decided by the nearest point.
    pub(crate) fn crossing(
        &self,
        from: &Vector3<Real>,
        to: &Vector3<Real>,
        tolerance: Real,
    ) -> Option<Crossing> {
        let (a, b) = (self.local(from), self.local(to));
        let d = b - a;
        // Entry and exit parameters of the slab |y| <= h and of the infinite cylinder.
        let (h, r) = (self.half_height, self.radius);
        let (mut enter, mut exit) = (Real::NEG_INFINITY, Real::INFINITY);
        if d.y != 0.0 {
            let (s1, s2) = ((-h - a.y) / d.y, (h - a.y) / d.y);
            enter = enter.max(s1.min(s2));
            exit = exit.min(s1.max(s2));
        } else if a.y.abs() > h + tolerance {
            return None;
        }
        let (qa, qb) = (d.x * d.x + d.z * d.z, a.x * d.x + a.z * d.z);
        let qc = a.x * a.x + a.z * a.z - r * r;
        if qa > 0.0 {
            let disc = qb * qb - qa * qc;
            if disc < 0.0 {
                return None;
            }
            let root = disc.sqrt();
            enter = enter.max((-qb - root) / qa);
            exit = exit.min((-qb + root) / qa);
        } else if qc > 2.0 * r * tolerance {
            return None;
        }
        if enter > exit || enter > 1.0 || exit < 0.0 {
            return None;
        }
        let s = enter.clamp(0.0, 1.0);
        let p = a + d * s;
        let radial = Vector3::new(p.x, 0.0, p.z);
        let rho = radial.norm();
        // What meets at the entry point, with the rate the node moved into each.
        let mut faces: Vec<(Vector3<Real>, Real)> = Vec::new();
        if p.y.abs() >= h - tolerance {
            let n = Vector3::new(0.0, p.y.signum(), 0.0);
            faces.push((n, -d.dot(&n)));
        }
        let side = (rho >= r - tolerance && rho > 0.0).then(|| radial / rho);
        if let Some(n) = side {
            faces.push((n, -d.dot(&n)));
        }
        let most = faces.iter().map(|f| f.1).fold(0.0, Real::max);
        let crossed: Vec<&(Vector3<Real>, Real)> = faces
            .iter()
            .filter(|f| f.1 > 0.0 && f.1 >= CROSSED_RATE * most)
            .collect();
        // The side alone is smooth: the nearest point decides.
        if crossed.is_empty() || (crossed.len() == 1 && side.is_some_and(|n| crossed[0].0 == n)) {
            return None;
        }
        let normal: Vector3<Real> = crossed.iter().map(|f| f.0).sum();
        Some(Crossing {
            point: self.world(&p),
            normal: self.rotation * normal.try_normalize(0.0)?,
        })
    }

    /// Points along both rims, at most `spacing` (m) apart.
    pub(crate) fn sharp_points(&self, spacing: Real) -> Vec<Vector3<Real>> {
        let around = std::f64::consts::TAU * self.radius;
        let pieces = (around / spacing).ceil().max(3.0) as usize;
        let mut points = Vec::with_capacity(2 * pieces);
        for y in [-self.half_height, self.half_height] {
            for i in 0..pieces {
                let t = std::f64::consts::TAU * i as Real / pieces as Real;
                let local = Vector3::new(self.radius * t.cos(), y, self.radius * t.sin());
                points.push(self.world(&local));
            }
        }
        points
    }

    /// Where the rims cross the plane z = 0 (corners of the section a 2D scene sees).
    pub(crate) fn section_corners(&self) -> Vec<Vector3<Real>> {
        let mut points = Vec::new();
        // World z of the rim point at angle t: k + a cos t + b sin t.
        let (ex, ez) = (
            self.rotation * Vector3::x() * self.radius,
            self.rotation * Vector3::z() * self.radius,
        );
        for y in [-self.half_height, self.half_height] {
            let k = (self.center + self.rotation * Vector3::new(0.0, y, 0.0)).z;
            let (a, b) = (ex.z, ez.z);
            let amplitude = (a * a + b * b).sqrt();
            if amplitude == 0.0 || k.abs() > amplitude {
                continue;
            }
            let phase = b.atan2(a);
            let spread = (-k / amplitude).clamp(-1.0, 1.0).acos();
            for t in [phase + spread, phase - spread] {
                let local = Vector3::new(self.radius * t.cos(), y, self.radius * t.sin());
                let mut p = self.world(&local);
                p.z = 0.0;
                if !points
                    .iter()
                    .any(|q: &Vector3<Real>| (q - p).norm() <= 1e-12 * self.radius)
                {
                    points.push(p);
                }
            }
        }
        points
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn upright() -> CylinderRim {
        CylinderRim::new(Vector3::new(0.0, 1.0, 0.0), 0.5, 0.25, Vector3::zeros())
    }

    #[test]
    fn a_node_pressed_into_the_cap_on_the_rim_counts_the_cap_only() {
        // On the rim circle under the bottom cap, moving up into the cylinder (the cylinder
        // coming down): it slides along the side and crosses the cap.
        let c = upright();
        let from = Vector3::new(0.5, 0.75, 0.0);
        let to = Vector3::new(0.5, 0.76, 0.0);
        let x = c.crossing(&from, &to, 1e-9).unwrap();
        assert!(
            (x.normal - Vector3::new(0.0, -1.0, 0.0)).norm() < 1e-12,
            "{x:?}"
        );
        assert!((x.point - from).norm() < 1e-12);
    }

    #[test]
    fn through_the_rim_diagonally_the_normal_is_the_mean() {
        let c = upright();
        let from = Vector3::new(0.6, 0.65, 0.0);
        let to = Vector3::new(0.4, 0.85, 0.0);
        let x = c.crossing(&from, &to, 1e-9).unwrap();
        let mean = Vector3::new(1.0, -1.0, 0.0).normalize();
        assert!((x.normal - mean).norm() < 1e-12, "{x:?}");
        assert!((x.point - Vector3::new(0.5, 0.75, 0.0)).norm() < 1e-12);
    }

    #[test]
    fn the_side_alone_is_left_to_the_nearest_point_and_a_cap_is_a_plane() {
        let c = upright();
        assert_eq!(
            c.crossing(
                &Vector3::new(0.6, 1.0, 0.0),
                &Vector3::new(0.45, 1.0, 0.0),
                1e-9
            ),
            None
        );
        let x = c
            .crossing(
                &Vector3::new(0.1, 1.3, 0.2),
                &Vector3::new(0.1, 1.2, 0.2),
                1e-9,
            )
            .unwrap();
        assert!((x.normal - Vector3::y()).norm() < 1e-12);
        assert!((x.point - Vector3::new(0.1, 1.25, 0.2)).norm() < 1e-12);
        // A node that starts inside crossed nothing.
        assert_eq!(
            c.crossing(
                &Vector3::new(0.0, 1.0, 0.0),
                &Vector3::new(0.0, 1.1, 0.0),
                1e-9
            ),
            None
        );
    }

    #[test]
    fn rim_points_lie_on_the_rims_and_a_lying_cylinder_has_four_section_corners() {
        let c = upright();
        let points = c.sharp_points(0.1);
        assert!(points.len() >= 2 * 32);
        for p in &points {
            let l = c.local(p);
            assert!(((l.x * l.x + l.z * l.z).sqrt() - 0.5).abs() < 1e-12);
            assert!((l.y.abs() - 0.25).abs() < 1e-12);
        }
        // Axis along x: the section by z = 0 is a rectangle 0.5 long, 1 high.
        let lying = CylinderRim::new(
            Vector3::zeros(),
            0.5,
            0.25,
            Vector3::new(0.0, 0.0, std::f64::consts::FRAC_PI_2),
        );
        let mut corners: Vec<[i64; 2]> = lying
            .section_corners()
            .iter()
            .map(|p| [(p.x * 1e6).round() as i64, (p.y * 1e6).round() as i64])
            .collect();
        corners.sort_unstable();
        assert_eq!(
            corners,
            [
                [-250000, -500000],
                [-250000, 500000],
                [250000, -500000],
                [250000, 500000]
            ]
        );
    }
}
