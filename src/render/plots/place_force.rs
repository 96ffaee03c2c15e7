//! The load–displacement curve at a place the scene names (`[output] plot = { support =
//! "NAME" }` or `plot = { body = .., nodes = [..] }`): the force there against its
//! displacement, so a peak and a softening branch show.

use crate::render::plots::reaction::CANCELLED;
use crate::render::plots::{Chart, Series};
use crate::scene::{PlotPlace, RunResults};

/// The force and displacement of `place` at each stored step of `run`, along the unit
/// direction e: (step, displacement, force) with displacement = the mean over the place's
/// nodes of u·e (m) and force = F·e (N), F the sum over its nodes of the support reactions
/// and the applied loads. e is the support's prescribed displacement direction, else the axis
/// of the largest force component over the run; its sign makes the force of largest
/// magnitude positive. `None` when the place's body is not in the results or the force is
/// round-off at every step ([`CANCELLED`]: reactions that cancel draw no curve).
pub fn place_points(run: &RunResults, place: &PlotPlace) -> Option<Vec<(usize, f64, f64)>> {
    let mut totals: Vec<(usize, [f64; 3], f64, [f64; 3])> = Vec::new();
    for step in &run.steps {
        let body = step
            .bodies
            .get(place.body_index)
            .filter(|b| b.name == place.body)
            .or_else(|| step.bodies.iter().find(|b| b.name == place.body))?;
        let mut force = [0.0; 3];
        let mut magnitude = 0.0;
        for f in body.reactions.iter().chain(&body.loads) {
            if place.nodes.contains(&f.node.wrapping_sub(1)) {
                for (k, c) in f.force.iter().enumerate().take(3) {
                    force[k] += c;
                    magnitude += c.abs();
                }
            }
        }
        let mut u = [0.0; 3];
        for &n in &place.nodes {
            if let Some(d) = body.displacements.get(n) {
                for (k, c) in d.iter().enumerate().take(3) {
                    u[k] += c / place.nodes.len() as f64;
                }
            }
        }
        totals.push((step.step, force, magnitude, u));
    }
    let real = totals.iter().any(|(_, f, m, _)| {
        let size = f.iter().map(|x| x.abs()).sum::<f64>();
        size > CANCELLED * m
    });
    if !real {
        return None;
    }
    let mut e = place.direction.unwrap_or_else(|| {
        let k = (0..3)
            .max_by(|&a, &b| {
                let peak = |k: usize| totals.iter().map(|t| t.1[k].abs()).fold(0.0, f64::max);
                peak(a).total_cmp(&peak(b))
            })
            .unwrap_or(0);
        let mut e = [0.0; 3];
        e[k] = 1.0;
        e
    });
    let along = |v: &[f64; 3], e: &[f64; 3]| (0..3).map(|k| v[k] * e[k]).sum::<f64>();
    let extreme = totals
        .iter()
        .map(|t| along(&t.1, &e))
        .max_by(|a, b| a.abs().total_cmp(&b.abs()))
        .unwrap_or(0.0);
    let force_sign = if extreme < 0.0 { -1.0 } else { 1.0 };
    if place.direction.is_none() {
        e = e.map(|x| x * force_sign);
    }
    // A support's direction is its pull: the displacement along it stays positive, the
    // force is signed so that its peak is positive.
    let sign = if place.direction.is_some() {
        force_sign
    } else {
        1.0
    };
    Some(
        totals
            .iter()
            .map(|(step, f, _, u)| (*step, along(u, &e), sign * along(f, &e)))
            .collect(),
    )
}

/// The chart `load_displacement` of `place` ([`place_points`]): one point per stored step.
pub fn place_force(scene: &str, run: &RunResults, place: &PlotPlace) -> Option<Chart> {
    let points = place_points(run, place)?;
    let mut series = Series::new(place.label.clone());
    for (step, u, f) in points {
        series.push(u, f, format!("step {step}"));
    }
    Some(Chart {
        name: "load_displacement".into(),
        title: format!("{scene}: force at {} against its displacement", place.label),
        x_label: format!("displacement of {} (m)", place.label),
        y_label: format!("force at {} (N)", place.label),
        columns: ("displacement_m".into(), "force_N".into()),
        log_y: false,
        legend: true,
        one_colour: false,
        integer: (false, false),
        series: vec![series],
    })
}
