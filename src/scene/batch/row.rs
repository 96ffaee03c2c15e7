//! A job's row of the batch table, read from its published results folder (so a job skipped
//! because its results are there gets the same row as the run that wrote them).

use crate::scene::batch::jobs::Job;
use crate::scene::batch::table::{contact_column, Row, DYNAMIC};
use crate::scene::peak_stress::peak_stress;
use crate::scene::{StoredRun, Summary, World};
use crate::Real;
use std::path::Path;

/// The summary of `folder` when it holds complete results of `world`: `summary.json` (written
/// last, and published with the folder in one rename) is there, reads, names the scene, came
/// from the same scene text (its `scene_digest`) and says no step failed.
pub fn complete_summary(folder: &Path, world: &World) -> Option<Summary> {
    let bytes = std::fs::read(folder.join("summary.json")).ok()?;
    let summary: Summary = serde_json::from_slice(&bytes).ok()?;
    (summary.scene == world.name
        && summary.scene_digest == world.scene_digest
        && summary.failure.is_none())
    .then_some(summary)
}

/// The row of `job`: `status` (`ok` or `failed: …`), and, when `results` (a folder the run
/// published, complete or stopped early) reads, its numbers; `world` gives the strengths.
pub fn job_row(job: &Job, status: String, results: Option<&Path>, world: Option<&World>) -> Row {
    let mut row = Row {
        job: job.id(),
        scene: job.name.clone(),
        variant: job.variant.map(|k| k.to_string()).unwrap_or_default(),
        values: job.value_cells(),
        status,
        ..Row::default()
    };
    let Some(dir) = results else {
        return row;
    };
    let Some(summary) = std::fs::read(dir.join("summary.json"))
        .ok()
        .and_then(|b| serde_json::from_slice::<Summary>(&b).ok())
    else {
        return row;
    };
    row.nodes = summary
        .bodies
        .iter()
        .map(|b| b.nodes)
        .sum::<usize>()
        .to_string();
    row.members = summary
        .bodies
        .iter()
        .map(|b| b.members)
        .sum::<usize>()
        .to_string();
    if let Some(c) = &summary.collapse {
        // A collapse is a result, not a failure: the status says where.
        row.status = format!(
            "collapsed: body '{}' at step {} (load factor {}), member {}",
            c.body, c.step, c.load_factor, c.member
        );
    }
    let seconds: Real = summary.steps.iter().map(|s| s.seconds).sum();
    row.seconds = format!("{seconds:.6}");
    if let Some(last) = summary.steps.last() {
        row.steps = last.step.to_string();
        row.max_displacement = format!("{:e}", last.max_displacement);
        row.overloaded = last.overloaded.to_string();
        row.broken = last.broken.map(|b| b.to_string()).unwrap_or_default();
        for pair in &last.contact_forces {
            for (axis, f) in pair.force.iter().enumerate() {
                row.contact.push((
                    contact_column(&pair.body, &pair.with, axis),
                    format!("{f:e}"),
                ));
            }
        }
    }
    let states: Vec<_> = summary
        .steps
        .iter()
        .filter_map(|s| s.dynamics.as_ref().map(|d| (s, d)))
        .collect();
    if let Some((_, last)) = states.last() {
        let peak_contact = states
            .iter()
            .map(|(s, _)| {
                s.contact_forces
                    .iter()
                    .map(|p| p.force.iter().map(|f| f * f).sum::<Real>().sqrt())
                    .fold(0.0, Real::max)
            })
            .fold(0.0, Real::max);
        let values = [last.time, peak_contact, last.kinetic_energy];
        row.dynamics = DYNAMIC
            .iter()
            .zip(values)
            .map(|(name, v)| (name.to_string(), format!("{v:e}")))
            .collect();
    }
    let residual = summary
        .steps
        .iter()
        .map(|s| s.residual)
        .fold(0.0, Real::max);
    row.residual = format!("{residual:e}");
    let warnings: Vec<&str> = summary
        .steps
        .iter()
        .flat_map(|s| s.warnings.iter().map(String::as_str))
        .collect();
    row.warnings = warnings.join("; ");
    // The summary carries the last step's peak stress; results written before it did are read
    // back (the whole last step file, which costs a second on a million-member body).
    let (peak, ratio) = match summary.steps.last() {
        Some(last) if last.peak_stress.is_some() => (last.peak_stress, last.stress_ratio),
        _ => StoredRun::open(dir)
            .ok()
            .and_then(|run| run.steps.last().and_then(|&k| run.read_step(k).ok()))
            .map(|step| peak_stress(&step, world))
            .unwrap_or_default(),
    };
    row.peak_stress = peak.map(|p| format!("{p:e}")).unwrap_or_default();
    row.stress_ratio = ratio.map(|r| format!("{r:e}")).unwrap_or_default();
    row
}
