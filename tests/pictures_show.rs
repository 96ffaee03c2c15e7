//! Pictures that show what happened (issue 35): up is up, cracks are marked, obstacles let
//! the bodies behind them show through, a half-space seen from inside is a see-through plane,
//! and each body of a frame of several has its own colour.

use linkage::render::{
    draw_frame, view_for, Colouring, Frame, RenderOptions, Rgb, RunExtent, BODY_COLOURS, CRACK_RED,
};
use linkage::scene::{
    load_scene, run, BodyFracture, BodyResult, ModelFile, RunResults, StepResult,
};
use nalgebra::Vector3;
use std::path::{Path, PathBuf};

fn scene(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("scenes/{name}.toml"))
}

fn options() -> RenderOptions {
    RenderOptions {
        width: 640,
        height: 360,
        ..RenderOptions::default()
    }
}

fn v3(p: &[f64]) -> Vector3<f64> {
    Vector3::new(p[0], p[1], p.get(2).copied().unwrap_or(0.0))
}

/// `model` at rest: zero displacements and stresses, members `broken[b]` (1-based) of body
/// `b` broken.
fn at_rest(model: &ModelFile, broken: &[Vec<usize>]) -> StepResult {
    StepResult {
        step: 0,
        load_factor: 0.0,
        time: None,
        bodies: model
            .bodies
            .iter()
            .enumerate()
            .map(|(i, b)| BodyResult {
                name: b.name.clone(),
                displacements: vec![vec![0.0; b.dimension]; b.nodes.len()],
                positions: b.nodes.clone(),
                axial_forces: vec![0.0; b.members.len()],
                strains: vec![0.0; b.members.len()],
                stresses: vec![0.0; b.members.len()],
                overloaded: vec![],
                reactions: vec![],
                loads: vec![],
                contacts: vec![],
                fracture: broken.get(i).map(|list| BodyFracture {
                    broken: list.clone(),
                    breaks: vec![],
                    fallen: vec![],
                    collapse: false,
                }),
                velocities: vec![],
            })
            .collect(),
    }
}

fn extent(model: &ModelFile, step: &StepResult) -> RunExtent {
    RunExtent::measure(model, &[0], Some(1.0), |_| Ok::<_, ()>(step.clone())).unwrap()
}

fn near(a: Rgb, b: Rgb, tol: f32) -> bool {
    (a.0 - b.0).abs() <= tol && (a.1 - b.1).abs() <= tol && (a.2 - b.2).abs() <= tol
}

/// Pixels of `frame` within `tol` of `colour`.
fn count(frame: &Frame, colour: Rgb, tol: f32) -> usize {
    (0..frame.height())
        .flat_map(|y| (0..frame.width()).map(move |x| (x, y)))
        .filter(|&(x, y)| near(frame.rgb(x, y).unwrap(), colour, tol))
        .count()
}

/// Pixel bounding box of the projected nodes of body 0, and the mean pixel height of its
/// nodes at the lowest and highest z.
fn block_on_screen(model: &ModelFile, o: &RenderOptions, ext: &RunExtent) -> [f32; 6] {
    let view = view_for(o, ext);
    let nodes: Vec<Vector3<f64>> = model.bodies[0].nodes.iter().map(|p| v3(p)).collect();
    let (zlo, zhi) = nodes
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.z), b.max(p.z)));
    let mut b = [f32::MAX, f32::MAX, f32::MIN, f32::MIN];
    let (mut base, mut nb, mut top, mut nt) = (0.0, 0.0, 0.0, 0.0);
    for p in &nodes {
        let q = view.project(p);
        b = [
            b[0].min(q[0]),
            b[1].min(q[1]),
            b[2].max(q[0]),
            b[3].max(q[1]),
        ];
        if (p.z - zlo).abs() < 1e-9 {
            base += q[1];
            nb += 1.0;
        }
        if (p.z - zhi).abs() < 1e-9 {
            top += q[1];
            nt += 1.0;
        }
    }
    [b[0], b[1], b[2], b[3], base / nb, top / nt]
}

