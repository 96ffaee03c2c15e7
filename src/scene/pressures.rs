//! `[[bodies.pressures]]`: pressure on the patches (3D) or boundary segments (2D) whose nodes a
//! selector chooses; on the undeformed faces of a linear body, following the deformed ones
//! of a body under large displacements.

use crate::linkage::{
    boundary_segments, chosen_patches, pressure_loads_on, Body, Dimension, Kinematics, Pressure,
    PressureFaces, Schedule,
};
use crate::scene::import::NodeGroup;
use crate::scene::selector::select_nodes_in;
use crate::scene::spec::PressureSpec;

/// Add the pressure of `spec` (Pa on the chosen patches, N/m on the chosen 2D boundary
/// segments) to `body`, growing by `schedule`: as nodal loads on the undeformed faces for a
/// linear body, as a following [`Pressure`] for a body under large displacements; `groups`
/// are the body's model-file groups (`group =`). Errors say what to change.
pub(crate) fn add_pressure(
    body: &mut Body,
    spec: &PressureSpec,
    schedule: Schedule,
    groups: &[NodeGroup],
) -> Result<(), String> {
    if !spec.pressure.is_finite() {
        return Err(format!(
            "pressure = {}: give a finite pressure (Pa in 3D, N/m in 2D)",
            spec.pressure
        ));
    }
    let nodes = select_nodes_in(&spec.selector(), body, groups)?;
    let mut chosen = vec![false; body.nodes.len()];
    for n in nodes {
        chosen[n] = true;
    }
    let faces = match body.dimension {
        Dimension::Three => PressureFaces::Patches(chosen_patches(body, &chosen)),
        Dimension::Two => PressureFaces::Segments(boundary_segments(body, &chosen)),
    };
    if faces.is_empty() {
        return Err(match body.dimension {
            Dimension::Three => "no patch has all three of its nodes among the selected ones: select the nodes of whole surface triangles (e.g. `on_plane` on a face)".to_string(),
            Dimension::Two => "no boundary segment (a member with the body on one side) has both of its nodes among the selected ones: select the nodes of whole boundary segments (e.g. `on_line` along an edge)".to_string(),
        });
    }
    if body.kinematics == Kinematics::Large {
        body.pressures.push(Pressure {
            pressure: spec.pressure,
            faces,
            schedule,
        });
    } else {
        let loads = pressure_loads_on(body, &faces, spec.pressure, &schedule);
        body.loads.extend(loads);
    }
    Ok(())
}
