//! `linkage check`: every check `linkage run` makes before its first load step, without
//! solving a step, and what the run would write.

use crate::scene::results::BodySize;
use crate::scene::run_error::RunError;
use crate::scene::{OutputSettings, ResultFormat, World};
use std::path::PathBuf;

/// A run that would write more step files than this, bytes, is warned about (1 GiB).
pub const OUTPUT_WARNING_BYTES: u64 = 1 << 30;

/// Bytes one value takes in a step file (JSON: a full-precision number, its comma, and a
/// share of the keys and brackets): 19–25 measured on the bundled scenes.
pub const BYTES_PER_VALUE: u64 = 21;

/// What [`check_world`] found: a scene that `linkage run` accepts up to its first step.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckReport {
    /// The scene file.
    pub scene: PathBuf,
    /// The model's size in one line ([`World::describe`]).
    pub describe: String,
    /// Per body its sizes and the solver it uses, as the run's summary gives them.
    pub bodies: Vec<BodySize>,
    /// What the check cannot decide without solving (a nonlinear body's steps, contacts).
    pub notes: Vec<String>,
    /// What loading the scene found and changed (mesh faces turned outward).
    pub found: Vec<String>,
    /// Per 3D body with a closed surface (or a material with `continuum_modulus`) its Young's
    /// modulus and Poisson's ratio as a solid ([`crate::linkage::homogenize`]).
    pub solids: Vec<String>,
    /// What the run would do that a user may not want: the scene's own warnings
    /// ([`World::warnings`]), more than 1 GiB of step files.
    pub warnings: Vec<String>,
}

/// Every check `linkage run` makes before its first load step, with the same errors: the
/// solvers are built as the run builds them ([`crate::scene::Simulation::new`], or [`crate::scene::DynamicSimulation::new`] in time: validation, assembly,
/// factorization, mechanisms and rigid motions left free by the supports of linear bodies,
/// contact surfaces, bodies starting inside obstacles or each other). Nothing is written.
pub fn check_world(world: &World) -> Result<CheckReport, RunError> {
    let simulation = crate::scene::Stepper::new(world)?;
    let mut notes = Vec::new();
    for body in world.bodies.iter().filter(|b| b.is_nonlinear()) {
        notes.push(format!(
            "body '{}' is nonlinear: whether Newton converges at each load step is found only by solving the steps (`linkage run`)",
            body.name
        ));
    }
    if world.has_contact() {
        notes.push(
            "the contacts each step makes, whether they settle and whether they hold bodies left free by their supports are found only by solving the steps (`linkage run`)"
                .to_string(),
        );
    }
    Ok(CheckReport {
        scene: world.source.clone(),
        describe: world.describe(),
        bodies: simulation.sizes(),
        notes,
        found: world.found.clone(),
        solids: solid_lines(world),
        warnings: world
            .warnings
            .iter()
            .cloned()
            .chain(output_warning(world))
            .collect(),
    })
}

/// How many steps `output` writes of a run of `steps` load steps (step 0 and the last always).
pub fn stored_steps(output: &OutputSettings, steps: usize) -> u64 {
    let steps = steps as u64;
    if steps == 0 {
        1
    } else if output.last_only {
        2
    } else {
        let every = output.every.max(1) as u64;
        steps / every + 1 + u64::from(!steps.is_multiple_of(every))
    }
}

/// Bytes one value takes in a `.npz` step file (a raw `float64`).
pub const NPZ_BYTES_PER_VALUE: u64 = 8;

/// The bytes of one step file of `world`, estimated: per node its displacement and position,
/// per member its axial force, strain and stress, [`BYTES_PER_VALUE`] each as JSON,
/// [`NPZ_BYTES_PER_VALUE`] as `.npz`.
pub fn step_file_bytes(world: &World) -> u64 {
    let per_value = match world.output.format {
        ResultFormat::Json => BYTES_PER_VALUE,
        ResultFormat::Npz => NPZ_BYTES_PER_VALUE,
    };
    let values: u64 = world
        .bodies
        .iter()
        .map(|b| {
            let d = b.dimension.dofs_per_node() as u64;
            2 * d * b.nodes.len() as u64 + 3 * b.members.len() as u64
        })
        .sum();
    values * per_value
}

/// The bytes `model.json` takes for the obstacles' offsets, one per step 0..=steps and
/// obstacle (`[0.0,0.0,0.0],` for one that stays put), estimated.
pub fn obstacle_offset_bytes(world: &World) -> u64 {
    let per_step: u64 = world
        .obstacles
        .iter()
        .map(|o| {
            if o.travel == nalgebra::Vector3::zeros() {
                14
            } else {
                3 * BYTES_PER_VALUE
            }
        })
        .sum();
    per_step.saturating_mul(world.steps as u64 + 1)
}

