//! Our Newmark against OpenSees on the same truss (`linkage::bench::opensees`): a 2D lattice
//! cantilever (10 × 1 cells, both diagonals) with the lumped masses ρAL/2, suddenly loaded at
//! its tip, large displacements. OpenSees (openseespy, from a venv under `target/`, see
//! [`common::python_with_openseespy`]) runs `corotTruss` elements with the same nodal masses,
//! `integrator('Newmark', 0.5, 0.25)`, `algorithm('Newton')`, `test('NormDispIncr', 1e-12, 50)`.
//!
//! The load (tip deflection about a quarter of the span, the chord shortening 2 % of it) is
//! where the strain measure matters: the same run with linear kinematics is off by far more
//! than the tolerance. The time per step of both on a larger cantilever is a benchmark:
//! `linkage bench --dynamics` (docs/PERFORMANCE.md, "Dynamics").

mod common;

use linkage::bench::opensees::{
    cantilever, difference, opensees, ours, peak, AGREEMENT, QUICK_CELLS, QUICK_RUN,
};
use linkage::linkage::Kinematics;

/// 400 steps of 0.2 ms (about 1.5 periods of the first mode, the tip swinging down 0.27 m and
/// back): ours and OpenSees agree to 1e-6 of the largest tip displacement at every step, and
/// the same run with linear kinematics differs from OpenSees by more than 1 %.
#[test]
fn newmark_cantilever_agrees_with_opensees_corot_truss() {
    let python = common::python_with_openseespy().unwrap_or_else(|e| panic!("{e}"));
    let dir = tempfile::tempdir().unwrap();
    let (body, mass, tip) = cantilever(QUICK_CELLS, Kinematics::Large).unwrap();
    let (theirs, their_time) = opensees(&python, dir.path(), &body, &mass, tip, QUICK_RUN).unwrap();
    let (mine, my_time) = ours(&body, &mass, tip, QUICK_RUN).unwrap();
    let peak = peak(&theirs);
    assert!(peak > 0.2, "the tip must move far: {peak} m");
    let large = difference(&mine, &theirs);
    let (linear_body, _, _) = cantilever(QUICK_CELLS, Kinematics::Linear).unwrap();
    let (linear, _) = ours(&linear_body, &mass, tip, QUICK_RUN).unwrap();
    let small = difference(&linear, &theirs);
    eprintln!(
        "OpenSees comparison: peak tip displacement {peak:.4} m; large kinematics differ by {large:.2e} of it, linear by {small:.2e}; {:.1} µs per step ours, {:.1} µs OpenSees",
        my_time * 1e6,
        their_time * 1e6
    );
    assert!(
        large < AGREEMENT,
        "ours differs from OpenSees by {large:e} of the peak"
    );
    assert!(
        small > 1e-2,
        "linear kinematics should not agree: {small:e}"
    );
}
