//! Every pair of features together (issue 32, combination 6; the table "Features together" in
//! `docs/SCENES.md`): one test per pair, on a scene of a few nodes written here, its answer
//! checked against a closed form, a symmetry, or the single-feature path with the other feature
//! switched off. Tolerances are stated where they are used.
//!
//! The scenes:
//! - the *vee*: node 1 at the origin hanging from nodes 2–4 at (−1, 1), (0, 1), (1, 1) (all
//!   held) by the diagonals 1–2 and 1–4 (material `steel`) and the post 1–3 (material `post`),
//!   with the members 2–3 and 3–4 between held nodes (they carry nothing, but close the
//!   triangles that make 1–2 and 1–4 boundary segments for a pressure). E A = 2e7 N for every
//!   member: at node 1 the diagonals give `K_d = E A/√2` along x and along y, with no coupling,
//!   and the post `E A` along y. A pressure p (N/m) on nodes 1, 2, 4 pushes node 1 up by p.
//! - the *hairpin*: one body, a lower arm and an upper arm joined by a web at their left end,
//!   the upper arm's end pushed down 15 mm onto the lower arm across a 1 cm gap (`[contact]
//!   self = true`). (A 2D body's contact surface is its one outer boundary loop: two separate
//!   pieces of one unbroken body do not touch each other, so the pair is shown on one piece.)
//! - the von Mises truss of `scenes/von_mises.*` (half span 1 m, rise 0.1 m) with its closed
//!   form P(w), and a hanging chain of four members (2 m) under its own weight.

use linkage::scene::{
    build_world_with, expand_sweep, run_in_memory, BodyResult, InlineFiles, StepResult, Summary,
};
use std::path::{Path, PathBuf};

const EA: f64 = 2e7;
/// The diagonals' stiffness at node 1 of the vee, N/m, along x and along y.
fn kd() -> f64 {
    EA / 2f64.sqrt()
}

// ---------------------------------------------------------------- running scenes

struct Run {
    summary: Summary,
    steps: Vec<StepResult>,
}

impl Run {
    /// Body `b` at the last step.
    fn last(&self, b: usize) -> &BodyResult {
        &self.steps.last().unwrap().bodies[b]
    }
    /// Displacement of 1-based `node` of body `b` at the last step.
    fn u(&self, b: usize, node: usize) -> Vec<f64> {
        self.last(b).displacements[node - 1].clone()
    }
}

fn folder() -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join("feature_pairs")
}

fn held(files: &[(&str, &str)]) -> InlineFiles {
    let mut h = InlineFiles::default();
    for (name, text) in files {
        h.insert(folder().join(name), text.to_string());
    }
    h
}

/// Build and solve `text` (its files held in memory); the error's text when it is refused or
/// a step fails.
fn try_run_at(text: &str, files: &[(&str, &str)], file: &str) -> Result<Run, String> {
    let world =
        build_world_with(text, &folder().join(file), &held(files)).map_err(|e| format!("{e:#}"))?;
    let (summary, steps, failure) = run_in_memory(&world, &|| {}).map_err(|e| format!("{e:#}"))?;
    match failure {
        Some(e) => Err(format!("{e:#}")),
        None => Ok(Run { summary, steps }),
    }
}

fn try_run(text: &str, files: &[(&str, &str)]) -> Result<Run, String> {
    try_run_at(text, files, "scene.toml")
}

