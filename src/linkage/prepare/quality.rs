//! The quality report of a prepared body: counts, its volume (or area) against the part's,
//! member lengths, and the smallest and largest dihedral (or triangle) angles.

use crate::linkage::{Dimension, Geometry};
use crate::Real;
use nalgebra::Vector3;
use std::fmt;

/// What `linkage prepare` prints and a run's `summary.json` records for a prepared body.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PrepareReport {
    /// 2 or 3.
    pub dimension: usize,
    /// The spacing asked for (target member length), m.
    pub spacing: Real,
    /// Nodes of the body.
    pub nodes: usize,
    /// Members of the body.
    pub members: usize,
    /// Patches (3D) or boundary segments (2D).
    pub patches: usize,
    /// Volume enclosed by the patches (3D, m³) or area of the triangles (2D, m²).
    pub measure: Real,
    /// The same of the mesh or outline given, m³ or m².
    pub reference: Real,
    /// `measure / reference − 1`.
    pub relative_error: Real,
    /// Shortest member, m.
    pub shortest_member: Real,
    /// Longest member, m.
    pub longest_member: Real,
    /// Smallest dihedral angle of a tetrahedron (3D) or angle of a triangle (2D), degrees.
    pub smallest_angle: Real,
    /// Largest dihedral angle (3D) or triangle angle (2D), degrees.
    pub largest_angle: Real,
    /// The body's Young's moduli and Poisson's ratio as a solid (its uniaxial tests, see
    /// [`crate::linkage::homogenize`]), for a body of a material with `continuum_modulus`
    /// (none otherwise: `linkage check` and `linkage prepare` show them for any 3D body).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub solid: Option<crate::linkage::homogenize::EffectiveElasticity>,
}

impl fmt::Display for PrepareReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (what, unit, angle) = if self.dimension == 3 {
            ("volume", "m³", "dihedral")
        } else {
            ("area", "m²", "triangle")
        };
        writeln!(
            f,
            "nodes {}, members {}, {} {}",
            self.nodes,
            self.members,
            if self.dimension == 3 {
                "patches"
            } else {
                "boundary segments"
            },
            self.patches
        )?;
        writeln!(
            f,
            "{what} {:.6e} {unit} against {:.6e} {unit} given ({:+.3}%)",
            self.measure,
            self.reference,
            100.0 * self.relative_error
        )?;
        writeln!(
            f,
            "member length {:.4e} to {:.4e} m ({:.3} to {:.3} × spacing {} m)",
            self.shortest_member,
            self.longest_member,
            self.shortest_member / self.spacing,
            self.longest_member / self.spacing,
            self.spacing
        )?;
        write!(
            f,
            "{angle} angle {:.2}° to {:.2}°",
            self.smallest_angle, self.largest_angle
        )?;
        match &self.solid {
            Some(s) => write!(f, "\n{s}"),
            None => Ok(()),
        }
    }
}

/// Volume enclosed by outward `triangles` over `vertices` (divergence theorem), m³.
pub fn enclosed_volume(vertices: &[Vector3<Real>], triangles: &[[usize; 3]]) -> Real {
    triangles
        .iter()
        .map(|&[a, b, c]| vertices[a].dot(&vertices[b].cross(&vertices[c])))
        .sum::<Real>()
        / 6.0
}

/// The six dihedral angles of tetrahedron `t` over `nodes`, radians.
pub fn dihedral_angles(nodes: &[Vector3<Real>], t: [usize; 4]) -> [Real; 6] {
    let p = t.map(|v| nodes[v]);
    // Outward normal of the face opposite vertex k.
    let normal = |k: usize| {
        let [a, b, c] = [0, 1, 2, 3]
            .into_iter()
            .filter(|&i| i != k)
            .collect::<Vec<_>>()[..]
        else {
            unreachable!()
        };
        let n = (p[b] - p[a]).cross(&(p[c] - p[a]));
        if n.dot(&(p[k] - p[a])) > 0.0 {
            -n
        } else {
            n
        }
    };
    let n = [0, 1, 2, 3].map(normal);
    let mut out = [0.0; 6];
    // Edge (i, j) is where the faces opposite the other two vertices k, l meet.
    for (e, (k, l)) in [(2, 3), (1, 3), (1, 2), (0, 3), (0, 2), (0, 1)]
        .into_iter()
        .enumerate()
    {
        let cos = (n[k].dot(&n[l]) / (n[k].norm() * n[l].norm())).clamp(-1.0, 1.0);
        out[e] = std::f64::consts::PI - cos.acos();
    }
    out
}

