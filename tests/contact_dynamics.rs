//! Contact in time (issue 31, item 4): the contact solver takes each body's inertia term
//! ([`InertiaTerm`]) and solves `f_int(y) + c M (y − y*) + f_contact(y) = f_ext` in one time
//! step. Each test runs a small hand-written midpoint (trapezoidal) time loop over
//! [`ContactSolver::solve_time_step`] ([`Midpoint`]); the `dyn` branch's integrators will
//! replace it. Every closed form is checked with its tolerance stated where it is used.

use linkage::contact::{
    ContactSettings, ContactSolver, ContactStep, FrictionSettings, Obstacle, ObstacleShape,
};
use linkage::linkage::dynamics::InertiaTerm;
use linkage::linkage::{
    member_stiffnesses, Body, Dimension, Material, Member, NodalLoad, Schedule,
};
use nalgebra::Vector3;

/// The midpoint rule as the contact solver sees it: per step the solver finds the midpoint
/// `y = (u_n + u_{n+1})/2` with `c = 4/h²` and predictor `u_n + h v_n / 2`; then
/// `u_{n+1} = 2y − u_n` and `v_{n+1} = 2(u_{n+1} − u_n)/h − v_n`. (A stand-in for the `dyn`
/// branch's trapezoidal integrator, which will replace it.)
struct Midpoint {
    /// Time step, s.
    h: f64,
    /// Per body, lumped mass per DOF, kg.
    mass: Vec<Vec<f64>>,
    /// Per body, displacement per DOF at the step's start, m.
    u: Vec<Vec<f64>>,
    /// Per body, velocity per DOF at the step's start, m/s.
    v: Vec<Vec<f64>>,
}

impl Midpoint {
    /// Bodies at rest in their undeformed state with `mass` (per body DOF, kg), moving at
    /// `velocity[b]` (m/s, every node of body b).
    fn new(h: f64, bodies: &[Body], mass: Vec<Vec<f64>>, velocity: &[Vector3<f64>]) -> Self {
        let v = bodies
            .iter()
            .zip(velocity)
            .map(|(b, w)| {
                let d = b.dimension.dofs_per_node();
                (0..b.dof_count()).map(|i| w[i % d]).collect()
            })
            .collect();
        let u = bodies.iter().map(|b| vec![0.0; b.dof_count()]).collect();
        Midpoint { h, mass, u, v }
    }

    /// One time step (loads at full value, obstacles fixed): the solver's report at the
    /// midpoint.
    fn step(
        &mut self,
        solver: &mut ContactSolver,
        bodies: &[Body],
        obstacles: &[Obstacle],
    ) -> ContactStep {
        let c = 4.0 / (self.h * self.h);
        let inertia: Vec<InertiaTerm> = (0..bodies.len())
            .map(|b| InertiaTerm {
                mass: self.mass[b].clone(),
                coefficient: c,
                predictor: self.u[b]
                    .iter()
                    .zip(&self.v[b])
                    .map(|(u, v)| u + 0.5 * self.h * v)
                    .collect(),
            })
            .collect();
        let out = solver
            .solve_time_step(bodies, obstacles, 1.0, 1, &inertia)
            .expect("the time step solves");
        for (b, body) in bodies.iter().enumerate() {
            let d = body.dimension.dofs_per_node();
            for (node, y) in out.states[b].displacements.iter().enumerate() {
                for k in 0..d {
                    let i = node * d + k;
                    let u1 = 2.0 * y[k] - self.u[b][i];
                    self.v[b][i] = 2.0 * (u1 - self.u[b][i]) / self.h - self.v[b][i];
                    self.u[b][i] = u1;
                }
            }
        }
        out
    }

    /// Kinetic energy of body `b`, J.
    fn kinetic(&self, b: usize) -> f64 {
        0.5 * self.mass[b]
            .iter()
            .zip(&self.v[b])
            .map(|(m, v)| m * v * v)
            .sum::<f64>()
    }

    /// Mean velocity of body `b` along `k` (momentum over mass), m/s.
    fn mean_velocity(&self, b: usize, k: usize, d: usize) -> f64 {
        let (mut p, mut m) = (0.0, 0.0);
        for (i, (mi, vi)) in self.mass[b].iter().zip(&self.v[b]).enumerate() {
            if i % d == k {
                p += mi * vi;
                m += mi;
            }
        }
        p / m
    }

