//! Pressure that follows the deformation of a body under large displacements, against closed
//! forms of inflated rings, and the convergence its load stiffness buys Newton.
//!
//! 3D: a tube wall of one antiprism band (two rings of N nodes, the upper one turned by half a
//! pitch, hoop members in both rings and a zigzag of members between them; its triangles are
//! the loaded patches), held in z. By its symmetry every node stays on one circle of radius r;
//! the pressure's nodal force is radial, `F = p ∂V/∂r / 2N` with `V` the volume enclosed by the
//! band and its end planes (the prismatoid `V = h/6 (A₀ + A₁ + 4 A_mid)`), which gives
//! `F = p h r (sin α + 4 cos²(α/4) sin(α/2)) / 6`, α = 2π/N. Equilibrium of a node:
//! `F = 2 T_h sin(α/2) + 4 T_z r sin²(α/4) / L_z`, with `T = EA (L − L₀)/L₀`, hoop length
//! `L_h = 2 r sin(α/2)` and zigzag length `L_z = √(4 r² sin²(α/4) + h²)`: one scalar equation
//! in r, solved by bisection.
//!
//! 2D: a ring lattice of an inner and an outer circle of N nodes, hoops on both, spokes, and
//! both diagonals of every cell, with a pressure (N/m) on the inner boundary. The inner
//! radius r₁ and the outer r₂ solve the radial equilibrium of an inner and an outer node (see
//! `ring_closed_form`).

use linkage::linkage::{
    boundary_segments, Body, Dimension, Kinematics, Material, Member, NewtonEquilibrium, Pressure,
    PressureFaces, Schedule, Support,
};
use nalgebra::Vector3;
use std::f64::consts::PI;

const EA: f64 = 1e7 * 1e-4;

fn member(a: usize, b: usize) -> Member {
    Member {
        nodes: [a, b],
        material: 0,
    }
}

/// The antiprism tube band: N nodes at z = 0 (0..N), N at z = h (N..2N), radius `radius`.
fn tube(n: usize, radius: f64, h: f64, pressure: f64) -> Body {
    let alpha = 2.0 * PI / n as f64;
    let mut body = Body::new("tube", Dimension::Three);
    body.materials.push(Material::new("rubber", 1e7, 1e-4));
    for k in 0..n {
        let t = k as f64 * alpha;
        body.nodes
            .push(Vector3::new(radius * t.cos(), radius * t.sin(), 0.0));
    }
    for k in 0..n {
        let t = (k as f64 + 0.5) * alpha;
        body.nodes
            .push(Vector3::new(radius * t.cos(), radius * t.sin(), h));
    }
    let (a, b) = (|k: usize| k % n, |k: usize| n + k % n);
    let mut patches = Vec::new();
    for k in 0..n {
        body.members.push(member(a(k), a(k + 1)));
        body.members.push(member(b(k), b(k + 1)));
        body.members.push(member(a(k), b(k)));
        body.members.push(member(a(k + 1), b(k)));
        // Normals toward the axis: the cavity is outside the wall's "body".
        patches.push([a(k), b(k), a(k + 1)]);
        patches.push([b(k), b(k + 1), a(k + 1)]);
    }
    body.patches = patches.clone();
    for node in 0..2 * n {
        body.supports
            .push(Support::fixed(node, [false, false, true]));
    }
    // Rigid motions in the plane: node 0 (on +x) and node N/2 (on −x) held in y, node N/4
    // (on +y) in x: the directions symmetry keeps still (two would leave a rotation about
    // the point where their lines cross).
    body.supports.push(Support::fixed(0, [false, true, false]));
    body.supports
        .push(Support::fixed(n / 4, [true, false, false]));
    body.supports
        .push(Support::fixed(n / 2, [false, true, false]));
    body.kinematics = Kinematics::Large;
    body.pressures.push(Pressure {
        pressure,
        faces: PressureFaces::Patches(patches),
        schedule: Schedule::Linear,
    });
    body
}

/// The radial pressure force on one node of the antiprism band of radius `r` (N).
fn tube_node_force(n: usize, r: f64, h: f64, p: f64) -> f64 {
    let alpha = 2.0 * PI / n as f64;
    let (s2, c4) = ((alpha / 2.0).sin(), (alpha / 4.0).cos());
    p * h * r * (alpha.sin() + 4.0 * c4 * c4 * s2) / 6.0
}

