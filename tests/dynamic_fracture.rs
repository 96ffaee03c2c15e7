//! Fracture in time (issue 31 item 5) against closed forms: a pulled bar breaks at the time
//! the trapezoidal rule's exact rotation gives, not at all when its peak stress is below the
//! strength, symmetric members break in one event, the pieces keep their momentum and the
//! energy balance holds through the break; and the same through a scene file.

use linkage::linkage::dynamics::{
    kinetic_energy, lumped_mass, momentum, strain_energy, BodyMotion, EnergyMomentum, Integrator,
    Newmark, RayleighDamping,
};
use linkage::linkage::{
    Body, Dimension, Failure, Kinematics, Material, Member, NodalLoad, Schedule, Support,
};
use linkage::scene::{solve_time_step, BreakingBodies, TimedBreak};
use nalgebra::Vector3;
use std::process::Command;

/// E = 1e6 Pa, A = 1e-2 m², L = 1 m per member (k = 1e4 N/m), ρ = 2000 kg/m³: an end node
/// carries 10 kg. Breaks in tension at `strength` Pa.
fn chain(members: usize, strength: f64, kinematics: Kinematics) -> (Body, Vec<f64>) {
    let mut body = Body::new("bar", Dimension::Two);
    let mut material = Material::new("glass", 1e6, 1e-2);
    material.failure = Failure::Break;
    material.tensile_strength = Some(strength);
    body.materials.push(material);
    body.nodes = (0..=members)
        .map(|i| Vector3::new(i as f64, 0.0, 0.0))
        .collect();
    for i in 0..members {
        body.members.push(Member {
            nodes: [i, i + 1],
            material: 0,
        });
    }
    body.kinematics = kinematics;
    let mass = lumped_mass(&body, &[Some(2000.0)]).unwrap();
    (body, mass)
}

/// Run `steps` steps of `h` from the end nodes moving apart at ±1 m/s; per step the state
/// after it (velocities, displacements) and every break.
struct Run {
    breaks: Vec<TimedBreak>,
    motion: BodyMotion,
    body: Body,
    dissipated: f64,
    work: f64,
}

fn pull(
    members: usize,
    strength: f64,
    kinematics: Kinematics,
    integrator: &dyn Integrator,
    h: f64,
    steps: usize,
) -> Run {
    let (body, mass) = chain(members, strength, kinematics);
    let mut v = vec![0.0; body.dof_count()];
    v[0] = -1.0;
    v[2 * members] = 1.0;
    let mut motions = vec![BodyMotion::new(&body, mass, v, RayleighDamping::default()).unwrap()];
    if integrator.needs_initial_acceleration() {
        motions[0].balance_initial_acceleration(&body, 1.0);
    }
    let mut breaking = BreakingBodies::new(std::slice::from_ref(&body))
        .unwrap()
        .unwrap();
    let (mut dissipated, mut work) = (0.0, 0.0);
    let mut breaks = Vec::new();
    for k in 0..steps {
        let reports = breaking
            .solve_step(
                &mut motions,
                &mut |m, b, t, h| solve_time_step(m, b, integrator, (t, h, 1.0)),
                (k as f64 * h, h, 1.0),
                integrator.needs_initial_acceleration(),
            )
            .unwrap();
        dissipated += reports[0].dissipated;
        work += reports[0].external_work;
        breaks.extend(breaking.take_breaks().remove(0));
    }
    Run {
        breaks,
        motion: motions.remove(0),
        body: breaking.bodies.remove(0),
        dissipated,
        work,
    }
}

/// ω of the two-mass bar's stretching: k over the reduced mass 5 kg.
const OMEGA: f64 = 44.721_359_549_995_796; // √2000