    /// Linear momentum of all bodies along `k`, kg m/s.
    fn momentum(&self, k: usize, d: usize) -> f64 {
        let mut p = 0.0;
        for (m, v) in self.mass.iter().zip(&self.v) {
            for (i, (mi, vi)) in m.iter().zip(v).enumerate() {
                if i % d == k {
                    p += mi * vi;
                }
            }
        }
        p
    }
}

/// Strain energy of a linear body at `u`, J: `Σ ½ (E A / L) (n·(u_b − u_a))²`.
fn strain_energy(body: &Body, u: &[f64]) -> f64 {
    let d = body.dimension.dofs_per_node();
    let k = member_stiffnesses(body);
    body.members
        .iter()
        .zip(&k)
        .map(|(m, k)| {
            let [a, b] = m.nodes;
            let n = (body.nodes[b] - body.nodes[a]).normalize();
            let s: f64 = (0..d).map(|q| n[q] * (u[b * d + q] - u[a * d + q])).sum();
            0.5 * k * s * s
        })
        .sum()
}

/// A 2D strip along x: two rails (`members` members each, `length` m long, `width` m apart)
/// of material "rail" (E = 1e9 Pa, A = 1e-4 m²), and a web of rungs and crossed braces of
/// material "web" (1/1000 of the rails' modulus) that holds the strip's shape. The rails alone
/// carry mass (`RHO`); the web is massless, so the strip is a 1D bar of wave speed
/// `c = √(E/ρ)` with a 2D contact surface. Starts at `x0` (m).
fn strip(name: &str, members: usize, length: f64, width: f64, x0: f64) -> Body {
    let mut body = Body::new(name, Dimension::Two);
    body.materials.push(Material::new("rail", E, AREA));
    body.materials.push(Material::new("web", E * 1e-3, AREA));
    let l = length / members as f64;
    for i in 0..=members {
        body.nodes.push(Vector3::new(x0 + i as f64 * l, 0.0, 0.0));
        body.nodes.push(Vector3::new(x0 + i as f64 * l, width, 0.0));
    }
    let member = |a: usize, b: usize, material: usize| Member {
        nodes: [a, b],
        material,
    };
    for i in 0..=members {
        body.members.push(member(2 * i, 2 * i + 1, 1));
        if i < members {
            body.members.push(member(2 * i, 2 * i + 2, 0));
            body.members.push(member(2 * i + 1, 2 * i + 3, 0));
            body.members.push(member(2 * i, 2 * i + 3, 1));
            body.members.push(member(2 * i + 1, 2 * i + 2, 1));
        }
    }
    body
}

/// `body` (a [`strip`]) with its rails moved apart by `by` (m) on either side: the same bar
/// (rails, masses and lengths unchanged), with a back face that reaches past the front
/// nodes of an equal strip striking it (a node on the line of a face's side is not in it).
fn widened(mut body: Body, by: f64) -> Body {
    for (i, p) in body.nodes.iter_mut().enumerate() {
        p.y += if i % 2 == 0 { -by } else { by };
    }
    body
}

/// Lumped mass per DOF of `body`, kg: `ρ A L / 2` to each end of its members of material 0
/// (the rails); material 1 (the web) is massless.
fn rail_mass(body: &Body) -> Vec<f64> {
    let d = body.dimension.dofs_per_node();
    let mut m = vec![0.0; body.dof_count()];
    for (i, member) in body.members.iter().enumerate() {
        if member.material != 0 {
            continue;
        }
        let half = 0.5 * RHO * AREA * body.member_length(i);
        for &node in &member.nodes {
            for k in 0..d {
                m[node * d + k] += half;
            }
        }
    }
    m
}

const E: f64 = 1e9;
const AREA: f64 = 1e-4;
const RHO: f64 = 1000.0;