#[test]
fn wedge_split_stands_on_its_base() {
    let world = load_scene(&scene("wedge_split")).unwrap();
    let model = ModelFile::new(&world);
    assert_eq!(model.up, Some([0.0, 0.0, 1.0]));
    let step = at_rest(&model, &[]);
    let o = options();
    let ext = extent(&model, &step);
    let [x0, y0, x1, y1, base, top] = block_on_screen(&model, &o, &ext);
    let (w, h) = (x1 - x0, y1 - y0);
    // The 0.2 m cube seen from 25° above its base: taller than wide (pixel y points down),
    // the base at the bottom of the picture, the top face at the top.
    assert!(h > w, "{w} px wide, {h} px high");
    assert!(base > top + 0.5 * h, "base at {base} px, top at {top} px");
    // The wedge above the block: its lowest vertex (the edge along y) is above the top face.
    let view = view_for(&o, &ext);
    let wedge_low = model.obstacles[0]
        .vertices
        .iter()
        .map(|v| view.project(&Vector3::from(*v))[1])
        .fold(f32::MIN, f32::max);
    assert!(
        wedge_low < base,
        "wedge's lowest pixel {wedge_low}, base {base}"
    );
    // Drawn with +y up instead (the old default), the base would not be at the bottom.
    let mut lying = model.clone();
    lying.up = None;
    let ext_y = extent(&lying, &step);
    let [_, y0, _, y1, base, top] = block_on_screen(&lying, &o, &ext_y);
    assert!(
        base <= top + 0.5 * (y1 - y0),
        "y-up: base {base}, top {top}"
    );
}

#[test]
fn wedge_split_frames_show_the_crack_on_the_surface_and_through_the_wedge() {
    let world = load_scene(&scene("wedge_split")).unwrap();
    let model = ModelFile::new(&world);
    let body = &model.bodies[0];
    // Break every member crossing the plane x = 0.09 m (between node planes 0.067 and 0.1).
    let crossing: Vec<usize> = body
        .members
        .iter()
        .enumerate()
        .filter(|(_, m)| {
            let (a, b) = (body.nodes[m[0] - 1][0], body.nodes[m[1] - 1][0]);
            a.min(b) < 0.09 && a.max(b) > 0.09
        })
        .map(|(j, _)| j + 1)
        .collect();
    assert!(crossing.len() > 50, "{}", crossing.len());
    let o = options();
    let whole = at_rest(&model, &[]);
    let split = at_rest(&model, &[crossing]);
    let ext = extent(&model, &whole);
    let red = |f: &Frame| count(f, CRACK_RED, 0.08);
    let f_whole = draw_frame(&model, &whole, &ext, &o).unwrap();
    let f_split = draw_frame(&model, &split, &ext, &o).unwrap();
    assert_eq!(red(&f_whole), 0);
    let marks = red(&f_split);
    assert!(marks > 300, "{marks} crack-red pixels");
    // The wedge in front of the block lets the block show through: drawn plain, the top
    // centre of the block (behind the wedge) keeps the surface's blue tint, where an opaque
    // wedge would be its warm grey; and the wedge changes the pixel, so it is there. The
    // point (0.05, 0.15, 0.2) lies on the top face just behind the wedge's lower edge as the
    // camera (at +x, −y, above) sees it.
    let plain = RenderOptions {
        colouring: Colouring::Plain,
        ..options()
    };
    let view = view_for(&plain, &ext);
    let q = view.project(&Vector3::new(0.05, 0.15, 0.2));
    let (x, y) = (q[0].round() as u32, q[1].round() as u32);
    let with = draw_frame(&model, &whole, &ext, &plain)
        .unwrap()
        .rgb(x, y)
        .unwrap();
    let mut bare = model.clone();
    bare.obstacles.clear();
    let without = draw_frame(&bare, &whole, &ext, &plain)
        .unwrap()
        .rgb(x, y)
        .unwrap();
    assert!(without.2 > without.0, "the block alone: {without:?}");
    assert!(with.2 > with.0, "the block through the wedge: {with:?}");
    assert!(
        (with.0 - without.0).abs() + (with.2 - without.2).abs() > 0.02,
        "the wedge is drawn: {with:?} {without:?}"
    );
    // The wedge alone (no body behind it): opaque, its warm grey.
    let wedge_top = view.project(&Vector3::new(0.1, 0.1, 0.33));
    let c = draw_frame(&model, &whole, &ext, &plain)
        .unwrap()
        .rgb(wedge_top[0].round() as u32, wedge_top[1].round() as u32)
        .unwrap();
    assert!(c.2 < 0.92 * c.0, "the wedge above the block: {c:?}");
}

