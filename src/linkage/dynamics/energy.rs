//! Kinetic energy and momenta of a body from its lumped masses.

use crate::linkage::Body;
use crate::Real;
use nalgebra::Vector3;

/// `½ Σ m v²` over the body DOFs, J (`mass` kg and `v` m/s per body DOF).
pub fn kinetic_energy(mass: &[Real], v: &[Real]) -> Real {
    0.5 * mass.iter().zip(v).map(|(m, v)| m * v * v).sum::<Real>()
}

/// The linear momentum `Σ m v`, kg·m/s, one component per dimension.
pub fn momentum(body: &Body, mass: &[Real], v: &[Real]) -> Vec<Real> {
    let d = body.dimension.dofs_per_node();
    let mut p = vec![0.0; d];
    for (i, (m, v)) in mass.iter().zip(v).enumerate() {
        p[i % d] += m * v;
    }
    p
}

/// The angular momentum about the origin `Σ m x × v` (x = X + u the current position),
/// kg·m²/s: three components in 3D, the z component alone in 2D.
pub fn angular_momentum(body: &Body, mass: &[Real], u: &[Real], v: &[Real]) -> Vec<Real> {
    let d = body.dimension.dofs_per_node();
    let mut total = Vector3::zeros();
    for (n, p) in body.nodes.iter().enumerate() {
        let mut x = *p;
        let mut w = Vector3::zeros();
        for k in 0..d {
            x[k] += u[n * d + k];
            w[k] = v[n * d + k];
        }
        total += x.cross(&w) * mass[n * d];
    }
    if d == 2 {
        vec![total.z]
    } else {
        total.as_slice().to_vec()
    }
}

/// The centre of mass of the undeformed body, m.
pub fn centre_of_mass(body: &Body, mass: &[Real]) -> Vector3<Real> {
    let d = body.dimension.dofs_per_node();
    let total: Real = (0..body.nodes.len()).map(|n| mass[n * d]).sum();
    body.nodes
        .iter()
        .enumerate()
        .map(|(n, p)| p * mass[n * d])
        .sum::<Vector3<Real>>()
        / total
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linkage::Dimension;

    #[test]
    fn two_masses_spinning_about_their_centre() {
        // Masses 2 kg at (±1, 0) moving at (0, ±3): L_z = 2·(1·3) · 2 = 12, p = 0, T = 18 J.
        let mut body = Body::new("b", Dimension::Two);
        body.nodes = vec![Vector3::new(1.0, 0.0, 0.0), Vector3::new(-1.0, 0.0, 0.0)];
        let mass = [2.0; 4];
        let v = [0.0, 3.0, 0.0, -3.0];
        assert_eq!(angular_momentum(&body, &mass, &[0.0; 4], &v), vec![12.0]);
        assert_eq!(momentum(&body, &mass, &v), vec![0.0, 0.0]);
        assert_eq!(kinetic_energy(&mass, &v), 18.0);
        assert_eq!(centre_of_mass(&body, &mass), Vector3::zeros());
    }
}