/// A rigid wall at x = 0 (bodies on x > 0).
fn wall() -> Obstacle {
    Obstacle {
        name: "wall".to_string(),
        shape: ObstacleShape::HalfSpace {
            point: Vector3::zeros(),
            normal: Vector3::new(1.0, 0.0, 0.0),
        },
        travel: Vector3::zeros(),
        schedule: Schedule::Linear,
    }
}

/// The penalty of the strips: 5 times a rail member's `E A / l`, so that a front node on the
/// penalty spring (`ω = √(k/m)`, `m = ρ A l / 2`) is resolved by the time step of a quarter
/// of a member's transit time (`ω h = 0.79`). The default (100 times the mean `E A / L`,
/// `ω h ≈ 3.5` on the rails) is not: the front nodes then chatter on the wall, coming in
/// and out of contact within steps, and each such step creates penalty energy (the bar left
/// with 3.9 times the energy it came with).
fn strip_settings(l: f64) -> ContactSettings {
    ContactSettings {
        penalty: Some(5.0 * E * AREA / l),
        ..ContactSettings::default()
    }
}

#[test]
fn a_bar_striking_a_wall_stays_in_contact_2l_over_c_and_rebounds_at_its_speed() {
    // 100 members per rail, L = 1 m, c = √(E/ρ) = 1000 m/s: contact lasts 2L/c = 2 ms.
    let (members, length, width) = (100, 1.0, 0.01);
    let l = length / members as f64;
    let v0 = 1.0;
    let c = (E / RHO).sqrt();
    let h = 0.25 * l / c;
    let gap = 2.5 * v0 * h;
    let bodies = [strip("bar", members, length, width, gap)];
    let obstacles = [wall()];
    let mut solver = ContactSolver::dynamic(&bodies, &obstacles, strip_settings(l)).unwrap();
    let mut time = Midpoint::new(
        h,
        &bodies,
        vec![rail_mass(&bodies[0])],
        &[Vector3::new(-v0, 0.0, 0.0)],
    );
    let energy = |t: &Midpoint| t.kinetic(0) + strain_energy(&bodies[0], &t.u[0]);
    let before = energy(&time);
    let tolerance = 0.01 * l;
    let (mut first, mut last) = (None, None);
    let steps = ((2.0 * length / c + 4.0 * gap / v0) / h) as usize;
    for n in 0..steps {
        let out = time.step(&mut solver, &bodies, &obstacles);
        if out.contacts[0].iter().any(|c| c.normal_force > 0.0) {
            first.get_or_insert(n);
            last = Some(n);
        }
        // No node passes the wall within a step: at the step's end every node is at most the
        // penetration tolerance (1% of a member) inside it.
        for (node, p) in bodies[0].nodes.iter().enumerate() {
            let x = p.x + time.u[0][2 * node];
            assert!(x > -tolerance, "step {n}: node {} at x = {x:e} m", node + 1);
        }
    }
    let (first, last) = (first.unwrap(), last.unwrap());
    // The midpoint of step n lies at (n + ½) h; contact from the first to the last step whose
    // midpoint touches, within a step at each end.
    let contact_time = (last - first + 1) as f64 * h;
    let expected = 2.0 * length / c;
    assert!(
        (contact_time - expected).abs() < 0.03 * expected,
        "contact {contact_time:e} s against 2L/c = {expected:e} s"
    );
    let rebound = time.mean_velocity(0, 0, 2);
    eprintln!(
        "wall: contact {contact_time:e} s (2L/c {expected:e} s), rebound {rebound} m/s, energy {before:e} -> {:e} J",
        energy(&time)
    );
    assert!(rebound >= 0.98 * v0, "rebound {rebound} m/s");
    let after = energy(&time);
    assert!(
        (after - before).abs() < 1e-3 * before,
        "energy {before:e} J before, {after:e} J after"
    );
}