/// The warning of a run of `world` whose step files would exceed [`OUTPUT_WARNING_BYTES`]:
/// the estimate and how to write fewer steps (`None` when below).
pub fn output_warning(world: &World) -> Option<String> {
    let stored = stored_steps(&world.output, world.steps);
    let per_step = step_file_bytes(world);
    let offsets = obstacle_offset_bytes(world);
    let total = stored.saturating_mul(per_step).saturating_add(offsets);
    if total <= OUTPUT_WARNING_BYTES {
        return None;
    }
    // Every k-th step keeps the files under the limit (step 0 and the last are always written).
    let room = (OUTPUT_WARNING_BYTES / per_step.max(1))
        .saturating_sub(2)
        .max(1);
    let every = (world.steps as u64).div_ceil(room).max(2);
    Some(format!(
        "the run would write about {:.1} GB ({stored} step files of about {} kB each, estimated from {} nodes and {} members{}): write fewer steps with [output] every = {every} or last_only = true, or use fewer load steps{}",
        total as f64 / 1e9,
        per_step.div_ceil(1000),
        world.bodies.iter().map(|b| b.nodes.len()).sum::<usize>(),
        world.bodies.iter().map(|b| b.members.len()).sum::<usize>(),
        if offsets > 0 {
            format!(
                ", and {:.1} GB of obstacle offsets in model.json",
                offsets as f64 / 1e9
            )
        } else {
            String::new()
        },
        match world.output.format {
            ResultFormat::Json => ", or write them as NumPy arrays with [output] format = \"npz\" (2 to 3 times smaller)",
            ResultFormat::Npz => "",
        },
    ))
}

/// Bodies with more members than this are not homogenized by `linkage check` (the three
/// uniaxial tests factor the body three times).
pub const SOLID_CHECK_MEMBERS: usize = 300_000;

/// One line per 3D body that models a solid: its elasticity as one, or why it has none.
fn solid_lines(world: &World) -> Vec<String> {
    use crate::linkage::homogenize::{continuum_volume, effective_elasticity};
    let mut lines = Vec::new();
    for body in &world.bodies {
        if let Some(s) = world.solids.get(&body.name) {
            let area = body
                .members
                .first()
                .map_or(0.0, |m| body.materials[m.material].area);
            lines.push(format!(
                "body '{}' (continuum_modulus: member area {area:.4e} m²): {s}",
                body.name
            ));
            continue;
        }
        if body.dimension != crate::linkage::Dimension::Three || !is_closed(&body.patches) {
            continue;
        }
        if body.members.len() > SOLID_CHECK_MEMBERS {
            lines.push(format!(
                "body '{}': not homogenized ({} members, more than {SOLID_CHECK_MEMBERS})",
                body.name,
                body.members.len()
            ));
            continue;
        }
        let volume = world
            .prepared
            .get(&body.name)
            .map_or_else(|| continuum_volume(body), |r| r.reference);
        lines.push(match effective_elasticity(body, volume) {
            Ok(s) => format!("body '{}': {s}", body.name),
            Err(e) => e.to_string(),
        });
    }
    lines
}

/// Whether `patches` are a closed surface: not empty, every edge in exactly two of them.
fn is_closed(patches: &[[usize; 3]]) -> bool {
    let mut edges = std::collections::HashMap::new();
    for &[a, b, c] in patches {
        for (p, q) in [(a, b), (b, c), (c, a)] {
            *edges.entry((p.min(q), p.max(q))).or_insert(0usize) += 1;
        }
    }
    !patches.is_empty() && edges.values().all(|&n| n == 2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stored_steps_count_step_zero_and_the_last() {
        let every = |every, last_only| OutputSettings {
            every,
            last_only,
            ..OutputSettings::default()
        };
        assert_eq!(stored_steps(&every(1, false), 10), 11);
        assert_eq!(stored_steps(&every(3, false), 10), 5); // 0, 3, 6, 9, 10
        assert_eq!(stored_steps(&every(5, false), 10), 3); // 0, 5, 10
        assert_eq!(stored_steps(&every(1, true), 10), 2);
        assert_eq!(stored_steps(&every(1, true), 0), 1);
        for (e, last_only, steps) in [(3, false, 10), (4, false, 7), (1, true, 5), (2, false, 1)] {
            let o = every(e, last_only);
            let counted = (0..=steps).filter(|&s| o.writes(s, steps)).count() as u64;
            assert_eq!(stored_steps(&o, steps), counted);
        }
    }
}