/// The break time of the two-mass bar under the trapezoidal rule: in (ω e/2, v_rel/2) a step
/// of h is the rotation by φ = 2 atan(ωh/2) exactly, so the stress E·e/L = E·(2v/ω)·sin(angle)
/// reaches `strength` at angle `α = asin(strength ω / (2 v E))`: after n = ⌊α/φ⌋ whole steps
/// and a cut step of `(2/ω) tan((α − nφ)/2)`.
fn trapezoidal_break_time(strength: f64, h: f64) -> f64 {
    let alpha = (strength * OMEGA / (2.0 * 1e6)).asin();
    let phi = 2.0 * (OMEGA * h / 2.0).atan();
    let n = (alpha / phi).floor();
    n * h + 2.0 / OMEGA * ((alpha - n * phi) / 2.0).tan()
}

/// A bar of two 10 kg masses pulled apart at ±1 m/s (peak stress E·2v/ω = 44,721 Pa) with
/// strength 30,000 Pa breaks once, at the time the trapezoidal rotation gives (to 1e-9 s; the
/// search stops at the strength to 1e-8), within (ωh)²/12 of the continuum's asin(f/σ_max)/ω;
/// linear and large kinematics alike (the bar stays on its axis). After the break both pieces
/// coast at ±v cos α (1e-7 m/s), momentum stays 0 (1e-12), the released strain energy is
/// ½ k (f L/E)² = 4.5 J (1e-7 J) and kinetic energy + released is the initial 10 J (1e-9 J):
/// energy-momentum.
#[test]
fn a_pulled_bar_breaks_at_the_trapezoidal_event_time() {
    let h = 1e-3;
    let expected = trapezoidal_break_time(30_000.0, h);
    let continuum = (30_000.0 * OMEGA / 2e6).asin() / OMEGA;
    assert!((expected - continuum).abs() < continuum * (OMEGA * h).powi(2) / 12.0);
    for kinematics in [Kinematics::Linear, Kinematics::Large] {
        let run = pull(1, 30_000.0, kinematics, &EnergyMomentum, h, 40);
        assert_eq!(run.breaks.len(), 1, "{kinematics:?}: {:?}", run.breaks);
        assert_eq!(run.breaks[0].member, 0);
        let t = run.breaks[0].time;
        eprintln!(
            "{kinematics:?}: broke at {t} s, trapezoidal {expected} s (off {:.2e}), continuum {continuum} s; released {} J",
            t - expected,
            run.dissipated
        );
        assert!(
            (t - expected).abs() < 1e-9,
            "{kinematics:?}: broke at {t} s, expected {expected} s"
        );
        assert_eq!(run.body.modulus_factor(0), 0.0);
        let cos = (1.0 - (30_000.0 * OMEGA / 2e6).powi(2)).sqrt();
        let v = &run.motion.motion.v;
        assert!(
            (v[0] + cos).abs() < 1e-7 && (v[2] - cos).abs() < 1e-7,
            "{v:?}"
        );
        let p = momentum(&run.body, &run.motion.mass, v);
        assert!(p.iter().all(|p| p.abs() < 1e-12), "{p:?}");
        let ke = kinetic_energy(&run.motion.mass, v);
        assert!(strain_energy(&run.body, &run.motion.motion.u) == 0.0);
        assert!(
            (ke + run.dissipated - 10.0).abs() < 1e-9 && run.work == 0.0,
            "{ke} + {} against 10 J",
            run.dissipated
        );
        // The released energy is the member's ½ k e² at the break: ½ k (f L/E)².
        assert!((run.dissipated - 0.5 * 1e4 * 0.03f64.powi(2)).abs() < 1e-7);
    }
}

/// Strength just above the peak stress (44,721 Pa): nothing breaks over three periods
/// (0.42 s); just below: it breaks. Energy-momentum and Newmark ¼, ½ (the same trapezoidal
/// rule on this linear bar).
#[test]
fn a_bar_below_its_strength_does_not_break() {
    let peak = 2.0 * 1e6 / OMEGA;
    for integrator in [
        &EnergyMomentum as &dyn Integrator,
        &Newmark {
            beta: 0.25,
            gamma: 0.5,
        },
    ] {
        let run = pull(1, peak * 1.001, Kinematics::Linear, integrator, 1e-3, 420);
        assert!(run.breaks.is_empty(), "{:?}", run.breaks);
        let run = pull(1, peak * 0.999, Kinematics::Linear, integrator, 1e-3, 420);
        assert_eq!(run.breaks.len(), 1, "{}", integrator.name());
    }
}