#[test]
fn two_equal_bars_colliding_head_on_exchange_their_velocities_and_keep_their_momentum() {
    // Bar 1 moves at v0 onto bar 2 at rest: after 2L/c bar 1 stops and bar 2 moves at v0.
    let (members, length, width) = (100, 1.0, 0.01);
    let l = length / members as f64;
    let v0 = 1.0;
    let c = (E / RHO).sqrt();
    let h = 0.25 * l / c;
    let gap = 2.5 * v0 * h;
    let bodies = [
        strip("left", members, length, width, 0.0),
        widened(
            strip("right", members, length, width, length + gap),
            0.1 * width,
        ),
    ];
    let mut solver = ContactSolver::dynamic(&bodies, &[], strip_settings(l)).unwrap();
    let mut time = Midpoint::new(
        h,
        &bodies,
        bodies.iter().map(rail_mass).collect(),
        &[Vector3::new(v0, 0.0, 0.0), Vector3::zeros()],
    );
    let momentum = time.momentum(0, 2);
    let energy = |t: &Midpoint| {
        (0..2)
            .map(|b| t.kinetic(b) + strain_energy(&bodies[b], &t.u[b]))
            .sum::<f64>()
    };
    let before = energy(&time);
    let steps = ((2.0 * length / c + 4.0 * gap / v0) / h) as usize;
    let mut touched = 0;
    for n in 0..steps {
        let out = time.step(&mut solver, &bodies, &[]);
        touched += usize::from(!out.contacts[0].is_empty());
        // Linear momentum is kept to the Newton tolerance: 1e-9 of the initial.
        let p = time.momentum(0, 2);
        assert!(
            (p - momentum).abs() < 1e-9 * momentum,
            "step {n}: momentum {p:e} against {momentum:e}"
        );
        // The front nodes of bar 1 never pass the back face of bar 2 by more than the
        // penetration tolerance (1% of a member).
        let front = |b: usize, node: usize| bodies[b].nodes[node].x + time.u[b][2 * node];
        for k in 0..2 {
            let passed = front(0, 2 * members + k) - front(1, k);
            assert!(passed < 0.01 * l, "step {n}: passed by {passed:e} m");
        }
    }
    assert!(touched > 0, "the bars never touched");
    let (v1, v2) = (time.mean_velocity(0, 0, 2), time.mean_velocity(1, 0, 2));
    eprintln!(
        "bars: v1 {v1:e} m/s, v2 {v2} m/s, momentum {:e} of {momentum:e}, energy {before:e} -> {:e} J",
        time.momentum(0, 2) - momentum,
        energy(&time)
    );
    assert!(v1.abs() < 0.02 * v0, "bar 1 left at {v1} m/s");
    assert!((v2 - v0).abs() < 0.02 * v0, "bar 2 left at {v2} m/s");
    // Energy is exact while the contact set holds within each step (the penalty is quadratic
    // against a plane); a step within which a node comes into or out of contact errs by at
    // most the node's penalty energy over it, ½ k (v0 h)²: allowed twice for each of the two
    // front nodes (in and out).
    let after = energy(&time);
    let k = 5.0 * E * AREA / l;
    let allowed = 4.0 * 0.5 * k * (v0 * h).powi(2);
    assert!(
        (after - before).abs() < allowed,
        "energy {before:e} J before, {after:e} J after (allowed {allowed:e} J)"
    );
}