#[test]
fn notched_beams_last_frame_shows_its_broken_members_in_red() {
    let out = tempfile::tempdir().unwrap();
    let world = load_scene(&scene("notched_beam")).unwrap();
    run(&world, out.path(), &|| {}).unwrap();
    let results = RunResults::read(&out.path().join(&world.name)).unwrap();
    let o = options();
    let ext = RunExtent::of_run(&results, None);
    let view = view_for(&o, &ext);
    let last = results.steps.last().unwrap();
    let frame = draw_frame(&results.model, last, &ext, &o).unwrap();
    let b = &results.model.bodies[0];
    let r = &last.bodies[0];
    let broken = &r.fracture.as_ref().unwrap().broken;
    assert!(broken.len() > 10, "{} broken", broken.len());
    // At each broken member's middle (drawn, magnified position): the crack's red.
    let drawn = |n: usize| v3(&b.nodes[n - 1]) + v3(&r.displacements[n - 1]) * ext.magnification;
    let red = broken
        .iter()
        .filter(|&&j| {
            let m = b.members[j - 1];
            let q = view.project(&((drawn(m[0]) + drawn(m[1])) / 2.0));
            near(
                frame.rgb(q[0].round() as u32, q[1].round() as u32).unwrap(),
                CRACK_RED,
                0.08,
            )
        })
        .count();
    // (An arrow or a neighbour's black overloaded line may cover a few.)
    assert!(
        red * 10 >= broken.len() * 8,
        "{red} of {} broken members show red",
        broken.len()
    );
    // The first frame has no crack: no crack-red pixel.
    let first = draw_frame(&results.model, &results.steps[0], &ext, &o).unwrap();
    assert_eq!(count(&first, CRACK_RED, 0.08), 0);
}

