//! The camera: where it looks from and how it projects points onto the frame.

use crate::render::Projection;
use crate::Real;
use nalgebra::Vector3;

/// Where the camera looks from: angles in degrees around the centre of what it shows, about
/// the scene's `up` direction. With `up` = +y, azimuth 0 and elevation 0 look along −z (the
/// plane of 2D bodies face on); another `up` turns the whole view by the rotation that takes
/// +y to it (with +z up, azimuth 0 looks along +y, x to the right).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Rotation about `up`, degrees (with +y up: from +z towards +x).
    pub azimuth: Real,
    /// Angle above the plane normal to `up`, degrees (−90 to 90).
    pub elevation: Real,
    /// The unit direction drawn upwards on the frame (+y for most scenes, +z for z-up
    /// scenes, opposite gravity when a scene has it).
    pub up: Vector3<Real>,
    /// Magnification of the fitted view (1: the box fills the viewport).
    pub zoom: Real,
    /// Orthographic or perspective.
    pub projection: Projection,
}

/// Field of view of the perspective projection, degrees.
pub const FIELD_OF_VIEW: Real = 30.0;

/// A camera fitted to a box and a viewport: maps world points (m) to frame pixels.
#[derive(Clone, Debug, PartialEq)]
pub struct View {
    right: Vector3<Real>,
    up: Vector3<Real>,
    back: Vector3<Real>,
    centre: Vector3<Real>,
    /// Distance from the eye to `centre`, m (0 for orthographic).
    eye_distance: Real,
    /// Pixels per unit of projected length.
    scale: Real,
    /// Pixel position of the projected centre.
    offset: (Real, Real),
    /// Depth differences below this count as equal (in depth units).
    depth_epsilon: f32,
}

impl Camera {
    /// The view that shows the box `min`–`max` (m) whole inside the pixel rectangle
    /// `viewport` = `[x0, y0, x1, y1]`, centred, then zoomed by `self.zoom`.
    pub fn fit(&self, min: Vector3<Real>, max: Vector3<Real>, viewport: [Real; 4]) -> View {
        let (az, el) = (self.azimuth.to_radians(), self.elevation.to_radians());
        let back = Vector3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos());
        // Looking straight down or up: "up" on the frame is −z or +z instead of +y.
        let world_up = if back.y.abs() > 0.999 {
            Vector3::new(0.0, 0.0, -back.y.signum())
        } else {
            Vector3::y()
        };
        // The y-up view turned so that +y goes to `self.up`.
        let turn = turn_y_to(&self.up);
        let (back, world_up) = (turn * back, turn * world_up);
        let right = world_up.cross(&back).normalize();
        let up = back.cross(&right);
        let centre = (min + max) / 2.0;
        let radius = ((max - min).norm() / 2.0).max(1e-12);
        let eye_distance = match self.projection {
            Projection::Orthographic => 0.0,
            Projection::Perspective => radius / (FIELD_OF_VIEW.to_radians() / 2.0).sin(),
        };
        let mut view = View {
            right,
            up,
            back,
            centre,
            eye_distance,
            scale: 1.0,
            offset: (0.0, 0.0),
            depth_epsilon: 0.0,
        };
        let mut lo = (Real::INFINITY, Real::INFINITY);
        let mut hi = (Real::NEG_INFINITY, Real::NEG_INFINITY);
        for k in 0..8 {
            let corner = Vector3::new(
                if k & 1 == 0 { min.x } else { max.x },
                if k & 2 == 0 { min.y } else { max.y },
                if k & 4 == 0 { min.z } else { max.z },
            );
            let (sx, sy, _) = view.projected(&corner);
            lo = (lo.0.min(sx), lo.1.min(sy));
            hi = (hi.0.max(sx), hi.1.max(sy));
        }
        let w = (hi.0 - lo.0).max(radius * 1e-9);
        let h = (hi.1 - lo.1).max(radius * 1e-9);
        let (vw, vh) = (viewport[2] - viewport[0], viewport[3] - viewport[1]);
        view.scale = (vw / w).min(vh / h) * self.zoom;
        let mid = ((lo.0 + hi.0) / 2.0, (lo.1 + hi.1) / 2.0);
        view.offset = (
            (viewport[0] + viewport[2]) / 2.0 - mid.0 * view.scale,
            (viewport[1] + viewport[3]) / 2.0 + mid.1 * view.scale,
        );
        view.depth_epsilon = match self.projection {
            Projection::Orthographic => (radius * 4e-3) as f32,
            Projection::Perspective => (radius * 4e-3 / (eye_distance * eye_distance)) as f32,
        };
        view
    }
}

