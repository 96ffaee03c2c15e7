//! Dynamics without contact against closed forms: the discrete period of the trapezoidal rule,
//! backward Euler's and generalized-α's damping per step, conservation by the energy–momentum
//! method, free fall; and every error of a dynamic scene with its line.

use linkage::linkage::dynamics::{
    angular_momentum, kinetic_energy, lumped_mass, momentum, strain_energy, BackwardEuler,
    BodyMotion, EnergyMomentum, GeneralizedAlpha, Integrator, Motion, Newmark, RayleighDamping,
};
use linkage::linkage::generators::box_lattice;
use linkage::linkage::{Body, Dimension, Kinematics, Material, Member, Support};
use nalgebra::{Matrix3, Vector3};
use std::path::Path;
use std::process::{Command, Output};

/// A 2D bar 1 m along x, EA = 1e4 N (k = 1e4 N/m), ρ = 2000 kg/m³, A = 1e-2 m²: node 2
/// carries m = ρAL/2 = 10 kg and moves along x only; ω = √(k/m) = √1000 rad/s.
fn oscillator() -> (Body, Vec<f64>) {
    let mut body = Body::new("spring", Dimension::Two);
    body.materials.push(Material::new("m", 1e6, 1e-2));
    body.nodes = vec![Vector3::zeros(), Vector3::new(1.0, 0.0, 0.0)];
    body.members.push(Member {
        nodes: [0, 1],
        material: 0,
    });
    body.supports.push(Support::fixed(0, [true, true, false]));
    body.supports.push(Support::fixed(1, [false, true, false]));
    let mass = lumped_mass(&body, &[Some(2000.0)]).unwrap();
    assert!((mass[2] - 10.0).abs() < 1e-12);
    (body, mass)
}

const OMEGA2: f64 = 1000.0;

/// The oscillator's node-2 displacement after each of `steps` steps of `h` from u = 0,
/// v = 1 m/s (and the velocities).
fn history(integrator: &dyn Integrator, h: f64, steps: usize) -> Vec<(f64, f64)> {
    let (body, mass) = oscillator();
    let mut m = BodyMotion::new(
        &body,
        mass,
        vec![0.0, 0.0, 1.0, 0.0],
        RayleighDamping::default(),
    )
    .unwrap();
    if integrator.needs_initial_acceleration() {
        m.balance_initial_acceleration(&body, 1.0);
    }
    let mut out = vec![(0.0, 1.0)];
    for k in 0..steps {
        m.step(&body, integrator, k as f64 * h, h, 1.0).unwrap();
        out.push((m.motion.u[2], m.motion.v[2]));
    }
    out
}

/// Trapezoidal rule on a linear oscillator: `u_{n+1} + u_{n−1} = 2 cos θ u_n` with
/// `θ = 2 atan(ωh/2)`, so the discrete period is `2πh/θ = T (ωh/2)/atan(ωh/2)`. Measured from
/// the recurrence at every step where |u_n| is not small, for energy–momentum and Newmark ¼, ½,
/// to 1e-8 of the period; the energy ½mv² + ½ku² is kept to 1e-12.
#[test]
fn one_member_oscillator_has_the_trapezoidal_period() {
    let omega = OMEGA2.sqrt();
    let h = 0.5 / omega;
    let period = 2.0 * std::f64::consts::PI / omega;
    let expected = period * (omega * h / 2.0) / (omega * h / 2.0).atan();
    for integrator in [
        &EnergyMomentum as &dyn Integrator,
        &Newmark {
            beta: 0.25,
            gamma: 0.5,
        },
    ] {
        let u = history(integrator, h, 200);
        let amplitude = u.iter().map(|x| x.0.abs()).fold(0.0, f64::max);
        let mut checked = 0;
        for n in 1..u.len() - 1 {
            if u[n].0.abs() < 0.3 * amplitude {
                continue;
            }
            let cos = (u[n + 1].0 + u[n - 1].0) / (2.0 * u[n].0);
            let measured = 2.0 * std::f64::consts::PI * h / cos.acos();
            assert!(
                ((measured - expected) / expected).abs() < 1e-8,
                "{}: step {n}: period {measured} against {expected}",
                integrator.name()
            );
            checked += 1;
        }
        assert!(checked > 100);
        let energy = |(x, v): (f64, f64)| 0.5 * 10.0 * v * v + 0.5 * 1e4 * x * x;
        for s in &u {
            assert!(
                (energy(*s) - 5.0).abs() < 1e-12 * 5.0,
                "{}",
                integrator.name()
            );
        }
        // Longer than the exact period T (the rule lags).
        assert!(expected > period);
    }
}

