//! Verification against hand calculations and closed-form solutions (paper Eq. 1–10).
//! Every tolerance is stated where it is used.

use linkage::linkage::{
    Body, Dimension, Equilibrium, Material, Member, NodalLoad, Schedule, StepState, Support,
};
use linkage::scene::{load_scene, Simulation};
use nalgebra::Vector3;
use std::path::Path;

fn v(x: f64, y: f64, z: f64) -> Vector3<f64> {
    Vector3::new(x, y, z)
}

fn solve(body: &Body) -> StepState {
    let eq = Equilibrium::new(body).expect("solvable");
    eq.solve_step(body, 1, 1).expect("step")
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs().max(1e-300)
}

/// The paper's square (Fig. 4–5) solved by hand with the force method: one redundant member,
/// P = 200 N, L = 1 m, EA = 2e7 N. Compatibility gives sides ±P/2, diagonals ±P/√2;
/// U1 = (1/2 + √2) PL/EA, V1 = −PL/(2EA), U2 = (1 + √2) PL/EA, V2 = PL/(2EA), U4 = PL/(2EA);
/// the supports answer with (−P, −P) at node 3 and (0, P) at node 4 (Eq. 10).
#[test]
fn paper_square_matches_hand_calculation() {
    let world = load_scene(Path::new("scenes/paper_square.toml")).unwrap();
    let mut sim = Simulation::new(&world).unwrap();
    let (result, summary) = sim.step(1).unwrap();
    let body = &result.bodies[0];
    let (p, pl_ea) = (200.0, 200.0 * 1.0 / 2e7);
    let s2 = 2f64.sqrt();
    let expect_u = [
        [(0.5 + s2) * pl_ea, -0.5 * pl_ea],
        [(1.0 + s2) * pl_ea, 0.5 * pl_ea],
        [0.0, 0.0],
        [0.5 * pl_ea, 0.0],
    ];
    for (n, e) in expect_u.iter().enumerate() {
        for (k, (got, want)) in body.displacements[n].iter().zip(e).enumerate() {
            assert!(
                (got - want).abs() <= 1e-12 * pl_ea,
                "node {} dir {k}: {got} vs {want}",
                n + 1
            );
        }
    }
    // Members 1–4 (sides 1-4, 1-2, 2-3, 3-4), 5–6 (diagonals 1-3, 2-4): tension positive.
    let expect_n = [-p / 2.0, -p / 2.0, p / 2.0, p / 2.0, p / s2, -p / s2];
    for (m, e) in expect_n.iter().enumerate() {
        assert!(
            (body.axial_forces[m] - e).abs() <= 1e-9 * p,
            "member {}",
            m + 1
        );
        assert!((body.stresses[m] - e / 1e-4).abs() <= 1e-9 * p / 1e-4);
    }
    assert_eq!(body.reactions.len(), 2);
    assert_eq!(body.reactions[0].node, 3);
    assert!((body.reactions[0].force[0] + p).abs() <= 1e-9 * p);
    assert!((body.reactions[0].force[1] + p).abs() <= 1e-9 * p);
    assert_eq!(body.reactions[1].node, 4);
    assert_eq!(
        body.reactions[1].force[0], 0.0,
        "node 4 is free in x: no reaction there"
    );
    assert!((body.reactions[1].force[1] - p).abs() <= 1e-9 * p);
    assert!(summary.residual < 1e-12);
}

