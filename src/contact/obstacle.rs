//! A rigid obstacle as plain data: its shape, where it is, and how it moves over the steps.

use crate::linkage::body_state::factor_at;
use crate::linkage::Schedule;
use crate::Real;
use nalgebra::Vector3;

/// The shape of a rigid obstacle and where it stands at step 0. Points in m; rotations are
/// rotation vectors (axis times angle, radians) applied about the shape's centre.
#[derive(Clone, Debug, PartialEq)]
pub enum ObstacleShape {
    /// Everything on the inner side of the plane through `point` with the outward unit
    /// `normal` (bodies belong on the side the normal points to).
    HalfSpace {
        /// A point on the boundary plane, m.
        point: Vector3<Real>,
        /// Outward unit normal.
        normal: Vector3<Real>,
    },
    /// A box with half extents along its local axes.
    Cuboid {
        /// Centre, m.
        center: Vector3<Real>,
        /// Half extents along the local x, y, z axes, m.
        half_extents: Vector3<Real>,
        /// Rotation vector, rad.
        rotation: Vector3<Real>,
    },
    /// A ball.
    Ball {
        /// Centre, m.
        center: Vector3<Real>,
        /// Radius, m.
        radius: Real,
    },
    /// A cylinder whose axis is the local y axis.
    Cylinder {
        /// Centre, m.
        center: Vector3<Real>,
        /// Radius, m.
        radius: Real,
        /// Half the length along the axis, m.
        half_height: Real,
        /// Rotation vector, rad.
        rotation: Vector3<Real>,
    },
    /// A closed triangle mesh, counter-clockwise seen from outside (3D).
    Mesh {
        /// Vertices, m.
        vertices: Vec<Vector3<Real>>,
        /// Triangles, 0-based vertex indices.
        triangles: Vec<[usize; 3]>,
    },
    /// A capsule (a segment swept by a ball) whose axis is the local y axis.
    Capsule {
        /// Centre, m.
        center: Vector3<Real>,
        /// Radius, m.
        radius: Real,
        /// Half the length of the segment, m.
        half_height: Real,
        /// Rotation vector, rad.
        rotation: Vector3<Real>,
    },
}

/// A rigid obstacle: a shape that may translate along a straight path over the load steps.
#[derive(Clone, Debug, PartialEq)]
pub struct Obstacle {
    /// Name, distinct from every body's and obstacle's name; results name it in `with`.
    pub name: String,
    /// Shape and position at step 0.
    pub shape: ObstacleShape,
    /// Translation at full schedule (a press plate coming down), m.
    pub travel: Vector3<Real>,
    /// How the translation grows over the steps.
    pub schedule: Schedule,
}

impl Obstacle {
    /// The obstacle's translation at `step` of `steps`, m.
    pub fn offset(&self, step: usize, steps: usize) -> Vector3<Real> {
        if self.travel == Vector3::zeros() {
            return Vector3::zeros();
        }
        self.travel * self.schedule.factor(step, steps)
    }

    /// The obstacle's translation at pseudo-time `t` (step units, fractional between steps:
    /// the schedule interpolated linearly, exact at whole steps), m.
    pub fn offset_at(&self, t: Real, steps: usize) -> Vector3<Real> {
        if self.travel == Vector3::zeros() {
            return Vector3::zeros();
        }
        self.travel * factor_at(&self.schedule, t, steps)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_at_whole_steps_is_the_step_offset_and_linear_between() {
        let o = Obstacle {
            name: "press".to_string(),
            shape: ObstacleShape::Ball {
                center: Vector3::zeros(),
                radius: 1.0,
            },
            travel: Vector3::new(0.0, -0.4, 0.0),
            schedule: Schedule::Factors(vec![0.5, 1.0]),
        };
        for k in 0..=2 {
            assert_eq!(o.offset_at(k as Real, 2), o.offset(k, 2));
        }
        // Halfway between step 1 (0.5) and step 2 (1.0): factor 0.75.
        assert!((o.offset_at(1.5, 2).y + 0.3).abs() < 1e-15);
    }
}