/// The rotation that takes +y to the direction `up` (the identity for +y or a zero vector;
/// half a turn about +x for −y): x stays to the right when `up` lies in the x = 0 plane.
pub fn turn_y_to(up: &Vector3<Real>) -> nalgebra::Rotation3<Real> {
    let Some(u) = up.try_normalize(1e-12) else {
        return nalgebra::Rotation3::identity();
    };
    nalgebra::Rotation3::rotation_between(&Vector3::y(), &u).unwrap_or_else(|| {
        nalgebra::Rotation3::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
    })
}

impl View {
    /// Projected coordinates before the pixel mapping: (x, y, depth).
    fn projected(&self, p: &Vector3<Real>) -> (Real, Real, Real) {
        let d = p - self.centre;
        let (x, y, z) = (self.right.dot(&d), self.up.dot(&d), self.back.dot(&d));
        if self.eye_distance > 0.0 {
            let dist = (self.eye_distance - z).max(self.eye_distance * 1e-3);
            let k = self.eye_distance / dist;
            (x * k, y * k, -1.0 / dist)
        } else {
            (x, y, -z)
        }
    }

    /// Frame pixel coordinates of `p` (x right, y down) and its depth (smaller is nearer;
    /// linear across the screen, so it interpolates exactly over a triangle).
    pub fn project(&self, p: &Vector3<Real>) -> [f32; 3] {
        let (x, y, depth) = self.projected(p);
        [
            (self.offset.0 + x * self.scale) as f32,
            (self.offset.1 - y * self.scale) as f32,
            depth as f32,
        ]
    }

    /// `v` in camera axes (x right, y up, z towards the viewer).
    pub fn to_camera(&self, v: &Vector3<Real>) -> [f32; 3] {
        [
            self.right.dot(v) as f32,
            self.up.dot(v) as f32,
            self.back.dot(v) as f32,
        ]
    }

    /// Depth differences below this count as equal (the tolerance of depth-tested lines).
    pub fn depth_epsilon(&self) -> f32 {
        self.depth_epsilon
    }

    /// Pixels per metre at the centre of the view.
    pub fn pixels_per_metre(&self) -> Real {
        self.scale
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn face_on_view_keeps_x_right_y_up_and_fills_the_viewport() {
        let cam = Camera {
            azimuth: 0.0,
            elevation: 0.0,
            zoom: 1.0,
            projection: Projection::Orthographic,
            up: Vector3::y(),
        };
        let v = cam.fit(
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(2.0, 1.0, 0.0),
            [0.0, 0.0, 200.0, 200.0],
        );
        let a = v.project(&Vector3::new(0.0, 0.0, 0.0));
        let b = v.project(&Vector3::new(2.0, 1.0, 0.0));
        assert!((a[0] - 0.0).abs() < 1e-3 && (b[0] - 200.0).abs() < 1e-3);
        assert!((a[1] - 150.0).abs() < 1e-3 && (b[1] - 50.0).abs() < 1e-3);
    }

    #[test]
    fn perspective_depth_orders_points() {
        let cam = Camera {
            azimuth: 30.0,
            elevation: 20.0,
            zoom: 1.0,
            projection: Projection::Perspective,
            up: Vector3::y(),
        };
        let v = cam.fit(
            Vector3::new(-1.0, -1.0, -1.0),
            Vector3::new(1.0, 1.0, 1.0),
            [0.0, 0.0, 100.0, 100.0],
        );
        let back = Vector3::new(30f64.to_radians().sin(), 0.0, 30f64.to_radians().cos());
        let near = v.project(&(back * 0.9));
        let far = v.project(&(-back * 0.9));
        assert!(near[2] < far[2]);
    }

    #[test]
    fn z_up_draws_z_upwards_and_keeps_x_to_the_right() {
        let cam = Camera {
            azimuth: 0.0,
            elevation: 0.0,
            zoom: 1.0,
            projection: Projection::Orthographic,
            up: Vector3::z(),
        };
        let v = cam.fit(
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(1.0, 1.0, 1.0),
            [0.0, 0.0, 100.0, 100.0],
        );
        let o = v.project(&Vector3::zeros());
        let z = v.project(&Vector3::z());
        let x = v.project(&Vector3::x());
        // Pixel y grows downwards: +z is above the origin by the whole viewport, +x right.
        assert!((o[1] - z[1] - 100.0).abs() < 1e-3, "{o:?} {z:?}");
        assert!((x[0] - o[0] - 100.0).abs() < 1e-3, "{o:?} {x:?}");
        // Seen along +y (azimuth 0 turned with the scene): a step along y changes only depth.
        let y = v.project(&Vector3::y());
        assert!((y[0] - o[0]).abs() < 1e-3 && (y[1] - o[1]).abs() < 1e-3);
    }

    #[test]
    fn up_turns_y_to_the_given_axis() {
        for up in [Vector3::x(), Vector3::y(), Vector3::z(), -Vector3::y()] {
            let t = turn_y_to(&up);
            assert!((t * Vector3::y() - up).norm() < 1e-12, "{up:?}");
        }
    }
}