/// Backward Euler: with `z = ω u + i v`, one step is `z_{n+1} = z_n / (1 + iωh)`, so
/// `|z|` falls by exactly `1/√(1 + ω²h²)` per step: to 1e-10, at ωh = 0.5 and 2.
#[test]
fn backward_euler_damps_the_amplitude_by_its_closed_form_per_step() {
    let omega = OMEGA2.sqrt();
    for wh in [0.5, 2.0] {
        let h = wh / omega;
        let u = history(&BackwardEuler, h, 40);
        let norm = |(x, v): (f64, f64)| (omega * omega * x * x + v * v).sqrt();
        let ratio = 1.0 / (1.0 + wh * wh).sqrt();
        for n in 0..u.len() - 1 {
            let r = norm(u[n + 1]) / norm(u[n]);
            assert!(
                (r - ratio).abs() < 1e-10,
                "ωh = {wh}, step {n}: {r} against {ratio}"
            );
        }
    }
}

/// Generalized-α: the spectral radius of the one-step map of (u, v, a) of a mode with
/// ωh = 1e4 (a stiff mode) is ρ∞ within 0.005, and 50 steps shrink its state by about ρ∞⁵⁰.
#[test]
fn generalized_alpha_damps_a_stiff_mode_by_rho_inf_per_step() {
    let (body, mass) = oscillator();
    let omega = OMEGA2.sqrt();
    let h = 1e4 / omega;
    for rho_inf in [0.0, 0.5, 0.8, 1.0] {
        let g = GeneralizedAlpha { rho_inf };
        let mut columns = Matrix3::zeros();
        for j in 0..3 {
            let mut m = BodyMotion::new(
                &body,
                mass.clone(),
                vec![0.0; 4],
                RayleighDamping::default(),
            )
            .unwrap();
            let mut start = [0.0; 3];
            // Scaled so the three columns are of one size: u, v/ω, a/ω².
            start[j] = 1.0;
            m.motion = Motion {
                u: vec![0.0, 0.0, start[0], 0.0],
                v: vec![0.0, 0.0, start[1] * omega, 0.0],
                a: vec![0.0, 0.0, start[2] * OMEGA2, 0.0],
            };
            m.step(&body, &g, 0.0, h, 1.0).unwrap();
            columns[(0, j)] = m.motion.u[2];
            columns[(1, j)] = m.motion.v[2] / omega;
            columns[(2, j)] = m.motion.a[2] / OMEGA2;
        }
        let radius = columns
            .complex_eigenvalues()
            .iter()
            .map(|z| z.norm())
            .fold(0.0, f64::max);
        assert!(
            (radius - rho_inf).abs() < 0.005,
            "ρ∞ = {rho_inf}: spectral radius {radius}"
        );
    }
}

