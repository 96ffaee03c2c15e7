//! The large-set mode of the condensed friction Newton (approximate factor, slip-following rows, Anderson mixing, early letting go), driven through the solver on a small sheared pair by lowering this thread's threshold.

use crate::contact::condensed::jacobian::{check_couplings, set_approximate_from, take_carried};
use crate::contact::condensed::solver::{take_record, Recorded};
use crate::scene::{build_world, Simulation, StepResult, StepSummary};
use std::path::Path;

/// The sheared pair of `tests/friction.rs` (`tests/common/sheared_pair.toml`) with 8 cells per edge instead of 4 (μ = 0.3,
/// 500 N pressing, the upper box sheared 0.1 mm per step from step 2; 135-158 contacts). With
/// 4 cells the large-set mode does not converge on the condensed path (step 1 leaves it, the
/// approximate factor's corrections cycling between residuals of about 0.56 and 0.89, the
/// same with mixing and early letting-go switched off): the approximate factor is made for
/// fine interfaces (it is used from 2,000 rows), not for coarse ones.
fn sheared_pair() -> String {
    include_str!("../../../tests/common/sheared_pair.toml")
        .replace("cells = [4, 4, 4]", "cells = [8, 8, 8]")
}

/// Every step of the sheared pair with the large-set mode from `from` rows on this thread,
/// and the condensed Newton's iterations recorded meanwhile.
fn run(from: usize) -> (Vec<(StepResult, StepSummary)>, Vec<Recorded>) {
    set_approximate_from(from);
    take_record();
    let world =
        build_world(&sheared_pair(), Path::new("sheared_pair.toml")).expect("a valid scene");
    let mut sim = Simulation::new(&world).expect("builds");
    let mut steps = Vec::new();
    for k in 0..=world.steps {
        let (result, summary) = sim.step(k).expect("solves");
        assert!(
            sim.contact().is_some_and(|c| c.is_condensed()),
            "from {from} rows: step {k} left the condensed path"
        );
        assert_eq!(summary.cuts, 0, "from {from} rows: step {k} was cut");
        steps.push((result, summary));
    }
    let record = take_record();
    set_approximate_from(super::jacobian::APPROXIMATE_FROM);
    (steps, record)
}

#[test]
fn the_large_set_mode_converges_to_the_exact_paths_answer_on_the_sheared_pair() {
    take_carried();
    let (exact, exact_record) = run(super::jacobian::APPROXIMATE_FROM);
    assert!(
        exact_record.iter().all(|r| !r.approximate),
        "below the threshold every Jacobian is exact"
    );
    assert_eq!(
        take_carried(),
        0,
        "below the threshold a Jacobian is never kept across contact sets"
    );
    // From one row: every Jacobian with more than a quarter of its rows slipping is the
    // approximate factor, and Jacobians are kept across contact sets (the rows of contacts
    // that come bordered in, those of contacts that go through the Schur complement).
    let (large, record) = run(1);
    let carried = take_carried();
    println!("contact sets taken into a kept Jacobian: {carried}");
    assert!(
        carried > 0,
        "the contact set never changed on a kept Jacobian"
    );
    let approximate: Vec<&Recorded> = record.iter().filter(|r| r.approximate).collect();
    assert!(
        approximate.len() >= 5,
        "the large-set mode was not used: {} approximate iterations",
        approximate.len()
    );
    assert!(
        approximate.iter().any(|r| r.mixed),
        "no Anderson-mixed step was taken"
    );
    // The residual sequences of the approximate iterations (relative), for the record.
    let sequence: Vec<String> = approximate
        .iter()
        .map(|r| format!("{:.1e}{}", r.relative, if r.mixed { "*" } else { "" }))
        .collect();
    println!("large-set mode, relative residual at each iteration (* mixed):");
    println!("{}", sequence.join(" "));
    for ((_, a), (_, b)) in exact.iter().zip(&large) {
        let k = a.step;
        assert!(b.residual <= 1e-9, "step {k}: residual {}", b.residual);
        let load = 500.0 * a.load_factor;
        if load == 0.0 {
            continue;
        }
        // The bodies' total contact forces agree to 1e-6 of the load.
        for (pa, pb) in a.contact_forces.iter().zip(&b.contact_forces) {
            for (x, y) in pa.force.iter().zip(&pb.force) {
                assert!(
                    (x - y).abs() <= 1e-6 * load,
                    "step {k}: {:?} against the exact path's {:?}",
                    pb.force,
                    pa.force
                );
            }
        }
        println!(
            "step {k}: exact path {} Newton ({} sticking, {} slipping), large-set mode {} ({}, {})",
            a.iterations, a.sticking, a.slipping, b.iterations, b.sticking, b.slipping
        );
    }
    // Contact by contact: the same contacts, each force within 1e-6 of the load.
    let mut largest: f64 = 0.0;
    for ((ra, sa), (rb, _)) in exact.iter().zip(&large) {
        let load = 500.0 * sa.load_factor;
        for (ba, bb) in ra.bodies.iter().zip(&rb.bodies) {
            assert_eq!(
                ba.contacts.len(),
                bb.contacts.len(),
                "step {}: body {}",
                sa.step,
                ba.name
            );
            for (ca, cb) in ba.contacts.iter().zip(&bb.contacts) {
                assert_eq!(ca.node, cb.node);
                for (x, y) in ca.force.iter().zip(&cb.force) {
                    if load > 0.0 {
                        largest = largest.max((x - y).abs() / load);
                    }
                    assert!(
                        (x - y).abs() <= 1e-6 * load,
                        "step {}: node {} of {}: {:?} against {:?}",
                        sa.step,
                        ca.node,
                        ba.name,
                        cb.force,
                        ca.force
                    );
                }
            }
        }
    }
    println!(
        "largest difference of a contact force from the exact path's: {largest:.1e} of the load"
    );
}

#[test]
fn g_c_gt_from_cartesian_node_blocks_equals_the_row_by_row_one_on_the_sheared_pair() {
    // Every `G C Gᵀ` of the sheared pair, formed from the contacts' Cartesian blocks, against
    // the sums row by row: the fresh factors of the exact path (the lower triangle), then
    // with the large-set mode from one row, the borders of kept Jacobians (whole blocks).
    for from in [super::jacobian::APPROXIMATE_FROM, 1] {
        check_couplings(true);
        run(from);
        let (worst, cartesian, two, whole) = check_couplings(false).expect("checked");
        println!(
            "from {from} rows: largest relative difference {worst:.1e}; {cartesian} contacts \
             as Cartesian rows, {two} of them touching two bodies; {whole} borders"
        );
        assert!(worst <= 1e-13, "from {from} rows: {worst:.1e}");
        assert!(
            cartesian > 0 && two > 0,
            "from {from} rows: no Cartesian contact"
        );
        if from == 1 {
            assert!(whole > 0, "no border was formed");
        }
    }
}
