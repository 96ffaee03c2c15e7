//! Loaded box lattices for the solver tests and benchmarks.
//!
//! The bottom face clamped, a force shared by the top face.

use crate::linkage::generators::{box_lattice, GeneratorError};
use crate::linkage::{Body, Material, NodalLoad, Schedule, Support};
use crate::Real;
use nalgebra::Vector3;

/// A steel lattice of `cells` unit cells (0.01 m each, members of 1 mm²), bottom face fixed,
/// the top face pushed down and sideways by 1 kN in total.
pub fn lattice_body(cells: [usize; 3]) -> Result<Body, GeneratorError> {
    loaded_lattice("lattice", cells, Vector3::new(200.0, 0.0, -1000.0))
}

/// A steel lattice of `cells` unit cells (0.01 m each, members of 1 mm²) named `name`, its
/// bottom face clamped, `total_force` (N) shared by the nodes of its top face.
pub fn loaded_lattice(
    name: &str,
    cells: [usize; 3],
    total_force: Vector3<Real>,
) -> Result<Body, GeneratorError> {
    let h = 0.01;
    let size = [
        cells[0] as Real * h,
        cells[1] as Real * h,
        cells[2] as Real * h,
    ];
    let geometry = box_lattice(size, cells)?;
    let mut body = Body::from_geometry(name, geometry, Material::new("steel", 200e9, 1e-6));
    let top: Vec<usize> = (0..body.nodes.len())
        .filter(|&i| (body.nodes[i].z - size[2]).abs() < 1e-9)
        .collect();
    for i in 0..body.nodes.len() {
        if body.nodes[i].z.abs() < 1e-9 {
            body.supports.push(Support::fixed(i, [true, true, true]));
        }
    }
    let per_node = total_force / top.len() as Real;
    for i in top {
        body.loads.push(NodalLoad {
            node: i,
            force: per_node,
            schedule: Schedule::Linear,
        });
    }
    Ok(body)
}