#[test]
fn a_frame_of_two_bodies_shows_each_in_its_own_colour() {
    let out = tempfile::tempdir().unwrap();
    let world = load_scene(&scene("two_disks")).unwrap();
    run(&world, out.path(), &|| {}).unwrap();
    let results = RunResults::read(&out.path().join(&world.name)).unwrap();
    assert_eq!(results.model.bodies.len(), 2);
    let o = options();
    let ext = RunExtent::of_run(&results, None);
    let frame = draw_frame(&results.model, results.steps.last().unwrap(), &ext, &o).unwrap();
    let tol = 2.0 / 255.0;
    let (a, b) = (
        count(&frame, BODY_COLOURS[0], tol),
        count(&frame, BODY_COLOURS[1], tol),
    );
    assert!(
        a > 200 && b > 200,
        "{a} and {b} pixels of the two body colours"
    );
    // Each colour on its own side: the first disk's pixels lie apart from the second's.
    let centre = |c: Rgb| {
        let (mut sx, mut sy, mut n) = (0.0, 0.0, 0.0);
        for y in 0..frame.height() {
            for x in 0..frame.width() {
                if near(frame.rgb(x, y).unwrap(), c, tol) {
                    sx += x as f64;
                    sy += y as f64;
                    n += 1.0;
                }
            }
        }
        (sx / n, sy / n)
    };
    let (ca, cb) = (centre(BODY_COLOURS[0]), centre(BODY_COLOURS[1]));
    let apart = ((ca.0 - cb.0).powi(2) + (ca.1 - cb.1).powi(2)).sqrt();
    assert!(apart > 60.0, "{ca:?} {cb:?}");
    // The body colour is a rim: inside each disk (within 0.6 of its radius on screen) next to
    // none of the body colour, and the members' stress colours show. The run's own stresses
    // are near zero inside (grey); drawn with the left disk's members all in tension (red) and
    // the right one's in compression (blue), the insides show red and blue.
    let limit = ext.stress_limit;
    let mut signed = results.steps.last().unwrap().clone();
    for (b, sign) in signed.bodies.iter_mut().zip([0.8, -0.8]) {
        b.stresses.iter_mut().for_each(|s| *s = sign * limit);
    }
    let coloured = draw_frame(&results.model, &signed, &ext, &o).unwrap();
    let view = view_for(&o, &ext);
    for (index, body) in results.model.bodies.iter().enumerate() {
        let nodes: Vec<[f32; 3]> = body.nodes.iter().map(|p| view.project(&v3(p))).collect();
        let n = nodes.len() as f32;
        let c = nodes
            .iter()
            .fold([0.0f32; 2], |s, p| [s[0] + p[0] / n, s[1] + p[1] / n]);
        let radius = nodes
            .iter()
            .map(|p| ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2)).sqrt())
            .fold(0.0f32, f32::max);
        assert!(radius > 40.0, "body {index}: {radius} pixels of radius");
        let (mut inside, mut own, mut stress) = (0usize, 0usize, 0usize);
        for y in 0..frame.height() {
            for x in 0..frame.width() {
                let d = ((x as f32 + 0.5 - c[0]).powi(2) + (y as f32 + 0.5 - c[1]).powi(2)).sqrt();
                if d > 0.6 * radius {
                    continue;
                }
                inside += 1;
                if BODY_COLOURS
                    .iter()
                    .any(|&b| near(frame.rgb(x, y).unwrap(), b, 0.06))
                {
                    own += 1;
                }
                // Red (tension) in the left disk, blue (compression) in the right one.
                let p = coloured.rgb(x, y).unwrap();
                let warm = if index == 0 { p.0 - p.2 } else { p.2 - p.0 };
                if warm > 0.25 {
                    stress += 1;
                }
            }
        }
        eprintln!(
            "body {index}: {inside} pixels inside, {own} of a body colour, {stress} of its stress colour"
        );
        assert!(
            own * 100 < inside,
            "body {index}: {own} of {inside} pixels of a body colour"
        );
        assert!(
            stress * 20 > inside,
            "body {index}: {stress} of {inside} pixels of its stress colour"
        );
    }
    // A single body keeps the plain look: none of the body colours.
    let mut one = results.model.clone();
    one.bodies.truncate(1);
    let mut step = results.steps.last().unwrap().clone();
    step.bodies.truncate(1);
    let single = draw_frame(&one, &step, &ext, &o).unwrap();
    assert_eq!(count(&single, BODY_COLOURS[0], tol), 0);
}

/// A 1 m cube 0.2 m under a half-space above it (its outward normal points down, to the
/// cube): the default camera, 25° above, sees the plane from inside.
const PRESSED: &str = r#"name = "pressed"
steps = 1
[[materials]]
name = "m"
youngs_modulus = 1e9
area = 1e-4

[[bodies]]
name = "cube"
box_lattice = { size = [1.0, 1.0, 1.0], cells = [2, 2, 2] }
material = "m"

[[bodies.supports]]
on_plane = { point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }
fix = ["x", "y", "z"]

[[obstacles]]
name = "press"
shape = "half_space"
point = [0.5, 1.2, 0.5]
normal = [0.0, -1.0, 0.0]
"#;

