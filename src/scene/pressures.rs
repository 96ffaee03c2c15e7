//! `[[bodies.pressures]]`: pressure on the patches whose three nodes a selector chooses.

use crate::linkage::{pressure_loads, Body, Dimension, Schedule};
use crate::scene::select_nodes;
use crate::scene::spec::PressureSpec;

/// Add the loads of `spec` (Pa on the chosen patches) to `body`, growing by `schedule`; errors
/// say what to change.
pub(crate) fn add_pressure(
    body: &mut Body,
    spec: &PressureSpec,
    schedule: Schedule,
) -> Result<(), String> {
    if body.dimension == Dimension::Two {
        return Err("pressure acts on patches, which 2D bodies do not have (pressure on 2D boundary segments is not available yet): apply `[[bodies.loads]]` instead".to_string());
    }
    if !spec.pressure.is_finite() {
        return Err(format!(
            "pressure = {}: give a finite pressure in Pa",
            spec.pressure
        ));
    }
    let nodes = select_nodes(&spec.selector(), body)?;
    let mut chosen = vec![false; body.nodes.len()];
    for n in nodes {
        chosen[n] = true;
    }
    let loads = pressure_loads(body, &chosen, spec.pressure, &schedule);
    if loads.is_empty() {
        return Err("no patch has all three of its nodes among the selected ones: select the nodes of whole surface triangles (e.g. `on_plane` on a face)".to_string());
    }
    body.loads.extend(loads);
    Ok(())
}