/// A free 3D lattice (2×1×1 cells, large kinematics, no supports) spinning at 5 rad/s about
/// a tilted axis through its centre of mass and translating at 0.1 m/s: over 10,000
/// energy–momentum steps (h = 2 ms, 16 turns, the members ringing from the spin) the energy
/// stays within 1e-10 of its start, relative, and the linear and angular momenta within 1e-12
/// of their scales `Σ m|v|` and `Σ m|x||v|` (the issue's numbers; a momentum vector's own size
/// depends on the frame). Newton carries the step's increment, so the momenta change only by
/// the Newton residual and the round-off of the velocities, not by that of `|u|` (2 m here).
#[test]
fn free_spinning_lattice_keeps_energy_and_momenta() {
    let geometry = box_lattice([0.2, 0.1, 0.1], [2, 1, 1]).unwrap();
    let mut body = Body::new("lattice", Dimension::Three);
    body.materials.push(Material::new("rubber", 1e6, 1e-4));
    body.nodes = geometry.nodes;
    body.members = geometry
        .members
        .into_iter()
        .map(|nodes| Member { nodes, material: 0 })
        .collect();
    body.kinematics = Kinematics::Large;
    body.newton.tolerance = 1e-14;
    let mass = lumped_mass(&body, &[Some(1000.0)]).unwrap();
    let centre = linkage::linkage::dynamics::centre_of_mass(&body, &mass);
    let omega = Vector3::new(1.0, 2.0, 3.0).normalize() * 5.0;
    let mut v = vec![0.0; body.dof_count()];
    for (n, p) in body.nodes.iter().enumerate() {
        let w = Vector3::new(0.1, 0.0, 0.0) + omega.cross(&(p - centre));
        v[3 * n..3 * n + 3].copy_from_slice(w.as_slice());
    }
    let mut m = BodyMotion::new(&body, mass.clone(), v, RayleighDamping::default()).unwrap();
    let energy =
        |m: &BodyMotion| kinetic_energy(&mass, &m.motion.v) + strain_energy(&body, &m.motion.u);
    let e0 = energy(&m);
    let p0 = momentum(&body, &mass, &m.motion.v);
    let l0 = angular_momentum(&body, &mass, &m.motion.u, &m.motion.v);
    let speeds: Vec<f64> = m
        .motion
        .v
        .chunks(3)
        .map(|c| Vector3::new(c[0], c[1], c[2]).norm())
        .collect();
    let p_scale: f64 = speeds
        .iter()
        .enumerate()
        .map(|(n, s)| mass[3 * n] * s)
        .sum();
    let l_scale: f64 = speeds
        .iter()
        .enumerate()
        .map(|(n, s)| mass[3 * n] * s * body.nodes[n].norm())
        .sum();
    let h = 2e-3;
    let mut peak_strain: f64 = 0.0;
    let mut iterations = 0;
    for k in 0..10_000 {
        iterations += m
            .step(&body, &EnergyMomentum, k as f64 * h, h, 100.0)
            .unwrap()
            .iterations;
        if k % 10 == 0 {
            peak_strain = peak_strain.max(strain_energy(&body, &m.motion.u));
        }
    }
    assert!(
        peak_strain > 1e-6 * e0,
        "the members do not ring: {peak_strain}"
    );
    let e1 = energy(&m);
    assert!(((e1 - e0) / e0).abs() < 1e-10, "energy {e0} → {e1}");
    let p1 = momentum(&body, &mass, &m.motion.v);
    let l1 = angular_momentum(&body, &mass, &m.motion.u, &m.motion.v);
    for (a, b) in p0.iter().zip(&p1) {
        assert!((a - b).abs() < 1e-12 * p_scale, "momentum {p0:?} → {p1:?}");
    }
    for (a, b) in l0.iter().zip(&l1) {
        assert!(
            (a - b).abs() < 1e-12 * l_scale,
            "angular momentum {l0:?} → {l1:?}"
        );
    }
    // It has turned and moved: 16 turns, 2 m along x.
    let x_shift: f64 = (0..body.nodes.len())
        .map(|n| m.motion.u[3 * n])
        .sum::<f64>()
        / body.nodes.len() as f64;
    assert!((x_shift - 2.0).abs() < 0.05, "{x_shift}");
    eprintln!(
        "spinning lattice: energy {:e}, momentum {:e}, angular momentum {:e} relative; {:.2} Newton iterations per step",
        ((e1 - e0) / e0).abs(),
        p0.iter().zip(&p1).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / p_scale,
        l0.iter().zip(&l1).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / l_scale,
        iterations as f64 / 10_000.0
    );
}