fn run(text: &str, files: &[(&str, &str)]) -> Run {
    try_run(text, files).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

/// Two runs with the same results, bit for bit (the summaries without their timings).
fn assert_same(a: &Run, b: &Run) {
    assert_eq!(a.steps, b.steps);
    let untimed = |s: &Summary| {
        let mut steps = s.steps.clone();
        for st in &mut steps {
            st.seconds = 0.0;
        }
        steps
    };
    assert_eq!(untimed(&a.summary), untimed(&b.summary));
    assert_eq!(a.summary.breaks, b.summary.breaks);
    assert_eq!(a.summary.collapse, b.summary.collapse);
    assert_eq!(a.summary.bodies, b.summary.bodies);
}

/// The scene `make(values[0])` with `[sweep] key = values`: every variant gives the results of
/// the scene written by hand with its value (bit for bit), and the values matter (the first
/// two variants differ). The hand-written runs, in order.
fn sweep_equals_single_runs(
    make: &dyn Fn(&str) -> String,
    files: &[(&str, &str)],
    key: &str,
    values: &[&str],
) -> Vec<Run> {
    let text = format!(
        "{}\n[sweep]\n\"{key}\" = [{}]\n",
        make(values[0]),
        values.join(", ")
    );
    let path = folder().join("sweep.toml");
    let variants = expand_sweep(&text, &path).unwrap_or_else(|e| panic!("{e:#}"));
    assert_eq!(variants.len(), values.len());
    let mut hands = Vec::new();
    for (variant, value) in variants.iter().zip(values) {
        let swept = try_run_at(&variant.text, files, "sweep.toml")
            .unwrap_or_else(|e| panic!("variant {value}: {e}"));
        let hand = run(&make(value), files);
        assert_same(&swept, &hand);
        hands.push(hand);
    }
    assert_ne!(
        hands[0].steps, hands[1].steps,
        "the swept value changes nothing"
    );
    hands
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs().max(1e-300)
}

fn assert_close(what: &str, a: f64, b: f64, rel: f64) {
    assert!(close(a, b, rel), "{what}: {a} against {b} (rel {rel})");
}

// ---------------------------------------------------------------- the vee

const VEE_NODES: &str = "0 0\n-1 1\n0 1\n1 1\n";
const VEE_LINKS: &str = "1 2\n1 3 post\n1 4\n2 3\n3 4\n";

fn vee_files() -> [(&'static str, &'static str); 2] {
    [("vee.nodes", VEE_NODES), ("vee.links", VEE_LINKS)]
}

/// The vee over `steps` steps: `head` top-level lines, `steel` and `post` extra material lines,
/// `body` extra body lines (before its supports), `tail` tables after them.
fn vee(steps: usize, head: &str, steel: &str, post: &str, body: &str, tail: &str) -> String {
    format!(
        r#"name = "vee"
steps = {steps}
{head}
[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4
{steel}
[[materials]]
name = "post"
youngs_modulus = 200e9
area = 1e-4
{post}
[[bodies]]
name = "vee"
nodes = "vee.nodes"
links = "vee.links"
material = "steel"
{body}
[[bodies.supports]]
nodes = [2, 3, 4]
fix = ["x", "y"]
{tail}"#
    )
}

fn load_at_1(fy: f64) -> String {
    format!("[[bodies.loads]]\nnodes = [1]\nforce = [0.0, {fy:?}]\n")
}

fn pressure(p: f64) -> String {
    format!("[[bodies.pressures]]\nnodes = [1, 2, 4]\npressure = {p:?}\n")
}

/// A half-space 1 mm below node 1 moved by `travel` over the steps, penalty 1e9 N/m, and the
/// `[contact]` lines `contact`.
fn floor(travel: &str, contact: &str) -> String {
    format!(
        r#"[[obstacles]]
name = "floor"
shape = "half_space"
point = [0.0, -0.001]
normal = [0.0, 1.0]
travel = {travel}
[contact]
penalty = 1e9
{contact}
"#
    )
}

const K: f64 = 1e9;
/// The floor's rise past node 1 at the end: travel 3 mm minus the gap of 1 mm.
const DELTA: f64 = 0.002;

/// A vee's contact entries at the last step, and the one of node 1.
fn contact_of_node_1(r: &Run) -> linkage::scene::ContactForce {
    let c = &r.last(0).contacts;
    assert_eq!(c.len(), 1, "{c:?}");
    assert_eq!(c[0].node, 1);
    c[0].clone()
}

/// A sliding contact obeys Coulomb: it slips with |f_T| = μ f_N (1e-9), f_N = k depth (1e-9).
fn assert_slips_at_coulomb(c: &linkage::scene::ContactForce, mu: f64) {
    assert_eq!(c.state, "slip", "{c:?}");
    let ft = c.tangential_force.iter().map(|f| f * f).sum::<f64>().sqrt();
    assert_close("|f_T| = μ f_N", ft, mu * c.normal_force, 1e-9);
    assert_close("f_N = k depth", c.normal_force, K * c.depth, 1e-9);
}

// ---------------------------------------------------------------- Softening teeth by hand

/// The post's material: tensile strength 20 MPa (ε₀ = 1e-4), two teeth with h = 1e-4, so
/// tooth 2 has σ₁ = 10 MPa at ε₁ = 2e-4 and E₁ = 5e10 Pa; the energy (post length 1 m)
/// `G_f = ½ (E − E₁) ε₀² + ½ E₁ ε₁² = 750 + 1000 = 1750 J/m²`.
const SOFT_POST: &str =
    "tensile_strength = 20e6\nfailure = \"break\"\nsoftening = { fracture_energy = 1750.0, teeth = 2 }";
const FT_A: f64 = 20e6 * 1e-4;
const SIGMA1_A: f64 = 10e6 * 1e-4;
const E1: f64 = 5e10;
/// The share of node 1's vertical load the post carries, intact and at tooth 2.
fn shares() -> (f64, f64) {
    (EA / (EA + kd()), E1 * 1e-4 / (E1 * 1e-4 + kd()))
}

/// The summary's events of a softening post (member 2) loaded at node 1 along y by `P` (N,
/// the post in tension) plus the dead load `dead` (N, same sense): tooth 1 at
/// `(f_t A/s₀ − dead)/P`, the break at `(σ₁ A/s₁ − dead)/P`, both to 1e-8.
fn assert_teeth(summary: &Summary, p: f64, dead: f64) {
    let (s0, s1) = shares();
    let b = &summary.breaks;
    assert_eq!(b.len(), 2, "{b:?}");
    assert_eq!((b[0].member, b[0].tooth), (2, Some(1)), "{b:?}");
    assert_eq!((b[1].member, b[1].tooth), (2, None), "{b:?}");
    assert_close("tooth 1", b[0].load_factor, (FT_A / s0 - dead) / p, 1e-8);
    assert_close("break", b[1].load_factor, (SIGMA1_A / s1 - dead) / p, 1e-8);
}

// ---------------------------------------------------------------- the hairpin

/// The hairpin's nodes: a lower arm of three 1 m cells (nodes 1–4 at y = 0, 5–8 at y = 1), a
/// web cell 1 cm high at its left end (nodes 5, 6, 9, 10) and an upper arm over it (nodes 9–12
/// at y = 1.01, 13–16 at y = 2.01; its last cell 0.5 m wide), so the upper arm's lower right
/// corner, node 12 at (2.5, 1.01), is 1 cm above the middle of the lower arm's top segment
/// 7–8. Its outer boundary is one loop through every node (the gap is outside the body).
const HAIRPIN_NODES: &str = "0 0\n1 0\n2 0\n3 0\n0 1\n1 1\n2 1\n3 1\n\
0 1.01\n1 1.01\n2 1.01\n2.5 1.01\n0 2.01\n1 2.01\n2 2.01\n2.5 2.01\n";

/// The hairpin's members: each cell's sides and diagonals (a side shared by two cells once),
/// with the lower arm's inner post 3–7 last, of `post` material ("" for none: left out).
fn hairpin_links(post: Option<&str>) -> String {
    let cells = [
        [1, 2, 6, 5],
        [2, 3, 7, 6],
        [3, 4, 8, 7],
        [5, 6, 10, 9],
        [9, 10, 14, 13],
        [10, 11, 15, 14],
        [11, 12, 16, 15],
    ];
    let mut links: Vec<(usize, usize)> = Vec::new();
    for [a, b, c, d] in cells {
        for (p, q) in [(a, b), (b, c), (d, c), (a, d), (a, c), (b, d)] {
            let key = (p.min(q), p.max(q));
            if key != (3, 7) && !links.contains(&key) {
                links.push(key);
            }
        }
    }
    let mut text: String = links.iter().map(|(p, q)| format!("{p} {q}\n")).collect();
    if let Some(material) = post {
        text.push_str(&format!("3 7 {material}\n"));
    }
    text
}

fn hairpin_files() -> Vec<(&'static str, String)> {
    vec![
        ("hairpin.nodes", HAIRPIN_NODES.to_string()),
        ("hairpin.links", hairpin_links(Some("steel"))),
        ("cable.links", hairpin_links(Some("cable"))),
        ("nopost.links", hairpin_links(None)),
    ]
}

fn refs<'a>(files: &'a [(&'static str, String)]) -> Vec<(&'static str, &'a str)> {
    files.iter().map(|(n, t)| (*n, t.as_str())).collect()
}

/// The hairpin with self-contact, held at its base (nodes 1–4), the upper arm's end nodes
/// 15 and 16 moved by `(dx, −15 mm)` over 4 steps, penalty 1e9 N/m; `links` its links file,
/// `body` extra body lines, `head` top-level lines, `contact` extra `[contact]` lines.
fn hairpin(links: &str, dx: f64, body: &str, head: &str, contact: &str) -> String {
    format!(
        r#"name = "hairpin"
steps = 4
{head}
[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4
density = 7850.0
[[materials]]
name = "cable"
youngs_modulus = 200e9
area = 1e-4
behaviour = "tension_only"
[[bodies]]
name = "hairpin"
nodes = "hairpin.nodes"
links = "{links}"
material = "steel"
{body}
[[bodies.supports]]
nodes = [1, 2, 3, 4]
fix = ["x", "y"]
[[bodies.supports]]
nodes = [15, 16]
fix = ["x", "y"]
displacement = [{dx:?}, -0.015]
[contact]
penalty = 1e9
self = true
{contact}
"#
    )
}

/// The hairpin's contacts at the last step: at least one, every one the body on itself,
/// pressing (over 1 kN) and less than 1 mm deep (the gap is 1 cm: a corner that passed
/// through would be 5 mm deep).
fn assert_touches_itself(r: &Run) -> Vec<linkage::scene::ContactForce> {
    let c = r.last(0).contacts.clone();
    assert!(!c.is_empty(), "the upper arm reaches the lower one");
    for x in &c {
        assert_eq!(x.with, "hairpin", "{x:?}");
        assert!(x.depth < 1e-3 && x.normal_force > 1e3, "{x:?}");
    }
    c
}

/// Two runs of the hairpin with the same displacements to `rel` of the largest.
fn assert_same_hairpin(a: &Run, b: &Run, rel: f64) {
    let scale = b
        .last(0)
        .displacements
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    for node in 1..=16 {
        let (p, q) = (a.u(0, node), b.u(0, node));
        for d in 0..2 {
            assert!(
                (p[d] - q[d]).abs() <= rel * scale,
                "node {node}: {p:?} against {q:?}"
            );
        }
    }
}

// ---------------------------------------------------------------- the von Mises truss

const VM_NODES: &str = "-1 0\n0 0.1\n1 0\n";
const VM_LINKS: &str = "1 2\n2 3\n";

/// Closed form of the von Mises truss (E A = 2e7 N, half span 1, rise 0.1, engineering
/// strain): the downward apex load in equilibrium with the apex lowered by w.
fn von_mises_load(w: f64) -> f64 {
    let (a, h) = (1.0f64, 0.1f64);
    let l0 = (a * a + h * h).sqrt();
    let l = (a * a + (h - w) * (h - w)).sqrt();
    -2.0 * EA * (l - l0) / l0 * (h - w) / l
}

/// The von Mises truss with `extra` body lines and `tail` tables; `cable`: node 4 at (0, −0.9)
/// held, and a tension-only member from the apex down to it.
fn von_mises(steps: usize, head: &str, steel: &str, body: &str, tail: &str, cable: bool) -> String {
    let (nodes, links, held) = if cable {
        ("vmc.nodes", "vmc.links", "[1, 3, 4]")
    } else {
        ("vm.nodes", "vm.links", "[1, 3]")
    };
    format!(
        r#"name = "truss"
steps = {steps}
{head}
[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4
{steel}
[[materials]]
name = "cable"
youngs_modulus = 200e9
area = 1e-4
behaviour = "tension_only"
[[bodies]]
name = "truss"
nodes = "{nodes}"
links = "{links}"
material = "steel"
kinematics = "large"
{body}
[[bodies.supports]]
nodes = {held}
fix = ["x", "y"]
{tail}"#
    )
}

fn vm_files() -> Vec<(&'static str, String)> {
    vec![
        ("vm.nodes", VM_NODES.to_string()),
        ("vm.links", VM_LINKS.to_string()),
        ("vmc.nodes", format!("{VM_NODES}0 -0.9\n")),
        ("vmc.links", format!("{VM_LINKS}2 4 cable\n")),
    ]
}

fn apex_load(p: f64) -> String {
    format!("[[bodies.loads]]\nnodes = [2]\nforce = [0.0, {:?}]\n", -p)
}

const ARC: &str = "[bodies.path]\nmethod = \"arc_length\"\narc_length = 0.0045";

/// Every step of an arc-length run of the truss lies on the closed form with the apex load
/// `λ · reference` (1e-6 of the limit load 7622 N), and the path passes the limit point (λ
/// falls after its largest value, beyond the limit's w = 0.0423 m).
fn assert_on_the_von_mises_path(r: &Run, reference: f64) {
    let mut peak = (0.0, 0.0);
    for s in &r.steps[1..] {
        let w = -s.bodies[0].displacements[1][1];
        let lambda = s.load_factor;
        assert!(
            (lambda * reference - von_mises_load(w)).abs() <= 1e-6 * 7622.0,
            "step {}: w = {w}, λ·P = {}, P(w) = {}",
            s.step,
            lambda * reference,
            von_mises_load(w)
        );
        if lambda > peak.1 {
            peak = (w, lambda);
        }
    }
    let last = r.steps.last().unwrap();
    assert!(
        last.load_factor < peak.1 && -last.bodies[0].displacements[1][1] > 0.0423,
        "past the limit point: peak {peak:?}, last λ {}",
        last.load_factor
    );
}

// ---------------------------------------------------------------- the hanging chain

const CHAIN_NODES: &str = "0 0\n0 -0.5\n0 -1\n0 -1.5\n0 -2\n";
const CHAIN_LINKS: &str = "1 2\n2 3\n3 4\n4 5\n";

fn chain_files() -> [(&'static str, &'static str); 2] {
    [("chain.nodes", CHAIN_NODES), ("chain.links", CHAIN_LINKS)]
}

/// A chain of four 0.5 m members hanging from node 1 (held), the others held sideways only,
/// under `gravity = [0, -9.81]` (or `head`'s), ρ = 7850 kg/m³; `material` extra lines.
fn chain(head: &str, material: &str, body: &str) -> String {
    format!(
        r#"name = "chain"
steps = 2
{head}
[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4
density = 7850.0
{material}
[[bodies]]
name = "chain"
nodes = "chain.nodes"
links = "chain.links"
material = "steel"
{body}
[[bodies.supports]]
nodes = [1]
fix = ["x", "y"]
[[bodies.supports]]
nodes = [2, 3, 4, 5]
fix = ["x"]
"#
    )
}

/// A hanging chain under g (m/s², down): the weight lumped ρ A ℓ g/2 at each member end, so
/// member i (from the top) carries ρ A ℓ g (4 − i + ½), the top reaction is ρ g A L (1e-12),
/// the forces agree to 1e-10 and the bottom sinks Σ Nᵢ ℓ/(E A) (1e-9).
fn assert_hanging_chain(r: &Run, g: f64) {
    let w = 7850.0 * 1e-4 * 0.5 * g;
    let b = r.last(0);
    let reaction = b.reactions.iter().find(|f| f.node == 1).unwrap();
    assert_close(
        "top reaction = ρgAL",
        reaction.force[1],
        7850.0 * g * 1e-4 * 2.0,
        1e-12,
    );
    let mut sink = 0.0;
    for i in 1..=4 {
        let n = w * (4.0 - i as f64 + 0.5);
        assert_close(&format!("member {i}"), b.axial_forces[i - 1], n, 1e-10);
        sink += n * 0.5 / EA;
    }
    assert_close("bottom node", -b.displacements[4][1], sink, 1e-9);
}

// ================================================================= large displacements (LD)

/// LD × F: the vee with `kinematics = "large"` on a floor that rises 3 mm and slides 3 mm
/// (μ = 0.3): node 1 slips (|f_T| = μ f_N, 1e-9), and its displacement solves the exact
/// equilibrium of node 1, solved here by Newton on two unknowns: each member's force
/// `E A (l − L)/L` along its current direction, the floor's `k (δ − u_y)` up and `μ k (δ − u_y)`
/// along x (to 1e-7 of the displacement; the linear body's answer differs by 1e-4 of it).
#[test]
fn a_large_body_dragged_by_a_sliding_floor_slips_at_its_exact_coulomb_equilibrium() {
    let mu = 0.3;
    let text = |kin: &str| {
        vee(
            5,
            "",
            "",
            "",
            &format!("kinematics = \"{kin}\""),
            &floor("[0.003, 0.003]", "friction = 0.3"),
        )
    };
    let large = run(&text("large"), &vee_files());
    let c = contact_of_node_1(&large);
    assert_slips_at_coulomb(&c, mu);
    // The exact equilibrium of node 1 at (x, y).
    let anchors: [(f64, f64, f64); 3] = [(-1.0, 1.0, EA), (0.0, 1.0, EA), (1.0, 1.0, EA)];
    let residual = |x: f64, y: f64| {
        let (mut fx, mut fy) = (0.0, 0.0);
        for (ax, ay, ea) in anchors {
            let l0: f64 = (ax * ax + ay * ay).sqrt();
            let (dx, dy): (f64, f64) = (ax - x, ay - y);
            let l = (dx * dx + dy * dy).sqrt();
            let n = ea * (l - l0) / l0;
            fx += n * dx / l;
            fy += n * dy / l;
        }
        let fn_ = K * (DELTA - y);
        (fx + mu * fn_, fy + fn_)
    };
    let (mut x, mut y) = (0.0, 0.0);
    for _ in 0..50 {
        let h = 1e-9;
        let (r0, r1) = residual(x, y);
        let (a0, a1) = residual(x + h, y);
        let (b0, b1) = residual(x, y + h);
        let j = [
            [(a0 - r0) / h, (b0 - r0) / h],
            [(a1 - r1) / h, (b1 - r1) / h],
        ];
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        x -= (j[1][1] * r0 - j[0][1] * r1) / det;
        y -= (-j[1][0] * r0 + j[0][0] * r1) / det;
    }
    let u = large.u(0, 1);
    assert_close("u_x", u[0], x, 1e-7);
    assert_close("u_y", u[1], y, 1e-7);
    let linear = run(&text("linear"), &vee_files()).u(0, 1);
    assert!(
        (linear[0] - u[0]).abs() > 1e-5 * u[0].abs(),
        "{linear:?} {u:?}"
    );
}

/// LD × SC: the hairpin under large displacements with self-contact: the upper arm's corner
/// rests on the lower arm (contacts of the body with itself, depth below 1 mm, where
/// without contact the corner would sink about 5 mm into it), and the answer is the linear
/// body's up to the arm's rotation (0.6 %: within 5 % of the largest displacement, and not
/// equal to it: above 1e-6).
#[test]
fn a_large_body_pressed_on_itself_rests_on_itself_and_agrees_with_the_linear_one() {
    let files = hairpin_files();
    let large = run(
        &hairpin("hairpin.links", 0.0, "kinematics = \"large\"", "", ""),
        &refs(&files),
    );
    let linear = run(&hairpin("hairpin.links", 0.0, "", "", ""), &refs(&files));
    assert_touches_itself(&large);
    assert_touches_itself(&linear);
    assert_same_hairpin(&large, &linear, 5e-2);
    let scale = 0.015;
    let differs = (1..=16).any(|n| (large.u(0, n)[0] - linear.u(0, n)[0]).abs() > 1e-6 * scale);
    assert!(differs, "the large body is solved as the linear one");
}

/// LD × Sw: a sweep of the von Mises truss's apex load (3 and 5 kN under load control) gives
/// the runs written by hand, bit for bit, each on the closed form P(w) (1e-6).
#[test]
fn a_sweep_of_a_large_truss_load_equals_the_runs_written_by_hand_on_the_closed_form() {
    let files = vm_files();
    let make = |v: &str| {
        von_mises(
            4,
            "",
            "",
            "",
            &format!("[[bodies.loads]]\nnodes = [2]\nforce = {v}\n"),
            false,
        )
    };
    let runs = sweep_equals_single_runs(
        &make,
        &refs(&files),
        "bodies.truss.loads.1.force",
        &["[0.0, -3000.0]", "[0.0, -5000.0]"],
    );
    for (r, p) in runs.iter().zip([3000.0, 5000.0]) {
        let w = -r.u(0, 2)[1];
        assert_close("P(w)", von_mises_load(w), p, 1e-6);
    }
}

// ================================================================= nonlinear members (NL)

/// NL × C: the vee with a tension-only post pushed up by the floor: the post goes slack
/// (force exactly 0) and node 1 rises by `k δ/(k + K_d)` as on the diagonals alone (1e-9);
/// with an elastic post it rises by `k δ/(k + K_d + E A)`.
#[test]
fn a_tension_only_post_goes_slack_as_the_floor_pushes_the_body_up() {
    let text = |post: &str| vee(5, "", "", post, "", &floor("[0.0, 0.003]", ""));
    let cable = run(&text("behaviour = \"tension_only\""), &vee_files());
    assert_eq!(cable.last(0).axial_forces[1], 0.0);
    assert_close("u_y", cable.u(0, 1)[1], K * DELTA / (K + kd()), 1e-9);
    assert!(cable.u(0, 1)[0].abs() < 1e-15);
    let elastic = run(&text(""), &vee_files());
    assert_close(
        "elastic u_y",
        elastic.u(0, 1)[1],
        K * DELTA / (K + kd() + EA),
        1e-9,
    );
    assert!(elastic.last(0).axial_forces[1] < -1e4);
}

/// NL × F: the floor rises and slides 3 mm (μ = 0.3) under the vee with a tension-only post:
/// the post is slack (0), node 1 slips (Coulomb, 1e-9), rises by `k δ/(k + K_d)` and is
/// dragged by `μ f_N/K_d = μ u_y` (1e-9).
#[test]
fn a_tension_only_post_is_slack_while_friction_drags_the_body_by_mu_times_its_rise() {
    let text = vee(
        5,
        "",
        "",
        "behaviour = \"tension_only\"",
        "",
        &floor("[0.003, 0.003]", "friction = 0.3"),
    );
    let r = run(&text, &vee_files());
    assert_eq!(r.last(0).axial_forces[1], 0.0);
    assert_slips_at_coulomb(&contact_of_node_1(&r), 0.3);
    let u = r.u(0, 1);
    assert_close("u_y", u[1], K * DELTA / (K + kd()), 1e-9);
    assert_close("u_x = μ u_y", u[0], 0.3 * u[1], 1e-9);
}

/// NL × SC: the hairpin's lower-arm post 3–7 (below the pressed segment) tension-only: as the
/// upper arm presses on the lower one the post shortens and goes slack (force exactly 0), and
/// the body agrees with the hairpin without that post (1e-8 of the largest displacement);
/// elastic, the post carries compression.
#[test]
fn a_tension_only_member_of_a_body_pressed_on_itself_goes_slack() {
    let files = hairpin_files();
    let cable = run(&hairpin("cable.links", 0.0, "", "", ""), &refs(&files));
    let none = run(&hairpin("nopost.links", 0.0, "", "", ""), &refs(&files));
    let elastic = run(&hairpin("hairpin.links", 0.0, "", "", ""), &refs(&files));
    assert_touches_itself(&cable);
    assert_eq!(*cable.last(0).axial_forces.last().unwrap(), 0.0);
    assert_same_hairpin(&cable, &none, 1e-8);
    assert!(*elastic.last(0).axial_forces.last().unwrap() < -1.0);
}

/// NL × Fr: a tension-only post that breaks (f_t = 20 MPa): pulled down by P = 5 kN it
/// carries `s₀ λ P` (s₀ = E A/(E A + K_d)) and breaks at `λ* = f_t A/(s₀ P)` = 0.6828 (1e-8);
/// pushed up with `strength = 20e6` (tension and compression) it is slack and never breaks,
/// where an elastic post breaks in compression at the same λ*.
#[test]
fn a_tension_only_post_breaks_in_tension_at_the_hand_load_and_never_in_compression() {
    let (s0, _) = shares();
    let text = |post: &str, fy: f64| vee(4, "", "", post, "", &load_at_1(fy));
    let pulled = run(
        &text(
            "tensile_strength = 20e6\nfailure = \"break\"\nbehaviour = \"tension_only\"",
            -5000.0,
        ),
        &vee_files(),
    );
    let b = &pulled.summary.breaks;
    assert_eq!(b.len(), 1, "{b:?}");
    assert_eq!((b[0].step, b[0].member), (3, 2));
    assert_close("λ*", b[0].load_factor, FT_A / (s0 * 5000.0), 1e-8);
    assert_close("after", pulled.u(0, 1)[1], -5000.0 / kd(), 1e-9);
    let pushed = run(
        &text(
            "strength = 20e6\nfailure = \"break\"\nbehaviour = \"tension_only\"",
            5000.0,
        ),
        &vee_files(),
    );
    assert!(
        pushed.summary.breaks.is_empty(),
        "{:?}",
        pushed.summary.breaks
    );
    assert_eq!(pushed.last(0).axial_forces[1], 0.0);
    assert_close("slack", pushed.u(0, 1)[1], 5000.0 / kd(), 1e-9);
    let elastic = run(
        &text("strength = 20e6\nfailure = \"break\"", 5000.0),
        &vee_files(),
    );
    assert_eq!(elastic.summary.breaks.len(), 1);
    assert_close(
        "elastic λ*",
        elastic.summary.breaks[0].load_factor,
        FT_A / (s0 * 5000.0),
        1e-8,
    );
}

/// NL × So: a tension-only softening post (2 teeth, `SOFT_POST`) pulled by 5 kN passes tooth 1
/// at `f_t A/(s₀ P)` and breaks at `σ₁ A/(s₁ P)` (s₁ with E₁ A), both to 1e-8.
#[test]
fn a_tension_only_softening_post_passes_its_teeth_at_the_hand_loads() {
    let text = vee(
        4,
        "",
        "",
        &format!("{SOFT_POST}\nbehaviour = \"tension_only\""),
        "",
        &load_at_1(-5000.0),
    );
    let r = run(&text, &vee_files());
    assert_teeth(&r.summary, 5000.0, 0.0);
}

/// NL × P: a pressure of 1000 N/m on the vee's outer sides pushes node 1 up by p: a
/// tension-only post goes slack (0) and node 1 rises `p/K_d` (1e-9), the diagonals carrying
/// `−E A u_y/2` each (1e-9); an elastic post: `p/(K_d + E A)`.
#[test]
fn a_pressure_on_a_body_with_a_tension_only_post_is_carried_by_the_rest() {
    let text = |post: &str| vee(2, "", "", post, "", &pressure(1000.0));
    let r = run(&text("behaviour = \"tension_only\""), &vee_files());
    let uy = r.u(0, 1)[1];
    assert_close("u_y", uy, 1000.0 / kd(), 1e-9);
    let f = &r.last(0).axial_forces;
    assert_eq!(f[1], 0.0);
    assert_close("diagonal 1", f[0], -EA * uy / 2.0, 1e-9);
    assert_close("diagonal 3", f[2], -EA * uy / 2.0, 1e-9);
    let elastic = run(&text(""), &vee_files());
    assert_close("elastic", elastic.u(0, 1)[1], 1000.0 / (kd() + EA), 1e-9);
}

/// The load factor of a scene whose only load is a pressure is the pressure's schedule
/// (`[0.5, 0.5, 1.0]`: 0.5 at step 2, not the step fraction 2/3), and the displacement follows
/// it (u_y = 0.5 P/(K_d + E A) at step 2, 1e-9); a load on another schedule beside it makes the
/// load factor the step fraction.
#[test]
fn the_load_factor_of_a_scene_loaded_by_a_pressure_alone_is_its_schedule() {
    let p =
        "[[bodies.pressures]]\nnodes = [1, 2, 4]\npressure = 1000.0\nschedule = [0.5, 0.5, 1.0]\n";
    let r = run(&vee(3, "", "", "", "", p), &vee_files());
    let factors: Vec<f64> = r.summary.steps.iter().map(|s| s.load_factor).collect();
    assert_eq!(factors, [0.0, 0.5, 0.5, 1.0]);
    let uy = r.steps[2].bodies[0].displacements[0][1];
    assert_close("u_y at step 2", uy, 500.0 / (kd() + EA), 1e-9);
    let both = format!("{p}{}", load_at_1(10.0));
    let r = run(&vee(3, "", "", "", "", &both), &vee_files());
    let factors: Vec<f64> = r.summary.steps.iter().map(|s| s.load_factor).collect();
    assert_eq!(factors, [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0]);
}

/// NL × G: a chain of tension-only members hanging under its own weight (the closed form of
/// `assert_hanging_chain`).
#[test]
fn nonlinear_members_with_gravity_match_the_closed_form_of_a_hanging_cable() {
    let r = run(
        &chain("gravity = [0.0, -9.81]", "behaviour = \"tension_only\"", ""),
        &chain_files(),
    );
    assert_hanging_chain(&r, 9.81);
}

/// NL × It: the vee with a tension-only post, pushed up by 5 kN (post slack) and pulled down
/// (post taut), solved by conjugate gradients: the same displacements as direct (1e-10 of the
/// largest) on the closed forms `P/K_d` and `P/(K_d + E A)` (1e-9).
#[test]
fn a_tension_only_body_solved_iteratively_agrees_with_direct() {
    let newton = "[bodies.newton]\ntolerance = 1e-12";
    for (fy, k) in [(5000.0, kd()), (-5000.0, kd() + EA)] {
        let text = |solver: &str| {
            vee(
                2,
                "",
                "",
                "behaviour = \"tension_only\"",
                &format!("solver = \"{solver}\"\niterative = {{ tolerance = 1e-12 }}\n{newton}"),
                &load_at_1(fy),
            )
        };
        let it = run(&text("iterative"), &vee_files());
        let direct = run(&text("direct"), &vee_files());
        assert_eq!(it.summary.bodies[0].solver, "iterative");
        assert_eq!(direct.summary.bodies[0].solver, "direct");
        let (a, b) = (it.u(0, 1), direct.u(0, 1));
        for d in 0..2 {
            assert!((a[d] - b[d]).abs() <= 1e-10 * b[1].abs(), "{a:?} {b:?}");
        }
        assert_close("u_y", a[1], fy / k, 1e-9);
    }
}

/// NL × AL: the von Mises truss with a tension-only member from its apex down to a held node,
/// traced by arc length through its limit point: the member shortens, stays slack (0 at every
/// step) and every step lies on the plain truss's closed form (1e-6 of the limit load).
#[test]
fn a_tension_only_member_stays_slack_along_an_arc_length_snap_through() {
    let files = vm_files();
    let text = von_mises(30, "", "", ARC, &apex_load(10000.0), true);
    let r = run(&text, &refs(&files));
    for s in &r.steps {
        assert_eq!(s.bodies[0].axial_forces[2], 0.0, "step {}", s.step);
    }
    assert_on_the_von_mises_path(&r, 10000.0);
}

/// NL × Sw: a sweep of the load on the vee with a tension-only post (2 kN up, slack; 2 kN
/// down, taut) equals the runs written by hand, each on its closed form (1e-9).
#[test]
fn a_sweep_of_the_load_on_a_tension_only_body_equals_the_runs_written_by_hand() {
    let make = |v: &str| {
        vee(
            2,
            "",
            "",
            "behaviour = \"tension_only\"",
            "",
            &format!("[[bodies.loads]]\nnodes = [1]\nforce = {v}\n"),
        )
    };
    let runs = sweep_equals_single_runs(
        &make,
        &vee_files(),
        "bodies.vee.loads.1.force",
        &["[0.0, 2000.0]", "[0.0, -2000.0]"],
    );
    assert_close("slack", runs[0].u(0, 1)[1], 2000.0 / kd(), 1e-9);
    assert_close("taut", runs[1].u(0, 1)[1], -2000.0 / (kd() + EA), 1e-9);
}

// ================================================================= contact (C)

/// C × Sw: a sweep of the floor's travel (2 and 3 mm up) equals the runs written by hand, node
/// 1 rising `k δ/(k + K_d + E A)` in each (1e-9).
#[test]
fn a_sweep_of_an_obstacles_travel_equals_the_runs_written_by_hand() {
    let make = |v: &str| vee(5, "", "", "", "", &floor(v, ""));
    let runs = sweep_equals_single_runs(
        &make,
        &vee_files(),
        "obstacles.floor.travel",
        &["[0.0, 0.002]", "[0.0, 0.003]"],
    );
    for (r, delta) in runs.iter().zip([0.001, 0.002]) {
        assert_close("u_y", r.u(0, 1)[1], K * delta / (K + kd() + EA), 1e-9);
    }
}

// ================================================================= friction (F)

/// F × SC: the hairpin with μ = 0.3, the upper arm's end moved 5 mm sideways (−x) as it comes
/// down: the arms rub. Every contact of the body with itself stays within Coulomb's cone
/// (|f_T| ≤ μ f_N, 1e-9) and some carry friction (over 1 kN), where the frictionless run has
/// no tangential force (1e-9 of f_N); friction changes the answer (the corner's x by more
/// than 10 µm).
#[test]
fn a_body_rubbing_on_itself_stays_within_coulomb() {
    let files = hairpin_files();
    let rough = run(
        &hairpin("hairpin.links", -0.005, "", "", "friction = 0.3"),
        &refs(&files),
    );
    let norm = |v: &[f64]| v.iter().map(|f| f * f).sum::<f64>().sqrt();
    let c = assert_touches_itself(&rough);
    for x in &c {
        assert!(
            norm(&x.tangential_force) <= 0.3 * x.normal_force * (1.0 + 1e-9),
            "{x:?}"
        );
    }
    assert!(c.iter().any(|x| norm(&x.tangential_force) > 1e3), "{c:?}");
    let smooth = run(&hairpin("hairpin.links", -0.005, "", "", ""), &refs(&files));
    for x in &assert_touches_itself(&smooth) {
        assert!(norm(&x.tangential_force) <= 1e-9 * x.normal_force, "{x:?}");
    }
    assert!((rough.u(0, 12)[0] - smooth.u(0, 12)[0]).abs() > 1e-5);
}

/// F × So: a cuboid press comes down 3 mm onto node 1 of the vee (1 mm gap) while sliding
/// 3 mm (μ = 0.3); the softening post (2 teeth, in tension) passes its teeth where the
/// frictionless hand calculation puts them: node 1 sinks `d = k (λ T − gap)/(k + K_y)`, so tooth
/// 1 at d = ε₀ L and the break at d = ε₁ L, `λ = (gap + d (k + K_y)/k)/T` with `K_y = K_d + E A`
/// then `K_d + E₁ A` (1e-8): friction drags node 1 along x only, which does not stretch the
/// post; at the end node 1 slips (Coulomb, 1e-9) dragged by `μ f_N/K_d` (1e-9).
#[test]
fn friction_leaves_a_softening_post_under_a_sliding_press_at_its_hand_loads() {
    let press = r#"[[obstacles]]
name = "press"
shape = "cuboid"
center = [0.0, 0.101]
half_extents = [0.5, 0.1]
travel = [0.003, -0.003]
[contact]
penalty = 1e9
friction = 0.3
"#;
    let r = run(&vee(5, "", "", SOFT_POST, "", press), &vee_files());
    let b = &r.summary.breaks;
    assert_eq!(b.len(), 2, "{b:?}");
    let lam = |d: f64, ky: f64| (0.001 + d * (K + ky) / K) / 0.003;
    assert_eq!((b[0].member, b[0].tooth), (2, Some(1)));
    assert_close("tooth 1", b[0].load_factor, lam(1e-4, kd() + EA), 1e-8);
    assert_eq!((b[1].member, b[1].tooth), (2, None));
    assert_close("break", b[1].load_factor, lam(2e-4, kd() + E1 * 1e-4), 1e-8);
    let c = contact_of_node_1(&r);
    assert_slips_at_coulomb(&c, 0.3);
    assert_close("dragged", r.u(0, 1)[0], 0.3 * c.normal_force / kd(), 1e-9);
}

/// The weight at node 1 of the vee, N per m/s² of g: half of each diagonal and of the post.
fn vee_weight_at_1(density: f64) -> f64 {
    density * 1e-4 * (2f64.sqrt() + 0.5)
}

/// F × G: the vee (ρ = 7.85e6 kg/m³, so node 1 weighs 14.7 kN) under a tilted gravity
/// (3, −9) m/s² on the rising, sliding floor (μ = 0.3): node 1 slips (Coulomb, 1e-9) with
/// `u_y = (W_y + k δ)/(K_y + k)` and `u_x = (W_x + μ k (δ − u_y))/K_d` (1e-9).
#[test]
fn gravity_and_friction_together_match_the_closed_form_of_a_dragged_heavy_node() {
    let dense = "density = 7.85e6";
    let text = vee(
        5,
        "gravity = [3.0, -9.0]",
        dense,
        dense,
        "",
        &floor("[0.003, 0.003]", "friction = 0.3"),
    );
    let r = run(&text, &vee_files());
    let w = vee_weight_at_1(7.85e6);
    let (wx, wy) = (3.0 * w, -9.0 * w);
    let uy = (wy + K * DELTA) / (kd() + EA + K);
    let ux = (wx + 0.3 * K * (DELTA - uy)) / kd();
    let c = contact_of_node_1(&r);
    assert_slips_at_coulomb(&c, 0.3);
    assert_close("u_y", r.u(0, 1)[1], uy, 1e-9);
    assert_close("u_x", r.u(0, 1)[0], ux, 1e-9);
}

/// F × It: the vee on the rising, sliding floor (μ = 0.3) solved by conjugate gradients: the
/// displacements of the direct run (1e-9 of the largest), on the closed form (1e-9).
#[test]
fn friction_with_an_iterative_body_agrees_with_direct_and_the_closed_form() {
    let text = |solver: &str| {
        vee(
            5,
            "",
            "",
            "",
            &format!("solver = \"{solver}\"\niterative = {{ tolerance = 1e-12 }}"),
            &floor("[0.003, 0.003]", "friction = 0.3"),
        )
    };
    let it = run(&text("iterative"), &vee_files());
    let direct = run(&text("direct"), &vee_files());
    assert!(
        it.summary.bodies[0].solver.starts_with("iterative"),
        "{:?}",
        it.summary.bodies
    );
    let (a, b) = (it.u(0, 1), direct.u(0, 1));
    for d in 0..2 {
        assert!((a[d] - b[d]).abs() <= 1e-9 * b[1].abs(), "{a:?} {b:?}");
    }
    let uy = K * DELTA / (K + kd() + EA);
    assert_close("u_y", a[1], uy, 1e-9);
    assert_close("u_x", a[0], 0.3 * K * (DELTA - uy) / kd(), 1e-9);
    assert_slips_at_coulomb(&contact_of_node_1(&it), 0.3);
}

/// F × Sw: a sweep of μ (0.1, 0.3) on the rising, sliding floor equals the runs written by
/// hand, node 1 dragged by `μ k (δ − u_y)/K_d` in each (1e-9).
#[test]
fn a_sweep_of_the_friction_coefficient_equals_the_runs_written_by_hand() {
    let make = |v: &str| {
        vee(
            5,
            "",
            "",
            "",
            "",
            &floor("[0.003, 0.003]", &format!("friction = {v}")),
        )
    };
    let runs = sweep_equals_single_runs(&make, &vee_files(), "contact.friction", &["0.1", "0.3"]);
    let uy = K * DELTA / (K + kd() + EA);
    for (r, mu) in runs.iter().zip([0.1, 0.3]) {
        assert_close("u_x", r.u(0, 1)[0], mu * K * (DELTA - uy) / kd(), 1e-9);
        assert_slips_at_coulomb(&contact_of_node_1(r), mu);
    }
}

// ================================================================= self-contact (SC)

/// SC × G: the hairpin (ρ = 7850 kg/m³) under gravity (0, −981) m/s² (it weighs about 20 kN)
/// pressed on itself: its supports carry its weight, the sum of the reactions is W along y
/// (1e-9) and 0 along x (1e-9 of W), and the weight changes the press (the corner's
/// contact force differs from the weightless run's).
#[test]
fn a_heavy_body_pressed_on_itself_hangs_on_its_supports_with_its_weight() {
    let files = hairpin_files();
    let g = "gravity = [0.0, -981.0]";
    let heavy = run(&hairpin("hairpin.links", 0.0, "", g, ""), &refs(&files));
    let light = run(&hairpin("hairpin.links", 0.0, "", "", ""), &refs(&files));
    assert_touches_itself(&heavy);
    let nodes: Vec<[f64; 2]> = HAIRPIN_NODES
        .lines()
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            [v[0], v[1]]
        })
        .collect();
    let length: f64 = hairpin_links(Some("steel"))
        .lines()
        .map(|l| {
            let v: Vec<usize> = l
                .split_whitespace()
                .take(2)
                .map(|x| x.parse().unwrap())
                .collect();
            let (a, b) = (nodes[v[0] - 1], nodes[v[1] - 1]);
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
        })
        .sum();
    let weight = 7850.0 * 1e-4 * length * 981.0;
    let (sx, sy) = heavy
        .last(0)
        .reactions
        .iter()
        .fold((0.0, 0.0), |(x, y), f| (x + f.force[0], y + f.force[1]));
    assert_close("Σ reactions", sy, weight, 1e-9);
    assert!(sx.abs() < 1e-9 * weight, "{sx}");
    let force = |r: &Run| {
        r.last(0)
            .contacts
            .iter()
            .map(|c| c.normal_force)
            .sum::<f64>()
    };
    assert!((force(&heavy) - force(&light)).abs() > 1e-3 * force(&light));
}

/// SC × It: the hairpin pressed on itself, solved by conjugate gradients: the direct run's
/// displacements (1e-9 of the largest).
#[test]
fn a_body_pressed_on_itself_solved_iteratively_agrees_with_direct() {
    let files = hairpin_files();
    let body = |s: &str| format!("solver = \"{s}\"\niterative = {{ tolerance = 1e-12 }}");
    let it = run(
        &hairpin("hairpin.links", 0.0, &body("iterative"), "", ""),
        &refs(&files),
    );
    let direct = run(
        &hairpin("hairpin.links", 0.0, &body("direct"), "", ""),
        &refs(&files),
    );
    assert!(
        it.summary.bodies[0].solver.starts_with("iterative"),
        "{:?}",
        it.summary.bodies
    );
    assert_touches_itself(&it);
    assert_same_hairpin(&it, &direct, 1e-9);
}

/// SC × Sw: a sweep of the upper arm end's move (15 and 13 mm down) with self-contact equals
/// the runs written by hand; both touch.
#[test]
fn a_sweep_of_a_body_pressed_on_itself_equals_the_runs_written_by_hand() {
    let files = hairpin_files();
    let make = |v: &str| {
        hairpin("hairpin.links", 0.0, "", "", "").replace(
            "displacement = [0.0, -0.015]",
            &format!("displacement = {v}"),
        )
    };
    let runs = sweep_equals_single_runs(
        &make,
        &refs(&files),
        "bodies.hairpin.supports.2.displacement",
        &["[0.0, -0.015]", "[0.0, -0.013]"],
    );
    for r in &runs {
        assert_touches_itself(r);
    }
}

// ================================================================= fracture (Fr)

/// Fr × P: a pressure of 5 kN/m pushes node 1 up by p; the post (compressive strength 20 MPa)
/// carries `−s₀ λ p` and breaks at `λ* = f_c A/(s₀ p)` = 0.6828 (1e-8); node 1 then rises
/// `p/K_d` (1e-9).
#[test]
fn a_pressure_breaks_a_post_at_the_hand_load() {
    let (s0, _) = shares();
    let text = vee(
        4,
        "",
        "",
        "compressive_strength = 20e6\nfailure = \"break\"",
        "",
        &pressure(5000.0),
    );
    let r = run(&text, &vee_files());
    let b = &r.summary.breaks;
    assert_eq!(b.len(), 1, "{b:?}");
    assert_eq!((b[0].step, b[0].member), (3, 2));
    assert_close("λ*", b[0].load_factor, FT_A / (s0 * 5000.0), 1e-8);
    assert_close("after", r.u(0, 1)[1], 5000.0 / kd(), 1e-9);
}

/// Fr × Sw: a sweep of the post's tensile strength (15, 20 MPa) under 5 kN down equals the
/// runs written by hand, each breaking at `f_t A/(s₀ P)` (1e-8).
#[test]
fn a_sweep_of_a_strength_equals_the_runs_written_by_hand() {
    let (s0, _) = shares();
    let make = |v: &str| {
        vee(
            4,
            "",
            "",
            &format!("tensile_strength = {v}\nfailure = \"break\""),
            "",
            &load_at_1(-5000.0),
        )
    };
    let runs = sweep_equals_single_runs(
        &make,
        &vee_files(),
        "materials.post.tensile_strength",
        &["15e6", "20e6"],
    );
    for (r, ft) in runs.iter().zip([15e6, 20e6]) {
        assert_eq!(r.summary.breaks.len(), 1);
        assert_close(
            "λ*",
            r.summary.breaks[0].load_factor,
            ft * 1e-4 / (s0 * 5000.0),
            1e-8,
        );
    }
}

// ================================================================= softening (So)

/// So × P: a suction of 5 kN/m (pressure −5000) pulls node 1 down; the softening post passes
/// its teeth at the hand loads (1e-8).
#[test]
fn a_suction_takes_a_softening_post_through_its_teeth_at_the_hand_loads() {
    let r = run(
        &vee(4, "", "", SOFT_POST, "", &pressure(-5000.0)),
        &vee_files(),
    );
    assert_teeth(&r.summary, 5000.0, 0.0);
}

/// So × G: the vee (ρ = 2.5e5 kg/m³: node 1 weighs 470 N) under its full weight from step 1
/// on and 5 kN down growing over 4 steps: the softening post passes its teeth at
/// `(σᵢ A/sᵢ − W₁)/P` (1e-8).
#[test]
fn a_softening_post_under_its_weight_and_a_growing_load_passes_its_teeth_at_the_hand_loads() {
    let dense = "density = 2.5e5";
    let text = vee(
        4,
        "gravity = [0.0, -9.81]\ngravity_schedule = [1.0, 1.0, 1.0, 1.0]",
        dense,
        &format!("{SOFT_POST}\n{dense}"),
        "",
        &load_at_1(-5000.0),
    );
    let r = run(&text, &vee_files());
    assert_teeth(&r.summary, 5000.0, vee_weight_at_1(2.5e5) * 9.81);
}

/// So × It: the softening post pulled by 5 kN in a body solved by conjugate gradients passes
/// its teeth at the hand loads (1e-8), and the last displacement is the direct run's (1e-9).
/// The scene has `[contact]` (nothing touches): a breaking body of a scene without contact is
/// solved event by event with the direct solver whatever its `solver` (summary: "direct").
#[test]
fn a_softening_post_of_an_iterative_body_passes_its_teeth_at_the_hand_loads() {
    let text = |s: &str| {
        vee(
            4,
            "",
            "",
            SOFT_POST,
            &format!("solver = \"{s}\"\niterative = {{ tolerance = 1e-12 }}"),
            &format!("{}[contact]\npenalty = 1e9\n", load_at_1(-5000.0)),
        )
    };
    let it = run(&text("iterative"), &vee_files());
    let direct = run(&text("direct"), &vee_files());
    assert!(
        it.summary.bodies[0].solver.starts_with("iterative"),
        "{:?}",
        it.summary.bodies
    );
    assert_teeth(&it.summary, 5000.0, 0.0);
    assert_close("u_y", it.u(0, 1)[1], direct.u(0, 1)[1], 1e-9);
}

/// So × Sw: a sweep of the fracture energy (1750, 2500 J/m²) equals the runs written by hand;
/// the first passes its teeth at the hand loads (1e-8).
#[test]
fn a_sweep_of_the_fracture_energy_equals_the_runs_written_by_hand() {
    let make = |v: &str| {
        vee(
            4,
            "",
            "",
            &SOFT_POST.replace("1750.0", v),
            "",
            &load_at_1(-5000.0),
        )
    };
    let runs = sweep_equals_single_runs(
        &make,
        &vee_files(),
        "materials.post.softening.fracture_energy",
        &["1750.0", "2500.0"],
    );
    assert_teeth(&runs[0].summary, 5000.0, 0.0);
}

// ================================================================= pressure (P)

/// P × G: a pressure of 5 kN/m up and the vee's weight (ρ = 7.85e6: 14.7 kN at node 1, both
/// at full value at the last step): node 1 moves `(p − W₁)/(K_d + E A)` (1e-9).
#[test]
fn a_pressure_and_the_weight_together_match_the_closed_form() {
    let dense = "density = 7.85e6";
    let text = vee(
        2,
        "gravity = [0.0, -9.81]",
        dense,
        dense,
        "",
        &pressure(5000.0),
    );
    let r = run(&text, &vee_files());
    let w = vee_weight_at_1(7.85e6) * 9.81;
    assert_close("u_y", r.u(0, 1)[1], (5000.0 - w) / (kd() + EA), 1e-9);
    assert!(r.u(0, 1)[0].abs() < 1e-15);
}

/// P × It: the pressure on the vee solved by conjugate gradients: `p/(K_d + E A)` (1e-9), as
/// the direct run.
#[test]
fn a_pressure_on_an_iterative_body_matches_the_closed_form_and_direct() {
    let text = |s: &str| {
        vee(
            2,
            "",
            "",
            "",
            &format!("solver = \"{s}\"\niterative = {{ tolerance = 1e-12 }}"),
            &pressure(5000.0),
        )
    };
    let it = run(&text("iterative"), &vee_files());
    let direct = run(&text("direct"), &vee_files());
    assert!(
        it.summary.bodies[0].solver.starts_with("iterative"),
        "{:?}",
        it.summary.bodies
    );
    assert_close("u_y", it.u(0, 1)[1], 5000.0 / (kd() + EA), 1e-9);
    assert_close("direct", it.u(0, 1)[1], direct.u(0, 1)[1], 1e-9);
}

/// P × AL: the pressure on the (linear) vee as the arc-length reference load: the path is
/// straight, so step k has `λ = k s/|u_ref|` with `u_ref = p/(K_d + E A)` (1e-9). A large
/// body's pressure follows its faces and is refused with arc length (an error naming the body).
#[test]
fn a_pressure_scaled_by_arc_length_follows_the_straight_path_and_a_following_one_is_refused() {
    let arc = "[bodies.path]\nmethod = \"arc_length\"\narc_length = 0.0001";
    let r = run(&vee(3, "", "", "", arc, &pressure(5000.0)), &vee_files());
    let u_ref = 5000.0 / (kd() + EA);
    for s in &r.steps[1..] {
        assert_close("λ", s.load_factor, s.step as f64 * 1e-4 / u_ref, 1e-9);
        assert_close(
            "u_y",
            s.bodies[0].displacements[0][1],
            s.step as f64 * 1e-4,
            1e-9,
        );
    }
    let large = format!("kinematics = \"large\"\n{arc}");
    let e = try_run(&vee(3, "", "", "", &large, &pressure(5000.0)), &vee_files())
        .err()
        .expect("a following pressure with arc length is refused");
    assert!(e.contains("'vee'") && e.contains("arc"), "{e}");
}

/// P × Sw: a sweep of the pressure (2, 5 kN/m) equals the runs written by hand, node 1 rising
/// `p/(K_d + E A)` (1e-9).
#[test]
fn a_sweep_of_a_pressure_equals_the_runs_written_by_hand() {
    let make = |v: &str| {
        vee(
            2,
            "",
            "",
            "",
            "",
            &format!("[[bodies.pressures]]\nnodes = [1, 2, 4]\npressure = {v}\n"),
        )
    };
    let runs = sweep_equals_single_runs(
        &make,
        &vee_files(),
        "bodies.vee.pressures.1.pressure",
        &["2000.0", "5000.0"],
    );
    for (r, p) in runs.iter().zip([2000.0, 5000.0]) {
        assert_close("u_y", r.u(0, 1)[1], p / (kd() + EA), 1e-9);
    }
}

// ================================================================= gravity (G)

/// G × It: a chain hanging under its weight solved by conjugate gradients: the closed form of
/// `assert_hanging_chain` (reaction ρgAL to 1e-12, bottom node 1e-9).
#[test]
fn a_hanging_bar_solved_iteratively_matches_its_self_weight_closed_form() {
    let r = run(
        &chain(
            "gravity = [0.0, -9.81]",
            "",
            "solver = \"iterative\"\niterative = { tolerance = 1e-12 }",
        ),
        &chain_files(),
    );
    assert!(
        r.summary.bodies[0].solver.starts_with("iterative"),
        "{:?}",
        r.summary.bodies
    );
    assert_hanging_chain(&r, 9.81);
}

/// G × AL: the von Mises truss with its own weight (ρ = 7.85e6 kg/m³: the apex carries
/// ρ A L g = 7.74 kN of it) and 10 kN at the apex traced by arc length: the weight is part of
/// the reference load λ scales, so every step lies on `λ (P + W) = P(w)` (1e-6 of the limit
/// load) through the limit point, at `λ = 7622/(P + W)`.
#[test]
fn arc_length_with_gravity_passes_the_limit_load_with_the_weight_added() {
    let files = vm_files();
    let text = von_mises(
        30,
        "gravity = [0.0, -9.81]",
        "density = 7.85e6",
        ARC,
        &apex_load(10000.0),
        false,
    );
    let r = run(&text, &refs(&files));
    let w = 7.85e6 * 1e-4 * (1.0f64 + 0.01).sqrt() * 9.81;
    assert_on_the_von_mises_path(&r, 10000.0 + w);
}

/// G × Sw: a sweep of gravity (the Earth's and the Moon's) on the hanging chain equals the
/// runs written by hand, each on its closed form.
#[test]
fn a_sweep_of_gravity_equals_the_runs_written_by_hand() {
    let make = |v: &str| chain(&format!("gravity = {v}"), "", "");
    let runs = sweep_equals_single_runs(
        &make,
        &chain_files(),
        "gravity",
        &["[0.0, -9.81]", "[0.0, -1.62]"],
    );
    assert_hanging_chain(&runs[0], 9.81);
    assert_hanging_chain(&runs[1], 1.62);
}

// ================================================================= iterative (It)

/// It × AL: refused. An arc-length path counts the tangent's negative pivots, which needs a
/// factorization: `solver = "iterative"` with it is an error naming the body.
#[test]
fn arc_length_with_the_iterative_solver_is_refused_naming_the_body() {
    let files = vm_files();
    let text = von_mises(
        4,
        "",
        "",
        &format!("solver = \"iterative\"\n{ARC}"),
        &apex_load(10000.0),
        false,
    );
    let e = try_run(&text, &refs(&files))
        .err()
        .expect("arc length with the iterative solver is refused");
    assert!(e.contains("truss") && e.contains("iterative"), "{e}");
}

/// It × Sw: a sweep of the solver (direct, iterative) on the pressed vee equals the runs
/// written by hand, which agree (1e-9).
#[test]
fn a_sweep_of_the_solver_equals_the_runs_written_by_hand() {
    let make = |v: &str| {
        vee(
            2,
            "",
            "",
            "",
            &format!("solver = {v}\niterative = {{ tolerance = 1e-12 }}"),
            &pressure(5000.0),
        )
    };
    let files = vee_files();
    let text = format!(
        "{}\n[sweep]\n\"bodies.vee.solver\" = [\"direct\", \"iterative\"]\n",
        make("\"direct\"")
    );
    let path = folder().join("sweep.toml");
    let variants = expand_sweep(&text, &path).unwrap();
    assert_eq!(variants.len(), 2);
    let mut hands = Vec::new();
    for (variant, v) in variants.iter().zip(["\"direct\"", "\"iterative\""]) {
        let swept = try_run_at(&variant.text, &files, "sweep.toml").unwrap();
        let hand = run(&make(v), &files);
        assert_same(&swept, &hand);
        hands.push(hand);
    }
    assert_eq!(hands[0].summary.bodies[0].solver, "direct");
    assert!(hands[1].summary.bodies[0].solver.starts_with("iterative"));
    assert_close("agree", hands[1].u(0, 1)[1], hands[0].u(0, 1)[1], 1e-9);
}

// ================================================================= arc length (AL)

/// AL × Sw: a sweep of the arc length (3 and 4.5 mm) on the von Mises truss equals the runs
/// written by hand, each on the closed form through the limit point.
#[test]
fn a_sweep_of_the_arc_length_equals_the_runs_written_by_hand() {
    let files = vm_files();
    let make = |v: &str| {
        von_mises(
            30,
            "",
            "",
            &ARC.replace("0.0045", v),
            &apex_load(10000.0),
            false,
        )
    };
    let runs = sweep_equals_single_runs(
        &make,
        &refs(&files),
        "bodies.truss.path.arc_length",
        &["0.003", "0.0045"],
    );
    for r in &runs {
        assert_on_the_von_mises_path(r, 10000.0);
    }
}
