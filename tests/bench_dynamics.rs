//! `linkage bench --dynamics` (docs/PERFORMANCE.md, "Dynamics") at its CI size: the dropped
//! lattice measured in this process, and the whole subcommand, OpenSees included. No timing is
//! asserted.

mod common;

use linkage::bench::dynamics::{
    format_summary, measure_dynamics, QUICK_CELLS, QUICK_STEPS, STEPS_BEFORE_CONTACT,
};
use linkage::bench::opensees::{compare, format_comparison, QUICK_CELLS as CANTILEVER, QUICK_RUN};

/// The quick lattice falls free for its first steps, then stays on the floor, no node deeper
/// than 1 % of the mean member length (the limit past which a time step is halved). The
/// energy balance (kinetic + strain + penalty − work of gravity) starts at ½ m v² and changes
/// only when nodes come into contact within a step, by at most ½ k (v h)² per node arriving
/// (`src/contact/time_step.rs`, "Energy under the midpoint rule").
#[test]
fn the_quick_drop_falls_free_then_touches_the_floor() {
    let t = measure_dynamics(QUICK_CELLS, QUICK_STEPS).unwrap();
    assert_eq!(t.sizes, [216, 1940, 648]);
    assert_eq!(t.steps.len(), QUICK_STEPS);
    // 540 edges, 900 face and 500 body diagonals of 1 cm cells, m.
    let length = 0.01 * (540.0 + 900.0 * 2f64.sqrt() + 500.0 * 3f64.sqrt());
    let kinetic = 0.5 * 1000.0 * 1e-6 * length;
    let mean_member = length / 1940.0;
    // Penalty 1e4 N/m, h = 0.1 ms, arriving at 1 m/s plus what gravity adds (< 1 %).
    let per_node = 0.5 * 1e4 * (1.01 * 1e-4f64).powi(2);
    let mut before = kinetic;
    for (k, s) in t.steps.iter().enumerate() {
        assert_eq!(
            s.contacts > 0,
            k >= STEPS_BEFORE_CONTACT,
            "step {}: {s:?}",
            k + 1
        );
        assert!(
            s.max_penetration < 0.01 * mean_member,
            "step {}: {s:?}",
            k + 1
        );
        let change = (s.total_energy - before).abs();
        if k < STEPS_BEFORE_CONTACT {
            assert!(change < 1e-8 * kinetic, "step {}: {change:e} J", k + 1);
        } else {
            assert!(
                change <= s.contacts as f64 * per_node,
                "step {}: {change:e} J",
                k + 1
            );
        }
        before = s.total_energy;
    }
    assert!(format_summary(&t).contains("1940 members, 648 DOFs"));
}

/// The cantilever is timed without OpenSees when there is no Python for it.
#[test]
fn the_quick_cantilever_is_timed_without_opensees() {
    let dir = tempfile::tempdir().unwrap();
    let c = compare(CANTILEVER, QUICK_RUN, None, dir.path()).unwrap();
    assert_eq!(c.sizes, [51, 44]);
    assert!(c.theirs.is_none() && c.ours > 0.0);
    // The tip swings about a quarter of the span down and back in 400 steps of 0.2 ms.
    assert!(c.peak > 0.2, "{}", c.peak);
    assert!(format_comparison(&c).contains("OpenSees not run"));
}

/// `linkage bench --dynamics --quick` runs both benchmarks at their CI size (no timing is
/// asserted): the dropped lattice's steps, phases and summary, then the cantilever against
/// OpenSees, agreeing.
#[test]
fn the_dynamics_benchmark_runs_in_its_quick_size() {
    let python = common::python_with_openseespy().unwrap_or_else(|e| panic!("{e}"));
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_linkage"))
        .args(["bench", "--dynamics", "--quick", "--python"])
        .arg(&python)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for expected in [
        "step   8 ",
        "5x5x5 cells: 216 nodes, 1940 members, 648 DOFs",
        "steps per second",
        "contact detection",
        "factorization",
        "Newton iterations per step",
        "10x1 cells: 51 members, 44 DOFs, 400 steps",
        "agree to 1e-6",
    ] {
        assert!(text.contains(expected), "no {expected:?} in:\n{text}");
    }
}
