//! Rigid stops: fixed planes a body's nodes press against, held by a penalty spring (the
//! contact solver's half-space law `f = k · depth · n`), in one body's Newton residual and
//! tangent. The arc-length path then follows the body through a limit point and against the
//! stop: the penalty force joins the out-of-balance `λ F_ref + F_stop − f_int` and its
//! stiffness `k n nᵀ` (exact for a plane) the tangent of every pressed node, so the
//! constraint's quadratic and the predictor see the stop as they see the members.

use crate::linkage::body_state::node_vector;
use crate::linkage::{Body, StiffnessAssembly};
use crate::Real;
use nalgebra::Vector3;

/// A fixed plane a body's nodes may not cross: a node `depth` (m) beyond it is pushed back by
/// `stiffness · depth` along `normal`.
#[derive(Clone, Debug, PartialEq)]
pub struct Stop {
    /// Name (the obstacle's), for results and messages.
    pub name: String,
    /// A point of the plane, m.
    pub point: Vector3<Real>,
    /// Unit normal, pointing out of the stop (toward the side the body is on).
    pub normal: Vector3<Real>,
    /// Penalty stiffness, N/m of depth.
    pub stiffness: Real,
}

impl Stop {
    /// How far the point `x` (m) lies beyond the plane, m (negative on the body's side).
    pub fn depth(&self, x: &Vector3<Real>) -> Real {
        -(x - self.point).dot(&self.normal)
    }

    /// The force of the stop on a node at `x`, N: `k · depth · n` when the node is beyond
    /// the plane, `None` on the body's side (a stop only pushes).
    pub fn force(&self, x: &Vector3<Real>) -> Option<Vector3<Real>> {
        let depth = self.depth(x);
        (depth > 0.0).then(|| self.normal * (self.stiffness * depth))
    }
}

/// The deformed position of `node` of `body` at displacement `u` (per body DOF), m.
fn position(body: &Body, u: &[Real], node: usize) -> Vector3<Real> {
    body.nodes[node] + node_vector(u, body.dimension.dofs_per_node(), node)
}

/// Add the force of every stop on every node of `body` at displacement `u` (per body DOF, m)
/// into `out` (per body DOF, N).
pub fn add_stop_forces(body: &Body, stops: &[Stop], u: &[Real], out: &mut [Real]) {
    let d = body.dimension.dofs_per_node();
    for node in 0..body.nodes.len() {
        let x = position(body, u, node);
        for stop in stops {
            if let Some(f) = stop.force(&x) {
                for k in 0..d {
                    out[node * d + k] += f[k];
                }
            }
        }
    }
}

/// The total force of each stop on `body` at displacement `u`, N (one per stop, in order),
/// and the nodes it presses (0-based).
pub fn stop_forces(body: &Body, stops: &[Stop], u: &[Real]) -> Vec<(Vector3<Real>, Vec<usize>)> {
    stops
        .iter()
        .map(|stop| {
            let mut total = Vector3::zeros();
            let mut nodes = Vec::new();
            for node in 0..body.nodes.len() {
                if let Some(f) = stop.force(&position(body, u, node)) {
                    total += f;
                    nodes.push(node);
                }
            }
            (total, nodes)
        })
        .collect()
}

/// Add each pressed node's penalty stiffness `k n nᵀ` (N/m) to the tangent `values` in the
/// pattern of `assembly`.
pub(crate) fn add_stop_stiffness(
    body: &Body,
    stops: &[Stop],
    u: &[Real],
    assembly: &StiffnessAssembly,
    values: &mut [Real],
) {
    for node in 0..body.nodes.len() {
        let x = position(body, u, node);
        for stop in stops {
            if stop.depth(&x) > 0.0 {
                let block = stop.normal * stop.normal.transpose() * stop.stiffness;
                assembly.add_node_block(node, &block, values);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stop_pushes_a_node_beyond_it_back_in_proportion_to_its_depth() {
        let stop = Stop {
            name: "floor".to_string(),
            point: Vector3::new(0.0, 0.2, 0.0),
            normal: Vector3::new(0.0, 1.0, 0.0),
            stiffness: 1e6,
        };
        // 1 mm below the floor: 1e6 N/m × 1e-3 m = 1000 N up.
        let f = stop.force(&Vector3::new(3.0, 0.199, 0.0)).unwrap();
        assert!((f - Vector3::new(0.0, 1000.0, 0.0)).norm() <= 1e-9, "{f}");
        assert!(stop.force(&Vector3::new(3.0, 0.2, 0.0)).is_none());
        assert!(stop.force(&Vector3::new(3.0, 0.3, 0.0)).is_none());
    }
}