/// The radius of the inflated antiprism band (see the module comment); with `follow` false,
/// the pressure's force stays that of the undeformed band (a dead load), for comparison.
fn tube_closed_form(n: usize, radius: f64, h: f64, p: f64, follow: bool) -> f64 {
    let alpha = 2.0 * PI / n as f64;
    let (s2, s4) = ((alpha / 2.0).sin(), (alpha / 4.0).sin());
    let zigzag = |r: f64| (4.0 * r * r * s4 * s4 + h * h).sqrt();
    let g = |r: f64| {
        let f = tube_node_force(n, if follow { r } else { radius }, h, p);
        let t_h = EA * (r - radius) / radius;
        let t_z = EA * (zigzag(r) - zigzag(radius)) / zigzag(radius);
        f - 2.0 * t_h * s2 - 4.0 * t_z * r * s4 * s4 / zigzag(r)
    };
    bisect(g, radius, 10.0 * radius)
}

fn bisect(g: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    assert!(g(lo) > 0.0 && g(hi) < 0.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if g(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

fn radii(body: &Body, displacements: &[Vector3<f64>]) -> Vec<f64> {
    body.nodes
        .iter()
        .zip(displacements)
        .map(|(x, u)| (x + u).xy().norm())
        .collect()
}

#[test]
fn an_inflated_tube_grows_to_its_closed_form_radius() {
    // p = 1 kPa on a band of radius 1 m, 0.5 m high: the hoops stretch by tens of percent.
    let (n, radius, h, p) = (16, 1.0, 0.5, 1000.0);
    let mut body = tube(n, radius, h, p);
    body.newton.tolerance = 1e-12;
    let steps = 4;
    let mut newton = NewtonEquilibrium::new(&body).unwrap();
    for step in 1..=steps {
        let state = newton.solve_step(&body, step, steps).unwrap();
        let pressure = p * step as f64 / steps as f64;
        let expected = tube_closed_form(n, radius, h, pressure, true);
        for (node, r) in radii(&body, &state.displacements).iter().enumerate() {
            assert!(
                (r - expected).abs() <= 1e-9 * expected,
                "step {step} node {}: r = {r}, closed form {expected}",
                node + 1
            );
        }
        if step == steps {
            // Large: the radius grows by more than 10%.
            assert!(expected > 1.1 * radius, "{expected}");
            // The test tells a following pressure from a dead one: on the undeformed band
            // the radius would be smaller by more than 1% of it.
            let dead = tube_closed_form(n, radius, h, pressure, false);
            assert!(expected - dead > 1e-2 * radius, "{expected} {dead}");
            println!(
                "tube radius {expected} (closed form; {dead} under a dead load), history {:?}",
                state.residual_history
            );
            // The step's loads: every node loaded, radially by F(r) of the deformed band.
            assert_eq!(state.loads.len(), 2 * n);
            let f = tube_node_force(n, expected, h, pressure);
            for (node, force) in &state.loads {
                let x = body.nodes[*node] + state.displacements[*node];
                let radial = force.xy().dot(&x.xy()) / x.xy().norm();
                assert!(
                    (radial - f).abs() <= 1e-9 * f,
                    "node {}: {radial} {f}",
                    node + 1
                );
            }
        }
    }
}

/// Relative residuals of one full-pressure step from the undeformed state.
fn one_step_history(load_stiffness: bool) -> Vec<f64> {
    let mut body = tube(16, 1.0, 0.5, 400.0);
    body.newton.tolerance = 1e-12;
    body.newton.max_iterations = 60;
    body.newton.load_stiffness = load_stiffness;
    let mut newton = NewtonEquilibrium::new(&body).unwrap();
    let state = newton.solve_step(&body, 1, 1).unwrap();
    assert_eq!(state.cuts, 0, "{:?}", state.residual_history);
    state.residual_history
}

#[test]
fn with_the_load_stiffness_newton_converges_quadratically_and_without_it_linearly() {
    let with = one_step_history(true);
    let without = one_step_history(false);
    println!("with load stiffness:    {with:?}");
    println!("without load stiffness: {without:?}");
    // Quadratic: once below 1e-3, each residual is at most 10 × the square of the one before.
    let tail: Vec<&[f64]> = with
        .windows(2)
        .filter(|w| w[0] < 1e-3 && w[1] > 0.0)
        .collect();
    assert!(!tail.is_empty(), "{with:?}");
    for w in tail {
        assert!(w[1] <= 10.0 * w[0] * w[0], "{with:?}");
    }
    // Without it the rate is linear: more iterations, and some step divides the residual by
    // less than 1e3 after it is below 1e-3.
    assert!(without.len() > with.len() + 2, "{with:?} {without:?}");
    assert!(
        without
            .windows(2)
            .any(|w| w[0] < 1e-3 && w[1] > 1e-12 && w[1] > 1e-3 * w[0]),
        "{without:?}"
    );
}

/// The 2D ring lattice: inner nodes 0..N at radius `a`, outer N..2N at `b`.
fn ring(n: usize, a: f64, b: f64, p: f64) -> Body {
    let alpha = 2.0 * PI / n as f64;
    let mut body = Body::new("ring", Dimension::Two);
    body.materials.push(Material::new("rubber", 1e7, 1e-4));
    for r in [a, b] {
        for k in 0..n {
            let t = k as f64 * alpha;
            body.nodes.push(Vector3::new(r * t.cos(), r * t.sin(), 0.0));
        }
    }
    let (i, o) = (|k: usize| k % n, |k: usize| n + k % n);
    for k in 0..n {
        body.members.push(member(i(k), i(k + 1)));
        body.members.push(member(o(k), o(k + 1)));
        body.members.push(member(i(k), o(k)));
        body.members.push(member(i(k), o(k + 1)));
        body.members.push(member(o(k), i(k + 1)));
    }
    body.supports.push(Support::fixed(0, [false, true, false]));
    body.supports
        .push(Support::fixed(n / 4, [true, false, false]));
    body.supports
        .push(Support::fixed(n / 2, [false, true, false]));
    body.kinematics = Kinematics::Large;
    let inner: Vec<bool> = (0..2 * n).map(|k| k < n).collect();
    let segments = boundary_segments(&body, &inner);
    assert_eq!(segments.len(), n);
    body.pressures.push(Pressure {
        pressure: p,
        faces: PressureFaces::Segments(segments),
        schedule: Schedule::Linear,
    });
    body
}

/// Radii (r₁, r₂) of the pressurised ring lattice: the radial equilibrium of an inner node,
/// `p r₁ sin α − 2 T₁ sin(α/2) + S + 2 T_d (r₂ cos α − r₁)/D = 0`, and of an outer node,
/// `−2 T₂ sin(α/2) − S + 2 T_d (r₁ cos α − r₂)/D = 0`, with hoop tensions
/// `T₁ = EA (r₁ − a)/a`, `T₂ = EA (r₂ − b)/b`, spoke `S = EA ((r₂ − r₁) − (b − a))/(b − a)`,
/// diagonal length `D = √(r₁² + r₂² − 2 r₁ r₂ cos α)` and tension `T_d = EA (D − D₀)/D₀`
/// (the pressure per node is `p` times the deformed segment length projected:
/// `p · 2 r₁ sin(α/2) cos(α/2)`). Solved by Newton on the two equations to 1e-15.
fn ring_closed_form(n: usize, a: f64, b: f64, p: f64) -> (f64, f64) {
    let alpha = 2.0 * PI / n as f64;
    let s = (alpha / 2.0).sin();
    let diag = |r1: f64, r2: f64| (r1 * r1 + r2 * r2 - 2.0 * r1 * r2 * alpha.cos()).sqrt();
    let d0 = diag(a, b);
    let g = |r1: f64, r2: f64| -> [f64; 2] {
        let t1 = EA * (r1 - a) / a;
        let t2 = EA * (r2 - b) / b;
        let sp = EA * ((r2 - r1) - (b - a)) / (b - a);
        let d = diag(r1, r2);
        let td = EA * (d - d0) / d0;
        [
            p * r1 * alpha.sin() - 2.0 * t1 * s + sp + 2.0 * td * (r2 * alpha.cos() - r1) / d,
            -2.0 * t2 * s - sp + 2.0 * td * (r1 * alpha.cos() - r2) / d,
        ]
    };
    let (mut r1, mut r2) = (a, b);
    for _ in 0..100 {
        let f = g(r1, r2);
        let h = 1e-7;
        let (f1, f2) = (g(r1 + h, r2), g(r1, r2 + h));
        let j = [
            [(f1[0] - f[0]) / h, (f2[0] - f[0]) / h],
            [(f1[1] - f[1]) / h, (f2[1] - f[1]) / h],
        ];
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        let d1 = (f[0] * j[1][1] - f[1] * j[0][1]) / det;
        let d2 = (j[0][0] * f[1] - j[1][0] * f[0]) / det;
        r1 -= d1;
        r2 -= d2;
        if d1.abs().max(d2.abs()) < 1e-15 {
            break;
        }
    }
    let f = g(r1, r2);
    assert!(f[0].abs().max(f[1].abs()) < 1e-9 * EA, "{f:?}");
    (r1, r2)
}

#[test]
fn a_pressurised_2d_ring_grows_to_its_closed_form_radii() {
    // 16 cells between radii 1 m and 1.2 m; 350 N/m on the inner boundary.
    let (n, a, b, p) = (16, 1.0, 1.2, 350.0);
    let mut body = ring(n, a, b, p);
    body.newton.tolerance = 1e-12;
    let steps = 3;
    let mut newton = NewtonEquilibrium::new(&body).unwrap();
    for step in 1..=steps {
        let state = newton.solve_step(&body, step, steps).unwrap();
        let (r1, r2) = ring_closed_form(n, a, b, p * step as f64 / steps as f64);
        let r = radii(&body, &state.displacements);
        for (node, &r) in r.iter().enumerate() {
            let expected = if node < n { r1 } else { r2 };
            assert!(
                (r - expected).abs() <= 1e-9 * expected,
                "step {step} node {}: r = {r}, closed form {expected}",
                node + 1
            );
        }
        if step == steps {
            assert!(r1 > 1.1 * a, "{r1}");
            println!("ring radii {r1} {r2}, history {:?}", state.residual_history);
            // Quadratic with the load stiffness (a closed loop: the tangent is exact).
            for w in state.residual_history.windows(2) {
                if w[0] < 1e-3 && w[1] > 0.0 {
                    assert!(w[1] <= 10.0 * w[0] * w[0], "{:?}", state.residual_history);
                }
            }
        }
    }
}

/// Relative residuals of one step of a soft box lattice (0.3 × 0.2 × 0.1 m) held at x = 0 and
/// bent by a pressure on its end face x = 0.3 that turns with the face, with or without the
/// load stiffness. An open surface: the skew part of the load stiffness at the face's rim is
/// left out of the tangent.
fn open_face_history(load_stiffness: bool) -> (Vec<f64>, Vec<Vector3<f64>>) {
    use linkage::linkage::{chosen_patches, generators::box_lattice};
    let g = box_lattice([0.3, 0.2, 0.1], [6, 4, 2]).unwrap();
    let mut body = Body::from_geometry("box", g, Material::new("foam", 1e6, 1e-4));
    for (node, x) in body.nodes.clone().iter().enumerate() {
        if x.x < 1e-12 {
            body.supports.push(Support::fixed(node, [true, true, true]));
        }
    }
    let end: Vec<bool> = body.nodes.iter().map(|x| x.x > 0.3 - 1e-12).collect();
    body.pressures.push(Pressure {
        pressure: -4000.0, // a suction pulling the end face along +x, then round as it turns
        faces: PressureFaces::Patches(chosen_patches(&body, &end)),
        schedule: Schedule::Linear,
    });
    // And a shear on the end face's nodes, so that the face turns.
    for (node, on) in end.iter().enumerate() {
        if *on {
            body.loads.push(linkage::linkage::NodalLoad {
                node,
                force: Vector3::new(0.0, -1.5, 0.0),
                schedule: Schedule::Linear,
            });
        }
    }
    body.kinematics = Kinematics::Large;
    body.newton.tolerance = 1e-10;
    body.newton.max_iterations = 60;
    body.newton.load_stiffness = load_stiffness;
    let mut newton = NewtonEquilibrium::new(&body).unwrap();
    let state = newton.solve_step(&body, 1, 1).unwrap();
    assert_eq!(state.cuts, 0, "{:?}", state.residual_history);
    (state.residual_history, state.displacements)
}

#[test]
fn on_an_open_face_the_tangent_leaves_the_load_stiffness_out_and_newton_converges_linearly() {
    // The skew part at the face's rim acts on free DOFs: the symmetric part alone (measured
    // here before this rule: a residual stalling near 2e-5 for 12 iterations, 28 in all) is
    // not taken, and Newton runs as without load stiffness, linearly (19 iterations).
    let (with, u_with) = open_face_history(true);
    let (without, u_without) = open_face_history(false);
    println!("open face, with load stiffness on: {with:?}");
    println!("open face, without load stiffness: {without:?}");
    assert_eq!(with, without);
    // Large: the end moves by more than 8% of the length.
    let largest = u_with.iter().map(|u| u.norm()).fold(0.0, f64::max);
    assert!(largest > 0.025, "{largest}");
    assert_eq!(u_with, u_without);
    assert!(*with.last().unwrap() <= 1e-10);
    // Linear: once below 1e-4, each residual is between 0.1 and 0.9 of the one before.
    for w in with.windows(2).filter(|w| w[0] < 1e-4) {
        assert!(w[1] > 0.1 * w[0] && w[1] < 0.9 * w[0], "{with:?}");
    }
}