/// Three members, the end nodes pulled apart at ±1 m/s: the two end members stretch alike and
/// break in one event (the same time, exactly), the middle member is left; the pieces move
/// symmetrically (velocities opposite to 1e-12) and momentum stays 0 (1e-12); energy balances
/// to 1e-9 J (energy-momentum).
#[test]
fn symmetric_members_break_together() {
    let run = pull(3, 20_000.0, Kinematics::Large, &EnergyMomentum, 1e-3, 100);
    assert!(run.breaks.len() >= 2, "{:?}", run.breaks);
    let (a, b) = (run.breaks[0], run.breaks[1]);
    assert_eq!(
        (a.member.min(b.member), a.member.max(b.member)),
        (0, 2),
        "{:?}",
        run.breaks
    );
    assert_eq!(a.time, b.time);
    eprintln!("members 1 and 3 broke together at {} s", a.time);
    let v = &run.motion.motion.v;
    for i in 0..2 {
        assert!((v[2 * i] + v[2 * (3 - i)]).abs() < 1e-12, "{v:?}");
    }
    let p = momentum(&run.body, &run.motion.mass, v);
    assert!(p.iter().all(|p| p.abs() < 1e-12), "{p:?}");
    let e = kinetic_energy(&run.motion.mass, v)
        + strain_energy(&run.body, &run.motion.motion.u)
        + run.dissipated;
    assert!((e - 10.0).abs() < 1e-9, "{e}");
}

/// A 10 kg mass hanging 1 m below a support on one member (k = 1e4 N/m, ω = √1000 rad/s),
/// its weight W = 98.1 N applied in full from t = 0: the stretch swings about e_s = W/k as
/// e_s (1 − cos ωt) (trapezoidal: the angle grows by 2 atan(ωh/2) per step), its stress to
/// twice the static 9,810 Pa, so with strength 15,000 Pa it breaks at 1 − cos α = 15000/9810.
/// Then the mass falls freely: at t = 0.2 s its velocity is −ω e_s sin α − 9.81 (0.2 − t_b)
/// (1e-7 m/s): nothing removed it from the solve, its load goes on acting. Energy-momentum, and
/// Newmark ¼, ½ (whose acceleration is rebalanced on the broken body: without it the free
/// fall would carry the member's last pull).
#[test]
fn a_mass_that_breaks_off_keeps_falling() {
    let h = 1e-3;
    let omega = 1000f64.sqrt();
    let e_s = 98.1 / 1e4;
    let alpha = (1.0f64 - 15_000.0 / 9_810.0).acos();
    let phi = 2.0 * (omega * h / 2.0).atan();
    let n = (alpha / phi).floor();
    let expected = n * h + 2.0 / omega * ((alpha - n * phi) / 2.0).tan();
    for integrator in [
        &EnergyMomentum as &dyn Integrator,
        &Newmark {
            beta: 0.25,
            gamma: 0.5,
        },
    ] {
        let mut body = Body::new("hanging", Dimension::Two);
        let mut material = Material::new("glass", 1e6, 1e-2);
        material.failure = Failure::Break;
        material.tensile_strength = Some(15_000.0);
        body.materials.push(material);
        body.nodes = vec![Vector3::zeros(), Vector3::new(0.0, -1.0, 0.0)];
        body.members.push(Member {
            nodes: [0, 1],
            material: 0,
        });
        body.supports.push(Support::fixed(0, [true, true, false]));
        body.loads.push(NodalLoad {
            node: 1,
            force: Vector3::new(0.0, -98.1, 0.0),
            schedule: Schedule::Factors(vec![1.0]),
        });
        let mass = lumped_mass(&body, &[Some(2000.0)]).unwrap();
        let mut motions =
            vec![BodyMotion::new(&body, mass, vec![0.0; 4], RayleighDamping::default()).unwrap()];
        if integrator.needs_initial_acceleration() {
            motions[0].balance_initial_acceleration(&body, 1.0);
        }
        let mut breaking = BreakingBodies::new(std::slice::from_ref(&body))
            .unwrap()
            .unwrap();
        let mut breaks = Vec::new();
        for k in 0..200 {
            breaking
                .solve_step(
                    &mut motions,
                    &mut |m, b, t, h| solve_time_step(m, b, integrator, (t, h, 1.0)),
                    (k as f64 * h, h, 1.0),
                    integrator.needs_initial_acceleration(),
                )
                .unwrap();
            breaks.extend(breaking.take_breaks().remove(0));
        }
        assert_eq!(breaks.len(), 1, "{breaks:?}");
        let t = breaks[0].time;
        let v = motions[0].motion.v[3];
        let falling = -omega * e_s * alpha.sin() - 9.81 * (0.2 - t);
        eprintln!(
            "{}: broke at {t} s (closed form {expected}, off {:.2e}); v at 0.2 s {v} m/s (closed form {falling}, off {:.2e})",
            integrator.name(),
            t - expected,
            v - falling
        );
        assert!((t - expected).abs() < 1e-9, "{t} against {expected}");
        assert!((v - falling).abs() < 1e-7, "{v} against {falling}");
        assert!(motions[0].motion.v[2].abs() < 1e-12);
    }
}