#[test]
fn a_half_space_seen_from_inside_is_a_see_through_plane() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("pressed.toml"), PRESSED).unwrap();
    let world = load_scene(&dir.path().join("pressed.toml")).unwrap();
    let model = ModelFile::new(&world);
    let step = at_rest(&model, &[]);
    let o = RenderOptions {
        colouring: Colouring::Plain,
        ..options()
    };
    let ext = extent(&model, &step);
    let with = draw_frame(&model, &step, &ext, &o).unwrap();
    let mut bare = model.clone();
    bare.obstacles.clear();
    let without = draw_frame(&bare, &step, &ext, &o).unwrap();
    let view = view_for(&o, &ext);
    let at = |f: &Frame, p: [f64; 3]| {
        let q = view.project(&Vector3::new(p[0], p[1], p[2]));
        f.rgb(q[0].round() as u32, q[1].round() as u32).unwrap()
    };
    // On the plane (y = 1.2) beyond the cube, where nothing lies behind: without the press,
    // white; with it, a light tint of the obstacle colour (22 % over white), not opaque.
    let beside = [-0.25, 1.2, -0.25];
    assert_eq!(at(&without, beside), Rgb(1.0, 1.0, 1.0));
    let c = at(&with, beside);
    assert!(c != Rgb(1.0, 1.0, 1.0) && c.0 > 0.75 && c.2 < c.0, "{c:?}");
    // The centre of the cube's top face, seen through the plane: still its blue tint, close
    // to the cube drawn alone.
    let face = [0.5, 1.0, 0.5];
    let (a, b) = (at(&with, face), at(&without, face));
    assert!(a.2 > a.0 && (a.0 - b.0).abs() < 0.25, "{a:?} {b:?}");
}

#[test]
fn a_contact_scene_is_magnified_as_far_as_nothing_crosses_what_it_touches() {
    const SCENE: &str = "disk_on_floor";
    let out = tempfile::tempdir().unwrap();
    let world = load_scene(&scene(SCENE)).unwrap();
    run(&world, out.path(), &|| {}).unwrap();
    let results = RunResults::read(&out.path().join(&world.name)).unwrap();
    let ext = RunExtent::of_run(&results, None);
    assert!(ext.contact);
    eprintln!("{SCENE}: x{}", ext.magnification);
    // Asked to start from ×1000, the factor found stops where the floor would be crossed:
    // at it no node is drawn deeper in the floor (the exact half-space) than solved; at the
    // round factor above it, some node is (the disk pressed onto the floor: ×1, as ×2
    // draws its foot through the floor).
    let obstacles = linkage::contact::Obstacles::new(&world.obstacles).unwrap();
    let deepest_excess = |m: f64| {
        let mut worst = f64::NEG_INFINITY;
        for step in &results.steps {
            let offset = Vector3::from(results.model.obstacles[0].offsets[step.step]);
            for (b, r) in results.model.bodies.iter().zip(&step.bodies) {
                for (p, u) in b.nodes.iter().zip(&r.displacements) {
                    let d = |k: f64| {
                        obstacles
                            .project(0, &(v3(p) + v3(u) * k), &offset)
                            .unwrap()
                            .depth
                    };
                    worst = worst.max(d(m) - d(1.0).max(0.0));
                }
            }
        }
        worst
    };
    let m = linkage::render::contact_magnification(&results.model, &results.steps, 1000.0);
    let factors = linkage::render::round_factors_down(1000.0);
    let i = factors.iter().position(|&f| f == m).unwrap();
    eprintln!("{SCENE} from x1000: x{m}");
    assert!(i > 0 && m >= 1.0, "x{m}");
    assert!(deepest_excess(m) <= 1e-9, "x{m}: {}", deepest_excess(m));
    assert!(
        deepest_excess(factors[i - 1]) > 0.0,
        "x{}: {}",
        factors[i - 1],
        deepest_excess(factors[i - 1])
    );
}

