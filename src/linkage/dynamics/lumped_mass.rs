//! The lumped mass of a body: each member's mass `ρ A L` shared half and half by its end nodes.

use crate::linkage::Body;
use crate::Real;

/// Why a body has no usable mass.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MassError {
    /// A member's material has no density (or not a positive one).
    #[error("body '{body}': material '{material}' has no density: a dynamic scene needs `density` (kg/m³, > 0) on every material its members use")]
    NoDensity {
        /// Body name.
        body: String,
        /// Material name.
        material: String,
    },
    /// A node that no member reaches: it has no mass to move with.
    #[error("body '{body}': node {node} has no mass (no member reaches it): a dynamic scene needs every node on a member")]
    Massless {
        /// Body name.
        body: String,
        /// 1-based node.
        node: usize,
    },
}

/// The lumped mass per body DOF of `body`, kg: per node the sum over its members of
/// `ρ A L / 2` (`L` the undeformed length), the same in each of its `d` directions, with
/// `density[k]` (kg/m³) that of `body.materials[k]`. The total is `Σ ρ A L` exactly up to
/// round-off. Every material a member uses needs a density > 0, and every node a member.
pub fn lumped_mass(body: &Body, density: &[Option<Real>]) -> Result<Vec<Real>, MassError> {
    let d = body.dimension.dofs_per_node();
    for m in &body.members {
        if !density
            .get(m.material)
            .copied()
            .flatten()
            .is_some_and(|rho| rho.is_finite() && rho > 0.0)
        {
            return Err(MassError::NoDensity {
                body: body.name.clone(),
                material: body.materials[m.material].name.clone(),
            });
        }
    }
    let node_mass = node_masses(body, density);
    if let Some(node) = node_mass.iter().position(|&m| m <= 0.0) {
        return Err(MassError::Massless {
            body: body.name.clone(),
            node: node + 1,
        });
    }
    Ok(node_mass
        .iter()
        .flat_map(|&m| std::iter::repeat_n(m, d))
        .collect())
}

/// Per node of `body` the sum over its members of `ρ A L / 2`, kg (`L` the undeformed length,
/// `density[k]` in kg/m³ that of `body.materials[k]`; a member of a material without density
/// weighs nothing): the lumped masses both the inertia and the self-weight use.
pub fn node_masses(body: &Body, density: &[Option<Real>]) -> Vec<Real> {
    let mut mass = vec![0.0; body.nodes.len()];
    for m in &body.members {
        let Some(rho) = density.get(m.material).copied().flatten() else {
            continue;
        };
        let [a, b] = m.nodes;
        let length = (body.nodes[b] - body.nodes[a]).norm();
        let half = 0.5 * rho * body.materials[m.material].area * length;
        mass[a] += half;
        mass[b] += half;
    }
    mass
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linkage::{Dimension, Material, Member};
    use nalgebra::Vector3;

    #[test]
    fn two_members_share_their_masses_half_and_half() {
        // Hand calculation: ρ = 7850 kg/m³, A = 1e-4 m², members of 1 m and 2 m: masses
        // 0.785 kg and 1.57 kg; node 2 carries half of each, 1.1775 kg, in x and y.
        let mut body = Body::new("bar", Dimension::Two);
        body.materials.push(Material::new("steel", 200e9, 1e-4));
        body.nodes = vec![
            Vector3::zeros(),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(3.0, 0.0, 0.0),
        ];
        body.members = vec![
            Member {
                nodes: [0, 1],
                material: 0,
            },
            Member {
                nodes: [1, 2],
                material: 0,
            },
        ];
        let m = lumped_mass(&body, &[Some(7850.0)]).unwrap();
        let expect = [0.3925, 0.3925, 1.1775, 1.1775, 0.785, 0.785];
        for (a, b) in m.iter().zip(expect) {
            assert!((a - b).abs() < 1e-12, "{m:?}");
        }
        assert_eq!(
            lumped_mass(&body, &[None]),
            Err(MassError::NoDensity {
                body: "bar".into(),
                material: "steel".into()
            })
        );
        body.nodes.push(Vector3::new(5.0, 0.0, 0.0));
        assert!(matches!(
            lumped_mass(&body, &[Some(1.0)]),
            Err(MassError::Massless { node: 4, .. })
        ));
    }
}