/// Paper Eq. 1: a single bar, D = F L / (A E).
#[test]
fn single_bar_obeys_eq1() {
    let (f, l, a, e) = (1234.5, 2.5, 3e-4, 70e9);
    let mut body = Body::new("bar", Dimension::Three);
    body.materials.push(Material::new("al", e, a));
    // An inclined bar, so the check covers the rotation of Eq. 2 as well.
    let dir = v(1.0, 2.0, -2.0) / 3.0;
    body.nodes = vec![v(0.0, 0.0, 0.0), dir * l];
    body.members.push(Member {
        nodes: [0, 1],
        material: 0,
    });
    body.supports.push(Support::fixed(0, [true, true, true]));
    // Node 2 held in y and z: only u_x is free, K_xx = (AE/L) n_x², so
    // u_x = F L / (A E n_x²) and the axial force is F / n_x.
    body.supports.push(Support::fixed(1, [false, true, true]));
    body.loads.push(NodalLoad {
        node: 1,
        force: v(f, 0.0, 0.0),
        schedule: Schedule::Linear,
    });
    let s = solve(&body);
    let ux = f * l / (a * e * dir.x * dir.x);
    assert!(close(s.displacements[1].x, ux, 1e-12));
    assert!(close(s.axial_forces[0], f / dir.x, 1e-12));

    // The plain case: a bar along x with transverse directions held.
    let mut bar = Body::new("bar", Dimension::Two);
    bar.materials.push(Material::new("steel", e, a));
    bar.nodes = vec![v(0.0, 0.0, 0.0), v(l, 0.0, 0.0)];
    bar.members.push(Member {
        nodes: [0, 1],
        material: 0,
    });
    bar.supports.push(Support::fixed(0, [true, true, false]));
    bar.supports.push(Support::fixed(1, [false, true, false]));
    bar.loads.push(NodalLoad {
        node: 1,
        force: v(f, 0.0, 0.0),
        schedule: Schedule::Linear,
    });
    let s = solve(&bar);
    assert!(close(s.displacements[1].x, f * l / (a * e), 1e-13));
    assert!(close(s.axial_forces[0], f, 1e-13));
    assert!(close(s.strains[0], f / (a * e), 1e-13));
    assert!(close(s.reactions[0].1.x, -f, 1e-13));
}

/// A symmetric tripod: three bars from the apex (0, 0, h) to supports on a circle of radius R
/// at 0°, 120°, 240°, apex loaded by P downward. Each bar carries N = −P / (3 sin α) and the apex
/// sinks by δ = P L / (3 E A sin² α), sin α = h / L.
#[test]
fn tripod_matches_closed_form() {
    let (h, r, p, e, a) = (1.2, 0.9, 5000.0, 200e9, 2e-4);
    let mut body = Body::new("tripod", Dimension::Three);
    body.materials.push(Material::new("steel", e, a));
    body.nodes.push(v(0.0, 0.0, h));
    for k in 0..3 {
        let t = (k as f64) * 2.0 * std::f64::consts::PI / 3.0;
        body.nodes.push(v(r * t.cos(), r * t.sin(), 0.0));
        body.members.push(Member {
            nodes: [0, k + 1],
            material: 0,
        });
        body.supports
            .push(Support::fixed(k + 1, [true, true, true]));
    }
    body.loads.push(NodalLoad {
        node: 0,
        force: v(0.0, 0.0, -p),
        schedule: Schedule::Linear,
    });
    let s = solve(&body);
    let l = (h * h + r * r).sqrt();
    let sin_a = h / l;
    for m in 0..3 {
        assert!(
            close(s.axial_forces[m], -p / (3.0 * sin_a), 1e-12),
            "member {}",
            m + 1
        );
    }
    assert!(close(
        s.displacements[0].z,
        -p * l / (3.0 * e * a * sin_a * sin_a),
        1e-12
    ));
    assert!(s.displacements[0].xy().norm() <= 1e-12 * s.displacements[0].z.abs());
}

fn series_body(k1: (f64, f64, f64), k2: (f64, f64, f64)) -> Body {
    // Two bars in series along x: (E, A, L) each, node 1 fixed, y held everywhere.
    let mut body = Body::new("series", Dimension::Two);
    body.materials.push(Material::new("one", k1.0, k1.1));
    body.materials.push(Material::new("two", k2.0, k2.1));
    body.nodes = vec![
        v(0.0, 0.0, 0.0),
        v(k1.2, 0.0, 0.0),
        v(k1.2 + k2.2, 0.0, 0.0),
    ];
    body.members.push(Member {
        nodes: [0, 1],
        material: 0,
    });
    body.members.push(Member {
        nodes: [1, 2],
        material: 1,
    });
    body.supports.push(Support::fixed(0, [true, true, false]));
    body.supports.push(Support::fixed(1, [false, true, false]));
    body.supports.push(Support::fixed(2, [false, true, false]));
    body
}

/// Composite: two materials in series carry the same force; the end moves by
/// P (L1 / E1A1 + L2 / E2A2).
#[test]
fn two_materials_in_series() {
    let (one, two) = ((200e9, 1e-4, 0.7), (70e9, 3e-4, 1.3));
    let mut body = series_body(one, two);
    let p = 10_000.0;
    body.loads.push(NodalLoad {
        node: 2,
        force: v(p, 0.0, 0.0),
        schedule: Schedule::Linear,
    });
    let s = solve(&body);
    let c1 = one.2 / (one.0 * one.1);
    let c2 = two.2 / (two.0 * two.1);
    assert!(close(s.displacements[1].x, p * c1, 1e-12));
    assert!(close(s.displacements[2].x, p * (c1 + c2), 1e-12));
    assert!(close(s.axial_forces[0], p, 1e-12) && close(s.axial_forces[1], p, 1e-12));
    assert!(close(s.stresses[0], p / one.1, 1e-12) && close(s.stresses[1], p / two.1, 1e-12));
}

