//! The energies of a dynamic scene against time: kinetic, strain, external work, dissipated
//! and their balance.

use crate::render::plots::{Chart, Series};
use crate::scene::Summary;

/// The chart `energies`: at every stored state of a dynamic scene (x its time, s) the kinetic
/// and strain energies, the external work and the energy dissipated since t = 0, and the
/// balance `total_energy = kinetic + strain − external_work + dissipated` (J), from
/// `summary.json`'s `dynamics`; `None` for a static scene.
pub fn energies(summary: &Summary) -> Option<Chart> {
    let states: Vec<_> = summary
        .steps
        .iter()
        .filter_map(|s| s.dynamics.as_ref().map(|d| (s.step, d)))
        .collect();
    if states.is_empty() {
        return None;
    }
    let series = ["kinetic", "strain", "external work", "dissipated", "total"]
        .iter()
        .enumerate()
        .map(|(k, name)| {
            let mut s = Series::new(*name);
            for (step, d) in &states {
                let value = [
                    d.kinetic_energy,
                    d.strain_energy,
                    d.external_work,
                    d.dissipated,
                    d.total_energy,
                ][k];
                s.push(d.time, value, format!("step {step}"));
            }
            s
        })
        .collect();
    Some(Chart {
        name: "energies".into(),
        title: format!("{}: energies against time", summary.scene),
        x_label: "time (s)".into(),
        y_label: "energy (J)".into(),
        columns: ("time_s".into(), "energy_J".into()),
        log_y: false,
        legend: true,
        one_colour: false,
        integer: (false, false),
        series,
    })
}

/// The chart `contact_force_time`: per pair (a body and what it touches) the magnitude of
/// the total contact force it receives (N, 0 where the pair does not touch) at every stored
/// state of a dynamic scene against its time (s); `None` for a static scene or when nothing
/// ever touches.
pub fn contact_force_time(summary: &Summary) -> Option<Chart> {
    let states: Vec<_> = summary
        .steps
        .iter()
        .filter_map(|s| s.dynamics.as_ref().map(|d| (s, d.time)))
        .collect();
    let mut pairs: Vec<(&str, &str)> = Vec::new();
    for p in states.iter().flat_map(|(s, _)| &s.contact_forces) {
        if !pairs.contains(&(p.body.as_str(), p.with.as_str())) {
            pairs.push((&p.body, &p.with));
        }
    }
    if pairs.is_empty() {
        return None;
    }
    let series = pairs
        .iter()
        .map(|&(body, with)| {
            let mut s = Series::new(format!("{body} from {with}"));
            for (step, time) in &states {
                let force = step
                    .contact_forces
                    .iter()
                    .find(|p| p.body == body && p.with == with)
                    .map_or(0.0, |p| p.force.iter().map(|f| f * f).sum::<f64>().sqrt());
                s.push(*time, force, format!("step {}", step.step));
            }
            s
        })
        .collect();
    Some(Chart {
        name: "contact_force_time".into(),
        title: format!(
            "{}: total contact force per pair against time",
            summary.scene
        ),
        x_label: "time (s)".into(),
        y_label: "contact force |F| (N)".into(),
        columns: ("time_s".into(), "contact_force_N".into()),
        log_y: false,
        legend: true,
        one_colour: false,
        integer: (false, false),
        series,
    })
}