fn linkage_cmd() -> Command {
    Command::new(env!("CARGO_BIN_EXE_linkage"))
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

fn run_scene(dir: &Path, scene: &str) -> Output {
    let path = dir.join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    linkage_cmd()
        .arg("run")
        .arg(&path)
        .arg("--out")
        .arg(dir.join("out"))
        .output()
        .unwrap()
}

const FALLING: &str = r#"name = "falling"
gravity = [0.0, -9.81]

[dynamics]
duration = 0.1
time_step = 0.01
frames = 5
integrator = "INTEGRATOR"

[[materials]]
name = "rubber"
youngs_modulus = 1e6
area = 1e-4
density = 1000.0

[[bodies]]
name = "block"
rectangle = { width = 0.2, height = 0.1, cells = [2, 1] }
velocity = [0.5, 0.0]
"#;

/// A free body under gravity, no supports: every node is at `x = v₀t`, `y = −½gt²` and moves
/// at `(v₀, −gt)` at every stored time (0.02 s apart), exactly (to 1e-12 m and m/s): a constant
/// force is integrated exactly by each integrator, and a rigid translation strains nothing.
/// The summary's energies balance: kinetic = work of gravity, total energy constant (1e-9 J).
#[test]
fn a_falling_body_falls_as_half_g_t_squared() {
    for integrator in [
        "energy_momentum",
        "newmark",
        "generalized_alpha",
        "backward_euler",
    ] {
        let dir = tempfile::tempdir().unwrap();
        let run = run_scene(dir.path(), &FALLING.replace("INTEGRATOR", integrator));
        assert!(run.status.success(), "{integrator}: {}", text(&run));
        let folder = dir.path().join("out/falling");
        for k in 0..=5 {
            let step: serde_json::Value = serde_json::from_str(
                &std::fs::read_to_string(folder.join(format!("steps/{k:04}.json"))).unwrap(),
            )
            .unwrap();
            let t = step["time"].as_f64().unwrap();
            assert!((t - 0.02 * k as f64).abs() < 1e-15, "{t}");
            let body = &step["bodies"][0];
            for (u, v) in body["displacements"]
                .as_array()
                .unwrap()
                .iter()
                .zip(body["velocities"].as_array().unwrap())
            {
                let (ux, uy) = (u[0].as_f64().unwrap(), u[1].as_f64().unwrap());
                let (vx, vy) = (v[0].as_f64().unwrap(), v[1].as_f64().unwrap());
                if integrator == "backward_euler" {
                    // First order: x exact, y off by ½ g h t (the rule's lag), v exact.
                    assert!(
                        (uy + 0.5 * 9.81 * t * t + 0.5 * 9.81 * 0.01 * t).abs() < 1e-12,
                        "{integrator} {uy}"
                    );
                } else {
                    assert!(
                        (uy + 0.5 * 9.81 * t * t).abs() < 1e-12,
                        "{integrator} t = {t}: {uy}"
                    );
                }
                assert!(
                    (ux - 0.5 * t).abs() < 1e-12 && (vx - 0.5).abs() < 1e-12,
                    "{integrator}"
                );
                assert!((vy + 9.81 * t).abs() < 1e-12, "{integrator} t = {t}: {vy}");
            }
        }
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(folder.join("summary.json")).unwrap())
                .unwrap();
        let steps = summary["steps"].as_array().unwrap();
        let e0 = steps[0]["total_energy"].as_f64().unwrap();
        let last = &steps[5];
        if integrator != "backward_euler" {
            let ke = last["kinetic_energy"].as_f64().unwrap();
            let ke0 = steps[0]["kinetic_energy"].as_f64().unwrap();
            let work = last["external_work"].as_f64().unwrap();
            assert!(
                (ke - ke0 - work).abs() < 1e-9,
                "{integrator}: {ke} − {ke0} against {work}"
            );
            assert!((last["total_energy"].as_f64().unwrap() - e0).abs() < 1e-9);
        }
        assert_eq!(last["momenta"][0]["momentum"].as_array().unwrap().len(), 2);
        assert_eq!(last["time_steps"].as_u64(), Some(2));
    }
}

/// The scene of [`FALLING`] with `replace` applied, checked by `linkage check`: it fails, and
/// the message names `line` of the scene file and says `says`.
fn refused(replace: &[(&str, &str)], line: usize, says: &str) {
    let mut scene = FALLING.replace("INTEGRATOR", "energy_momentum");
    for (a, b) in replace {
        assert!(scene.contains(a), "{a}");
        scene = scene.replace(a, b);
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, &scene).unwrap();
    let out = linkage_cmd().arg("check").arg(&path).output().unwrap();
    let msg = text(&out);
    assert!(!out.status.success(), "{scene}\n{msg}");
    assert!(
        msg.contains(&format!("scene.toml:{line}:")),
        "line {line}: {msg}"
    );
    assert!(msg.contains(says), "{says}: {msg}");
    assert!(!msg.contains("panicked"), "{msg}");
}