/// A prescribed support displacement δ at the end of two springs in series: the middle node
/// moves δ k2 / (k1 + k2) and the supports push with k1 k2 / (k1 + k2) δ.
#[test]
fn prescribed_support_displacement() {
    let (one, two) = ((200e9, 1e-4, 1.0), (200e9, 2e-4, 0.5));
    let mut body = series_body(one, two);
    let delta = 0.002;
    body.supports[2] = Support {
        node: 2,
        fixed: [true, true, false],
        displacement: v(delta, 0.0, 0.0),
        schedule: Schedule::Linear,
    };
    let eq = Equilibrium::new(&body).unwrap();
    let k1 = one.0 * one.1 / one.2;
    let k2 = two.0 * two.1 / two.2;
    for step in 1..=4 {
        let s = eq.solve_step(&body, step, 4).unwrap();
        let f = step as f64 / 4.0;
        assert!(close(s.displacements[2].x, f * delta, 1e-15));
        assert!(close(
            s.displacements[1].x,
            f * delta * k2 / (k1 + k2),
            1e-12
        ));
        let force = f * delta * k1 * k2 / (k1 + k2);
        let end = s.reactions.iter().find(|(n, _)| *n == 2).unwrap().1;
        let start = s.reactions.iter().find(|(n, _)| *n == 0).unwrap().1;
        assert!(
            close(end.x, force, 1e-12),
            "the support pulls the end outward"
        );
        assert!(close(start.x, -force, 1e-12));
    }
}

/// Loads follow their schedules: a linear ramp scales the whole answer by k / steps; an
/// explicit schedule gives its own factor; two schedules superpose.
#[test]
fn load_steps_follow_schedules() {
    let mut body = series_body((1e9, 1e-4, 1.0), (1e9, 1e-4, 1.0));
    body.loads.push(NodalLoad {
        node: 2,
        force: v(100.0, 0.0, 0.0),
        schedule: Schedule::Linear,
    });
    body.loads.push(NodalLoad {
        node: 1,
        force: v(-40.0, 0.0, 0.0),
        schedule: Schedule::Factors(vec![1.0, 0.0, -2.0]),
    });
    let eq = Equilibrium::new(&body).unwrap();
    let k = 1e9 * 1e-4 / 1.0;
    let zero = eq.solve_step(&body, 0, 3).unwrap();
    assert!(zero.displacements.iter().all(|u| u.norm() == 0.0));
    for (step, g) in [(1, 1.0), (2, 0.0), (3, -2.0)] {
        let s = eq.solve_step(&body, step, 3).unwrap();
        let f_end = 100.0 * step as f64 / 3.0;
        let f_mid = -40.0 * g;
        // Node 2 (index 1) carries everything beyond it: u1 = (f_end + f_mid)/k, u2 = u1 + f_end/k.
        assert!(
            close(s.displacements[1].x, (f_end + f_mid) / k, 1e-12),
            "step {step}"
        );
        assert!(
            close(s.displacements[2].x, (2.0 * f_end + f_mid) / k, 1e-12),
            "step {step}"
        );
    }
}

/// A structure symmetric about x = 0 under a symmetric load has a mirror-symmetric answer.
#[test]
fn symmetric_disk_gives_mirror_symmetric_answer() {
    let world = load_scene(Path::new("scenes/paper_disk.toml")).unwrap();
    let mut sim = Simulation::new(&world).unwrap();
    let (result, _) = sim.step(world.steps).unwrap();
    let body = &world.bodies[0];
    let u = &result.bodies[0].displacements;
    let scale = u.iter().map(|d| d[0].hypot(d[1])).fold(0.0, f64::max);
    assert!(scale > 0.0);
    let mut pairs = 0;
    for (i, p) in body.nodes.iter().enumerate() {
        let j = body
            .nodes
            .iter()
            .position(|q| (q.x + p.x).abs() < 1e-12 && (q.y - p.y).abs() < 1e-12)
            .expect("every node has a mirror image");
        assert!(
            (u[i][0] + u[j][0]).abs() <= 1e-9 * scale,
            "node {} x",
            i + 1
        );
        assert!(
            (u[i][1] - u[j][1]).abs() <= 1e-9 * scale,
            "node {} y",
            i + 1
        );
        pairs += 1;
    }
    assert_eq!(pairs, body.nodes.len());
}