const SCENE: &str = r#"name = "pulled"

[dynamics]
duration = 0.04
time_step = 1e-3
frames = 4
integrator = "INTEGRATOR"

[[materials]]
name = "glass"
youngs_modulus = 1e6
area = 1e-2
density = 2000.0
strength = 30000.0
failure = "break"

[[bodies]]
name = "bar"
nodes = "bar.nodes"
links = "bar.links"
material = "glass"

[[bodies.velocities]]
nodes = [1]
velocity = [-1.0, 0.0]

[[bodies.velocities]]
nodes = [2]
velocity = [1.0, 0.0]
"#;

/// The two-mass bar as a scene: the summary lists the break of member 1 with its time (as the
/// library test, 1e-9 s) and load factor, the frame after it lists member 1 broken, and the
/// total energy (fracture in `dissipated`) stays at its start to 1e-9 J in every frame.
#[test]
fn a_scene_reports_its_breaks_in_time() {
    for integrator in ["energy_momentum", "newmark"] {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::write(d.join("bar.nodes"), "0 0\n1 0\n").unwrap();
        std::fs::write(d.join("bar.links"), "1 2\n").unwrap();
        std::fs::write(d.join("s.toml"), SCENE.replace("INTEGRATOR", integrator)).unwrap();
        let o = Command::new(env!("CARGO_BIN_EXE_linkage"))
            .arg("run")
            .arg(d.join("s.toml"))
            .arg("--out")
            .arg(d.join("out"))
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
        let folder = d.join("out/pulled");
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(folder.join("summary.json")).unwrap())
                .unwrap();
        let breaks = summary["breaks"].as_array().unwrap();
        assert_eq!(breaks.len(), 1, "{breaks:?}");
        assert_eq!(breaks[0]["member"], 1);
        let t = breaks[0]["time"].as_f64().unwrap();
        let expected = trapezoidal_break_time(30_000.0, 1e-3);
        assert!(
            (t - expected).abs() < 1e-9,
            "{integrator}: {t} against {expected}"
        );
        assert_eq!(breaks[0]["step"], 2, "{breaks:?}");
        let steps = summary["steps"].as_array().unwrap();
        let e0 = steps[0]["total_energy"].as_f64().unwrap();
        let drift = steps
            .iter()
            .map(|s| (s["total_energy"].as_f64().unwrap() - e0).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "{integrator}: break at {t} s (off {:.2e}), energy drift {drift:.2e} J",
            t - expected
        );
        for s in steps {
            let e = s["total_energy"].as_f64().unwrap();
            assert!((e - e0).abs() < 1e-9, "{integrator}: {e} against {e0}");
        }
        let last: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(folder.join("steps/0004.json")).unwrap())
                .unwrap();
        assert_eq!(last["bodies"][0]["broken"], serde_json::json!([1]));
    }
}