/// Every error of a dynamic scene names its line and says what to do.
#[test]
fn every_error_of_a_dynamic_scene_names_its_line() {
    refused(
        &[("density = 1000.0\n", "")],
        10,
        "material 'rubber' has no density",
    );
    refused(&[("duration = 0.1", "duration = 0.0")], 5, "`duration` = 0");
    refused(
        &[("time_step = 0.01", "time_step = nan")],
        6,
        "`time_step` = NaN",
    );
    refused(
        &[("time_step = 0.01", "time_step = -1.0")],
        6,
        "`time_step` = -1",
    );
    refused(
        &[("frames = 5", "frames = 11")],
        7,
        "`frames` = 11 is more than the 10 time steps",
    );
    refused(&[("frames = 5", "frames = 0")], 7, "`frames` = 0");
    refused(
        &[(
            "integrator = \"energy_momentum\"",
            "integrator = \"generalized_alpha\"\nrho_inf = 1.5",
        )],
        9,
        "`rho_inf` = 1.5",
    );
    refused(
        &[(
            "integrator = \"energy_momentum\"",
            "integrator = \"newmark\"\ngamma = 0.4",
        )],
        9,
        "`gamma` = 0.4",
    );
    refused(
        &[("integrator = \"energy_momentum\"", "integrator = \"rk4\"")],
        8,
        "`integrator` = \"rk4\"",
    );
    refused(
        &[("frames = 5", "frames = 5\nrho_inf = 0.5")],
        8,
        "`rho_inf` is a parameter of integrator = \"generalized_alpha\"",
    );
    refused(
        &[("frames = 5", "frames = 5\ndamping = { mass = -1.0 }")],
        8,
        "`damping` mass = -1",
    );
    // A nonzero initial velocity in a held direction: x is held, the body moves at 0.5 m/s in x.
    refused(
        &[(
            "velocity = [0.5, 0.0]\n",
            "velocity = [0.5, 0.0]\n[[bodies.supports]]\nnodes = [1]\nfix = [\"x\"]\n",
        )],
        19,
        "gives node 1 the velocity 0.5 m/s in x, which a support holds",
    );
    refused(
        &[("velocity = [0.5, 0.0]\n", "[[bodies.velocities]]\nnodes = [2]\nvelocity = [0.0, 1.0]\n[[bodies.supports]]\nnodes = [2]\nfix = [\"y\"]\n")],
        21,
        "gives node 2 the velocity 1 m/s in y",
    );
    refused(
        &[("velocity = [0.5, 0.0]\n", "angular_velocity = [1.0, 2.0]\n")],
        19,
        "a 2D body turns about z: give one finite number",
    );
    refused(
        &[("[dynamics]", "[[obstacles]]\nname = \"floor\"\nshape = \"half_space\"\npoint = [0.0, -1.0]\nnormal = [0.0, 1.0]\n\n[dynamics]\ndamping = { stiffness = 1e-3 }")],
        15,
        "[dynamics] damping.stiffness with contact (obstacles or a [contact] table) is not supported",
    );
    refused(
        &[("[dynamics]\nduration = 0.1\ntime_step = 0.01\nframes = 5\nintegrator = \"energy_momentum\"\n", "")],
        14,
        "`velocity` is an initial velocity, for a scene solved in time",
    );
}

/// A zero velocity component in a held direction is fine, and a held body rings: a supported
/// node stays put while the rest moves.
#[test]
fn a_zero_velocity_in_a_held_direction_is_fine() {
    let dir = tempfile::tempdir().unwrap();
    let scene = FALLING.replace("INTEGRATOR", "newmark").replace(
        "velocity = [0.5, 0.0]\n",
        "velocity = [0.0, 0.0]\n[[bodies.supports]]\nnodes = [1]\nfix = [\"x\", \"y\"]\n",
    );
    let run = run_scene(dir.path(), &scene);
    assert!(run.status.success(), "{}", text(&run));
}