/// Equilibrium on every bundled scene: at every step the loads, reactions and contact forces of
/// all bodies sum to zero to 1e-9 of the largest of them.
#[test]
fn every_bundled_scene_is_in_equilibrium() {
    let mut scenes: Vec<_> = std::fs::read_dir("scenes")
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 5);
    for path in scenes {
        let world = load_scene(&path).unwrap();
        // A dynamic scene's forces balance its inertia, not each other: tests/dynamics.rs
        // checks its energy and momenta instead.
        if world.dynamics.is_some() {
            continue;
        }
        let mut sim = Simulation::new(&world).unwrap();
        // The balance is measured against the largest force the run has carried so far: once
        // a body has broken apart (wedge_split's last steps) its forces fall by orders of
        // magnitude, while the solution's absolute error stays that of the solves before.
        let mut largest = 0.0f64;
        for step in 0..=world.steps {
            // A structure that collapses (paper_fracture) ends its run there: the steps before
            // it are checked.
            let (result, summary) = match sim.step(step) {
                Ok(solved) => solved,
                Err(linkage::scene::RunError::Collapse { .. }) => break,
                Err(e) => panic!("{}: {e}", path.display()),
            };
            let mut total = [0.0f64; 3];
            let mut scale = 0.0f64;
            for b in &result.bodies {
                for f in b.loads.iter().chain(&b.reactions) {
                    for (k, c) in f.force.iter().enumerate() {
                        total[k] += c;
                    }
                }
                for f in &b.loads {
                    scale = scale.max(f.force.iter().map(|c| c * c).sum::<f64>().sqrt());
                }
                for f in &b.reactions {
                    scale = scale.max(f.force.iter().map(|c| c * c).sum::<f64>().sqrt());
                }
                // Contact forces (issue 5): obstacles push the bodies, bodies push each other.
                for c in &b.contacts {
                    for (k, x) in c.force.iter().enumerate() {
                        total[k] += x;
                    }
                    scale = scale.max(c.force.iter().map(|x| x * x).sum::<f64>().sqrt());
                }
            }
            let norm = total.iter().map(|c| c * c).sum::<f64>().sqrt();
            largest = largest.max(scale);
            // The balance below is vacuous without forces: at its last step every bundled
            // scene is loaded (by forces, prescribed displacements or contact).
            if step == world.steps {
                assert!(
                    scale > 0.0,
                    "{}: no forces at the last step",
                    path.display()
                );
            }
            assert!(
                norm <= 1e-9 * largest.max(1e-300) || largest == 0.0,
                "{}: step {step}: {norm}",
                path.display()
            );
            // The residual is relative to the step's own forces: once wedge_split's block has
            // split and its halves rest against the wedge carrying ~1e-7 N (its run's largest
            // force was 5.6 kN), 1e-3 of those is still 1e-16 of the run's largest: measured
            // like the balance above, against the largest force the run has carried.
            assert!(
                summary.residual < 1e-9 || summary.residual * scale <= 1e-9 * largest,
                "{}: step {step}: residual {:e} of {scale:e} N, the run's largest {largest:e} N",
                path.display(),
                summary.residual
            );
        }
    }
}

/// Fig. 6: as the force grows, more members pass their strength, none before it is large enough.
#[test]
fn overload_grows_with_the_force() {
    let world = load_scene(Path::new("scenes/paper_overload.toml")).unwrap();
    let mut sim = Simulation::new(&world).unwrap();
    let mut counts = Vec::new();
    for step in 0..=world.steps {
        let (result, summary) = sim.step(step).unwrap();
        let b = &result.bodies[0];
        for &m in &b.overloaded {
            assert!(
                b.stresses[m - 1].abs() > 4e6,
                "member {m} listed but within strength"
            );
        }
        let beyond = b.stresses.iter().filter(|s| s.abs() > 4e6).count();
        assert_eq!(beyond, b.overloaded.len());
        assert_eq!(summary.overloaded, beyond);
        counts.push(beyond);
    }
    assert_eq!(counts[0], 0);
    assert_eq!(counts[1], 0, "the first step is below every strength");
    assert!(counts.windows(2).all(|w| w[0] <= w[1]), "{counts:?}");
    assert!(*counts.last().unwrap() >= 3, "{counts:?}");
}