/// A block (a 2D square of 4 nodes and 6 members, 0.1 m, steel-like) resting on a slope of
/// `angle` (rad) through the origin, its bottom nodes at the depth where the penalty carries
/// its weight's normal part; gravity (9.81 m/s²) as nodal loads; friction μ = `mu` with the
/// default stick stiffness. Returns the displacement of its centre of mass along the slope
/// (down positive, m) after `duration` s, and its mean velocity there (m/s).
fn block_on_slope(angle: f64, mu: f64, duration: f64) -> (f64, f64) {
    let (side, g, mass) = (0.1, 9.81, 1.0);
    let (s, c) = angle.sin_cos();
    // Along the slope (down-hill: −t) and its outward normal n.
    let t = Vector3::new(c, s, 0.0);
    let n = Vector3::new(-s, c, 0.0);
    // The penalty resolved by the time step: ω h = √(k / (m/4)) h = 0.063.
    let k = 1e5;
    // Each bottom node carries half the weight's normal part: depth m g cos θ / (2 k).
    let depth = mass * g * c / (2.0 * k);
    let corner = -n * depth;
    let mut body = Body::new("block", Dimension::Two);
    body.materials.push(Material::new("steel", 2e11, 1e-4));
    body.nodes = vec![
        corner,
        corner + t * side,
        corner + t * side + n * side,
        corner + n * side,
    ];
    for (a, b) in [(0, 1), (1, 2), (2, 3), (3, 0), (0, 2), (1, 3)] {
        body.members.push(Member {
            nodes: [a, b],
            material: 0,
        });
    }
    for node in 0..4 {
        body.loads.push(NodalLoad {
            node,
            force: Vector3::new(0.0, -mass * g / 4.0, 0.0),
            schedule: Schedule::Linear,
        });
    }
    let slope = Obstacle {
        name: "slope".to_string(),
        shape: ObstacleShape::HalfSpace {
            point: Vector3::zeros(),
            normal: n,
        },
        travel: Vector3::zeros(),
        schedule: Schedule::Linear,
    };
    let settings = ContactSettings {
        penalty: Some(k),
        // Stick stiffness: the block starts sticking and slides once its elastic slip
        // reaches μ f_N / k_t, about a quarter period of a node on that spring
        // (`π/2 · √(m / 4 k_t)`) later; friction falls short of μ f_N until then. With the
        // default (the penalty, 1e5 N/m) that is 2.5 ms, and the block slid 1.6% fast over
        // 0.2 s; with 1e7 N/m it is 0.25 ms (0.1%). The time step resolves that spring
        // (ω h = 0.63): with 1e8 N/m and h = 1 ms (ω h = 20) its alias oscillation tore the
        // μ = 0.6 block loose (it slid at μ f_N).
        friction: FrictionSettings {
            coefficient: mu,
            stick_stiffness: Some(1e7),
            ..FrictionSettings::default()
        },
        ..ContactSettings::default()
    };
    let bodies = [body];
    let obstacles = [slope];
    let mut solver = ContactSolver::dynamic(&bodies, &obstacles, settings).unwrap();
    let h = 1e-4;
    let mut time = Midpoint::new(h, &bodies, vec![vec![mass / 4.0; 8]], &[Vector3::zeros()]);
    let steps = (duration / h).round() as usize;
    for step in 0..steps {
        let out = time.step(&mut solver, &bodies, &obstacles);
        for (node, p) in bodies[0].nodes.iter().enumerate() {
            let x = p + Vector3::new(time.u[0][2 * node], time.u[0][2 * node + 1], 0.0);
            // No node passes the slope's surface by more than 1% of the block's side.
            assert!(x.dot(&n) > -1e-3, "step {step}: node {} at {x:?}", node + 1);
        }
        // The block may rock (friction's moment at its base comes at once, and nothing damps
        // it), but it never leaves the slope.
        assert!(
            !out.contacts[0].is_empty(),
            "step {step}: the block left the slope"
        );
    }
    let along = |values: &[f64]| -> f64 {
        (0..4)
            .map(|node| -(values[2 * node] * t.x + values[2 * node + 1] * t.y) / 4.0)
            .sum()
    };
    (along(&time.u[0]), along(&time.v[0]))
}

#[test]
fn a_block_on_a_slope_slides_at_g_sin_minus_mu_cos_and_sticks_when_mu_holds_it() {
    let angle = 30f64.to_radians();
    let g = 9.81;
    let duration = 0.2;
    // μ = 0.3 < tan 30°: it slides at a = g (sin θ − μ cos θ) = 2.356 m/s², within 1%.
    let a = g * (angle.sin() - 0.3 * angle.cos());
    let (x, v) = block_on_slope(angle, 0.3, duration);
    let from_speed = v / duration;
    let from_distance = 2.0 * x / (duration * duration);
    eprintln!("slope: a {from_speed} (speed), {from_distance} (distance) m/s² against {a}");
    assert!(
        (from_speed - a).abs() < 0.01 * a,
        "{from_speed} m/s² against {a}"
    );
    assert!(
        (from_distance - a).abs() < 0.01 * a,
        "{from_distance} m/s² against {a}"
    );
    // μ = 0.6 > tan 30° = 0.577: it stays within 1 mm.
    let (x, _) = block_on_slope(angle, 0.6, duration);
    eprintln!("slope μ = 0.6: moved {x:e} m");
    assert!(x.abs() < 1e-3, "moved {x:e} m");
}