/// The outputs of a dynamic run (issue 31 item 6), on [`FALLING`] with pictures and ParaView
/// files: `plots/energies.csv` holds exactly the summary's kinetic, strain, external work,
/// dissipated and total energies at each stored time (to 1e-12 relative; no contact plot
/// without contact); the `.pvd`'s `timestep`s are the stored times; the GIF shows each frame
/// for its real time to the next (0.02 s: 2 hundredths); `batch.csv` has the dynamic columns
/// `duration` = 0.1 s, `peak_contact_force` = 0 and `final_kinetic_energy` = the summary's.
#[test]
fn a_dynamic_run_plots_its_energies_and_writes_times_and_batch_columns() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, FALLING.replace("INTEGRATOR", "newmark")).unwrap();
    let out = dir.path().join("out");
    let run = linkage_cmd()
        .arg("run")
        .arg(&path)
        .arg("--out")
        .arg(&out)
        .args(["--png", "--vtk"])
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", text(&run));
    let folder = out.join("falling");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(folder.join("summary.json")).unwrap())
            .unwrap();
    let steps = summary["steps"].as_array().unwrap();
    let times: Vec<f64> = steps.iter().map(|s| s["time"].as_f64().unwrap()).collect();
    assert_eq!(times.len(), 6);
    // The energy plot's points are the summary's, series by series.
    let csv = std::fs::read_to_string(folder.join("plots/energies.csv")).unwrap();
    assert!(folder.join("plots/energies.png").is_file());
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("series,time_s,energy_J,label"));
    let mut points = 0;
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        let key = match f[0] {
            "kinetic" => "kinetic_energy",
            "strain" => "strain_energy",
            "external work" => "external_work",
            "dissipated" => "dissipated",
            "total" => "total_energy",
            other => panic!("unexpected series {other}"),
        };
        let t: f64 = f[1].parse().unwrap();
        let e: f64 = f[2].parse().unwrap();
        let k = times.iter().position(|&s| s == t).expect("a stored time");
        let expected = steps[k][key].as_f64().unwrap();
        assert!(
            (e - expected).abs() <= 1e-12 * expected.abs().max(1e-300),
            "{key} at {t}: {e} against {expected}"
        );
        points += 1;
    }
    assert_eq!(points, 5 * 6);
    assert!(!folder.join("plots/contact_force_time.csv").exists());
    // The ParaView collection plays at the stored times.
    let pvd = std::fs::read_to_string(folder.join("vtk/falling.pvd")).unwrap();
    let pvd_times: Vec<f64> = pvd
        .split("timestep=\"")
        .skip(1)
        .map(|s| s[..s.find('"').unwrap()].parse().unwrap())
        .collect();
    assert_eq!(pvd_times, times);
    // The GIF at real speed: 0.02 s per frame, the last held 2 s.
    let file = std::fs::File::open(folder.join("anim.gif")).unwrap();
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::Indexed);
    let mut decoder = options.read_info(file).unwrap();
    let mut delays = Vec::new();
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        delays.push(frame.delay);
    }
    assert_eq!(delays, vec![2, 2, 2, 2, 2, 200]);
    // The batch table's dynamic columns.
    let table = std::fs::read_to_string(out.join("batch.csv")).unwrap();
    let mut rows = table.lines().map(|l| l.split(',').collect::<Vec<_>>());
    let header = rows.next().unwrap();
    let row = rows.next().unwrap();
    let cell = |name: &str| -> f64 {
        let k = header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("no column {name}: {header:?}"));
        row[k].parse().unwrap()
    };
    assert_eq!(cell("duration"), 0.1);
    assert_eq!(cell("peak_contact_force"), 0.0);
    let ke = steps[5]["kinetic_energy"].as_f64().unwrap();
    assert!(
        (cell("final_kinetic_energy") - ke).abs() <= 1e-12 * ke,
        "{ke}"
    );
}

/// A large-displacement body's pressure follows its deformed faces, which the time step's
/// residual does not take yet: a dynamic scene with one is refused naming the body and what to
/// do (before, the pressure was left out in silence and the body fell as if unloaded), and no
/// results are written.
#[test]
fn a_following_pressure_in_a_dynamic_scene_is_refused_not_left_out() {
    let scene = FALLING.replace("INTEGRATOR", "energy_momentum").replace(
        "velocity = [0.5, 0.0]\n",
        "velocity = [0.5, 0.0]\nkinematics = \"large\"\n\n[[bodies.pressures]]\non_line = { point = [0.0, 0.1], direction = [1.0, 0.0] }\npressure = 100.0\n",
    );
    let dir = tempfile::tempdir().unwrap();
    let run = run_scene(dir.path(), &scene);
    let msg = text(&run);
    assert!(!run.status.success(), "{msg}");
    assert!(
        msg.contains("body 'block'")
            && msg.contains("follows the deformed faces")
            && msg.contains("kinematics = \"small\""),
        "{msg}"
    );
    assert!(!msg.contains("panicked"), "{msg}");
    assert!(!dir.path().join("out/falling/summary.json").exists());
    // The same pressure on the small-displacement body acts on the undeformed faces: it runs.
    let small = scene.replace("kinematics = \"large\"\n", "");
    let dir = tempfile::tempdir().unwrap();
    let run = run_scene(dir.path(), &small);
    assert!(run.status.success(), "{}", text(&run));
}