/// The report of a 3D body of tetrahedra `tets` made at `spacing` (m) from a mesh enclosing
/// `reference` m³.
pub(crate) fn report_3d(
    geometry: &Geometry,
    tets: &[[usize; 4]],
    spacing: Real,
    reference: Real,
) -> PrepareReport {
    let (mut smallest, mut largest) = (Real::INFINITY, 0.0 as Real);
    for &t in tets {
        for a in dihedral_angles(&geometry.nodes, t) {
            smallest = smallest.min(a);
            largest = largest.max(a);
        }
    }
    let measure = enclosed_volume(&geometry.nodes, &geometry.patches);
    finish(geometry, spacing, measure, reference, smallest, largest)
}

/// The report from the parts every dimension shares; angles in radians.
pub(crate) fn finish(
    geometry: &Geometry,
    spacing: Real,
    measure: Real,
    reference: Real,
    smallest_angle: Real,
    largest_angle: Real,
) -> PrepareReport {
    let (mut shortest, mut longest) = (Real::INFINITY, 0.0 as Real);
    for &[a, b] in &geometry.members {
        let l = (geometry.nodes[a] - geometry.nodes[b]).norm();
        shortest = shortest.min(l);
        longest = longest.max(l);
    }
    PrepareReport {
        dimension: match geometry.dimension {
            Dimension::Two => 2,
            Dimension::Three => 3,
        },
        spacing,
        nodes: geometry.nodes.len(),
        members: geometry.members.len(),
        patches: geometry.patches.len(),
        measure,
        reference,
        relative_error: measure / reference - 1.0,
        shortest_member: shortest,
        longest_member: longest,
        smallest_angle: smallest_angle.to_degrees(),
        largest_angle: largest_angle.to_degrees(),
        solid: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_corner_tetrahedron_has_its_hand_computed_angles() {
        // Corner (0,0,0), (1,0,0), (0,1,0), (0,0,1): three right angles at the axes' edges,
        // and arccos(1/√3) = 54.7356° between the slanted face and each axis plane.
        let nodes = [Vector3::zeros(), Vector3::x(), Vector3::y(), Vector3::z()];
        let mut a = dihedral_angles(&nodes, [0, 1, 2, 3]).map(|a| a.to_degrees());
        a.sort_by(|x, y| x.total_cmp(y));
        let slanted = (1.0 / 3.0f64.sqrt()).acos().to_degrees();
        for (got, want) in a.iter().zip([slanted, slanted, slanted, 90.0, 90.0, 90.0]) {
            assert!((got - want).abs() < 1e-12, "{got} {want}");
        }
        let regular = [
            Vector3::new(1.0, 1.0, 1.0),
            Vector3::new(1.0, -1.0, -1.0),
            Vector3::new(-1.0, 1.0, -1.0),
            Vector3::new(-1.0, -1.0, 1.0),
        ];
        for a in dihedral_angles(&regular, [0, 1, 2, 3]) {
            assert!((a - (1.0 / 3.0f64).acos()).abs() < 1e-12);
        }
    }

    #[test]
    fn a_unit_cube_encloses_one_cubic_metre() {
        let g = crate::linkage::generators::box_lattice([1.0, 2.0, 3.0], [2, 2, 2]).unwrap();
        assert!((enclosed_volume(&g.nodes, &g.patches) - 6.0).abs() < 1e-12);
    }
}