/// Two 3D trusses (unit cubes of 12 edges and a diagonal on each face, no surface patches),
/// the second 1.05 m beside the first along x, each held at its four bottom nodes and pressed
/// down at a top node.
fn two_trusses(dir: &Path) -> PathBuf {
    let cube = |x0: f64| -> String {
        let mut nodes = String::new();
        for (x, y, z) in [
            (0., 0., 0.),
            (1., 0., 0.),
            (1., 0., 1.),
            (0., 0., 1.),
            (0., 1., 0.),
            (1., 1., 0.),
            (1., 1., 1.),
            (0., 1., 1.),
        ] {
            nodes.push_str(&format!("{} {y} {z}\n", x0 + x));
        }
        nodes
    };
    std::fs::write(dir.join("left.nodes"), cube(0.0)).unwrap();
    std::fs::write(dir.join("right.nodes"), cube(1.05)).unwrap();
    std::fs::write(
        dir.join("cube.links"),
        "1 2\n2 3\n3 4\n4 1\n5 6\n6 7\n7 8\n8 5\n1 5\n2 6\n3 7\n4 8\n1 3\n5 7\n1 6\n2 7\n3 8\n4 5\n",
    )
    .unwrap();
    let body = |name: &str| {
        format!(
            "[[bodies]]\nname = \"{name}\"\nnodes = \"{name}.nodes\"\nlinks = \"cube.links\"\nmaterial = \"steel\"\n\n\
             [[bodies.supports]]\nnodes = [1, 2, 3, 4]\nfix = [\"x\", \"y\", \"z\"]\n\n\
             [[bodies.loads]]\nnodes = [7]\nforce = [0.0, -1000.0, 0.0]\n\n"
        )
    };
    let text = format!(
        "name = \"trusses\"\nsteps = 1\n\n[[materials]]\nname = \"steel\"\nyoungs_modulus = 200e9\narea = 1e-4\n\n{}{}",
        body("left"),
        body("right")
    );
    let path = dir.join("trusses.toml");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn a_frame_of_two_3d_trusses_without_patches_shows_each_in_its_own_colour() {
    let out = tempfile::tempdir().unwrap();
    let world = load_scene(&two_trusses(out.path())).unwrap();
    run(&world, out.path(), &|| {}).unwrap();
    let results = RunResults::read(&out.path().join(&world.name)).unwrap();
    assert_eq!(results.model.bodies.len(), 2);
    assert!(results
        .model
        .bodies
        .iter()
        .all(|b| b.dimension == 3 && b.patches.is_empty()));
    let o = options();
    let ext = RunExtent::of_run(&results, None);
    let frame = draw_frame(&results.model, results.steps.last().unwrap(), &ext, &o).unwrap();
    let tol = 2.0 / 255.0;
    let (a, b) = (
        count(&frame, BODY_COLOURS[0], tol),
        count(&frame, BODY_COLOURS[1], tol),
    );
    eprintln!("{a} and {b} pixels of the two body colours");
    assert!(
        a > 200 && b > 200,
        "{a} and {b} pixels of the two body colours"
    );
    // Each colour where its truss is: the mean pixel of the first colour left of the
    // second's by at least a third of the trusses' on-screen distance.
    let view = view_for(&o, &ext);
    let centre_on_screen = |k: usize| {
        let nodes = &results.model.bodies[k].nodes;
        let n = nodes.len() as f32;
        nodes.iter().map(|p| view.project(&v3(p))[0]).sum::<f32>() / n
    };
    let mean_x = |c: Rgb| {
        let (mut sx, mut n) = (0.0f32, 0.0f32);
        for y in 0..frame.height() {
            for x in 0..frame.width() {
                if near(frame.rgb(x, y).unwrap(), c, tol) {
                    sx += x as f32;
                    n += 1.0;
                }
            }
        }
        sx / n
    };
    let (ca, cb) = (mean_x(BODY_COLOURS[0]), mean_x(BODY_COLOURS[1]));
    let (ta, tb) = (centre_on_screen(0), centre_on_screen(1));
    eprintln!("colours at x = {ca}, {cb}; trusses at x = {ta}, {tb}");
    assert!(tb - ta > 60.0, "the trusses {ta} and {tb} apart on screen");
    assert!(
        (ca - ta).abs() < (tb - ta) / 3.0 && (cb - tb).abs() < (tb - ta) / 3.0,
        "colours at {ca}, {cb}; trusses at {ta}, {tb}"
    );
}
