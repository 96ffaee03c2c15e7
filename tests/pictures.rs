//! What frames show of contact and fracture: obstacles drawn where they are (2D bands, 3D
//! surfaces through the depth buffer), contact and applied forces on one scale, magnification
//! that keeps bodies out of obstacles, broken members left out, the GIF's palette and the
//! `--out` folder.

use linkage::contact::Obstacles;
use linkage::render::{
    draw_frame, frame_primitives, render_run_to, view_for, Frame, GifAnimation, Primitive,
    RenderOptions, Rgb, RunExtent, StepSelection, CONTACT_ORANGE, CRACK_RED, FORCE_BLUE,
    OBSTACLE_FILL,
};
use linkage::scene::{load_scene, run, ContactForce, NodeForce, RunResults};
use nalgebra::Vector3;
use std::path::{Path, PathBuf};

fn scene(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("scenes/{name}.toml"))
}

/// Solve bundled scene `name` into `out` (no pictures) and read its results back.
fn solve(name: &str, out: &Path) -> (linkage::scene::World, RunResults) {
    let world = load_scene(&scene(name)).unwrap();
    run(&world, out, &|| {}).unwrap();
    let results = RunResults::read(&out.join(&world.name)).unwrap();
    (world, results)
}

fn options() -> RenderOptions {
    RenderOptions {
        width: 640,
        height: 360,
        ..RenderOptions::default()
    }
}

fn pixel(frame: &Frame, options: &RenderOptions, ext: &RunExtent, p: [f64; 3]) -> Rgb {
    let q = view_for(options, ext).project(&Vector3::new(p[0], p[1], p[2]));
    frame.rgb(q[0].round() as u32, q[1].round() as u32).unwrap()
}

fn near(a: Rgb, b: Rgb, tol: f32) -> bool {
    (a.0 - b.0).abs() <= tol && (a.1 - b.1).abs() <= tol && (a.2 - b.2).abs() <= tol
}

#[test]
fn the_floor_band_below_a_2d_disk_is_filled_in_the_obstacle_colour() {
    let out = tempfile::tempdir().unwrap();
    let (_, results) = solve("disk_on_floor", out.path());
    let o = options();
    let ext = RunExtent::of_run(&results, None);
    let last = results.steps.last().unwrap();
    let frame = draw_frame(&results.model, last, &ext, &o).unwrap();
    // The floor's boundary is y = -0.1 m; the band is 0.12 bounding diagonals (0.034 m) deep.
    for x in [-0.06, 0.06] {
        let inside = pixel(&frame, &o, &ext, [x, -0.115, 0.0]);
        assert!(near(inside, OBSTACLE_FILL, 2.0 / 255.0), "{x}: {inside:?}");
        // Below the band and beside the disk above the floor: background.
        let below = pixel(&frame, &o, &ext, [x, -0.16, 0.0]);
        assert!(near(below, Rgb(1.0, 1.0, 1.0), 1e-6), "{x}: {below:?}");
        let above = pixel(&frame, &o, &ext, [x * 2.2, -0.05, 0.0]);
        assert!(near(above, Rgb(1.0, 1.0, 1.0), 1e-6), "{x}: {above:?}");
    }
    // The camera takes in the floor near the disk, not the whole square model.json stores
    // (4 diagonals wide): the box stays within a quarter diagonal of the disk.
    let diagonal = (0.2f64 * 0.2 * 2.0).sqrt();
    assert!(
        ext.max.x - ext.min.x < 0.2 + 2.0 * 0.25 * diagonal + 0.1 * diagonal,
        "{:?} {:?}",
        ext.min,
        ext.max
    );
}

#[test]
fn a_3d_block_shows_where_it_is_and_hides_behind_the_shell_in_front() {
    let out = tempfile::tempdir().unwrap();
    let (_, results) = solve("shell_on_block", out.path());
    let o = options();
    let ext = RunExtent::of_run(&results, None);
    let last = results.steps.last().unwrap();
    let with = draw_frame(&results.model, last, &ext, &o).unwrap();
    let mut bare = results.model.clone();
    bare.obstacles.clear();
    let without = draw_frame(&bare, last, &ext, &o).unwrap();
    // The block: centre (1.93, -0.35, 0), half extents (0.15, 0.1, 0.3). Its front face
    // (z = 0.3) faces the default camera below the shell: a shade of the obstacle colour
    // (its blue well below its red, as the warm grey's), on white without the block.
    let front = [1.93, -0.4, 0.3];
    let block = pixel(&with, &o, &ext, front);
    assert_eq!(pixel(&without, &o, &ext, front), Rgb(1.0, 1.0, 1.0));
    assert!(
        block.0 < 0.95 && block.2 < 0.92 * block.0 && (block.0 - block.1).abs() < 0.06,
        "{block:?}"
    );
    // The top face under the shell's end is hidden by the shell: the pixel is the shell's,
    // the same with and without the block.
    let under = [1.9, -0.25, 0.0];
    let shell = pixel(&without, &o, &ext, under);
    assert_ne!(shell, Rgb(1.0, 1.0, 1.0), "the shell covers this point");
    assert_eq!(pixel(&with, &o, &ext, under), shell);
    // Block pixels exist at all, and many of them.
    let q = |c: Rgb| c.0 < 0.95 && c.2 < 0.92 * c.0 && (c.0 - c.1).abs() < 0.06;
    let count = |f: &Frame| {
        (0..f.height())
            .flat_map(|y| (0..f.width()).map(move |x| (x, y)))
            .filter(|&(x, y)| q(f.rgb(x, y).unwrap()))
            .count()
    };
    let (a, b) = (count(&with), count(&without));
    assert!(
        a > b + 2000,
        "{a} block-coloured pixels with the block, {b} without"
    );
}

#[test]
fn a_contact_arrow_is_as_long_as_a_load_arrow_of_the_same_force() {
    let out = tempfile::tempdir().unwrap();
    let (_, mut results) = solve("disk_on_floor", out.path());
    // Only the last step, with one contact and one load of the same size.
    let kept = results.steps.pop().unwrap();
    results.steps = vec![kept];
    let step = results.steps.last_mut().unwrap();
    let b = &mut step.bodies[0];
    b.contacts = vec![ContactForce {
        node: 5,
        with: "floor".into(),
        depth: 1e-4,
        force: vec![0.0, 123.0],
        normal: vec![0.0, 1.0],
        normal_force: 123.0,
        tangential_force: vec![0.0, 0.0],
        state: "slip".into(),
        slip: vec![0.0, 0.0],
    }];
    b.loads = vec![NodeForce {
        node: 9,
        force: vec![0.0, -123.0],
    }];
    let ext = RunExtent::of_run(&results, None);
    let last = results.steps.last().unwrap();
    let length = |colour: Rgb| {
        let lengths: Vec<f64> = frame_primitives(&results.model, last, &ext, &options())
            .iter()
            .filter_map(|p| match p {
                Primitive::Arrow {
                    tail,
                    tip,
                    colour: c,
                    ..
                } if *c == colour => Some((tip - tail).norm()),
                _ => None,
            })
            .collect();
        assert_eq!(lengths.len(), 1, "{colour:?}");
        lengths[0]
    };
    let (contact, load) = (length(CONTACT_ORANGE), length(FORCE_BLUE));
    assert!(contact > 0.0);
    // One scale: equal forces, equal arrows (to rounding).
    assert!(
        (contact - load).abs() <= 1e-12 * load,
        "{contact} m against {load} m"
    );
    // The largest force of the run (here both) is 15% of the bodies' diagonal.
    assert!((load - 0.15 * ext.size).abs() <= 1e-12 * load, "{load}");
}

#[test]
fn no_drawn_node_lies_inside_an_obstacle_at_automatic_magnification() {
    let scenes = [
        "disk_on_floor",
        "two_disks",
        "shell_on_block",
        "shell_on_block_moving",
        "stack",
        "block_pulled",
        "block_on_slope",
        "ring_press",
        "shell_on_block_friction",
    ];
    let out = tempfile::tempdir().unwrap();
    for name in scenes {
        let (world, results) = solve(name, out.path());
        let ext = RunExtent::of_run(&results, None);
        // Bodies touching obstacles or each other are magnified only as far as they stay out
        // of what they touch (checked below against the exact obstacles), never below 1.
        assert!(ext.magnification >= 1.0, "{name}");
        assert!(ext.contact, "{name}");
        eprintln!("{name}: displacements x{}", ext.magnification);
        let obstacles = Obstacles::new(&world.obstacles).unwrap();
        for step in &results.steps {
            for (m, r) in results.model.bodies.iter().zip(&step.bodies) {
                // A node may be inside by the penetration the penalty method solved for (the
                // depth its contact reports), never deeper.
                let allowed = r.contacts.iter().map(|c| c.depth).fold(0.0, f64::max) + 1e-9;
                for (n, (p, u)) in m.nodes.iter().zip(&r.displacements).enumerate() {
                    let v = |x: &[f64]| Vector3::new(x[0], x[1], x.get(2).copied().unwrap_or(0.0));
                    let drawn = v(p) + v(u) * ext.magnification;
                    for (k, o) in results.model.obstacles.iter().enumerate() {
                        let offset = Vector3::from(o.offsets[step.step]);
                        let depth = obstacles.project(k, &drawn, &offset).unwrap().depth;
                        assert!(
                            depth <= allowed,
                            "{name} step {}: body '{}' node {} drawn {depth} m inside '{}' (solved depth {allowed})",
                            step.step,
                            r.name,
                            n + 1,
                            o.name
                        );
                    }
                }
            }
        }
    }
}

/// A bundle of three parallel members pulled by a prescribed displacement: the weak one
/// (90 MPa) breaks at step 2 of 4 (stress 50 MPa per step), the others hold.
const BUNDLE: &str = r#"name = "bundle"
steps = 4
[[materials]]
name = "weak"
youngs_modulus = 200e9
area = 1e-4
tensile_strength = 90e6
failure = "break"

[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4
tensile_strength = 250e6
failure = "break"

[[bodies]]
name = "bundle"
nodes = "bundle.nodes"
links = "bundle.links"
material = "steel"

[[bodies.supports]]
nodes = [1, 2, 3]
fix = ["x", "y"]

[[bodies.supports]]
nodes = [4]
fix = ["x", "y"]
displacement = [0.0, 1e-3]

[[bodies.supports]]
nodes = [5, 6]
fix = ["y"]
displacement = [0.0, 1e-3]

[output]
magnification = 1.0
"#;

#[test]
fn broken_members_are_left_out_of_the_frame_so_the_crack_shows() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("bundle.nodes"), "0 0\n1 0\n2 0\n0 1\n1 1\n2 1\n").unwrap();
    std::fs::write(
        d.join("bundle.links"),
        "1 4 weak\n2 5 steel\n3 6 steel\n4 5 steel\n5 6 steel\n",
    )
    .unwrap();
    std::fs::write(d.join("bundle.toml"), BUNDLE).unwrap();
    let world = load_scene(&d.join("bundle.toml")).unwrap();
    run(&world, &d.join("out"), &|| {}).unwrap();
    let results = RunResults::read(&d.join("out/bundle")).unwrap();
    let o = RenderOptions {
        magnification: Some(1.0),
        ..options()
    };
    let ext = RunExtent::of_run(&results, Some(1.0));
    let frame_of = |k: usize| draw_frame(&results.model, &results.steps[k], &ext, &o).unwrap();
    let broken = |k: usize| {
        results.steps[k].bodies[0]
            .fracture
            .as_ref()
            .map_or(0, |f| f.broken.len())
    };
    assert_eq!((broken(1), broken(2), broken(4)), (0, 1, 1));
    let mid_weak = [0.0, 0.5, 0.0];
    let mid_steel = [1.0, 0.5, 0.0];
    let tinted = |c: Rgb| (c.0 - c.2).abs() > 0.15;
    // Intact at step 1: the weak member is drawn in its tension colour.
    let f1 = frame_of(1);
    assert!(tinted(pixel(&f1, &o, &ext, mid_weak)));
    // Broken from step 2 on: the member is gone, a short red mark says where it was; its
    // neighbour still shows its stress.
    let crack = |c: Rgb| near(c, CRACK_RED, 0.05);
    assert!(!crack(pixel(&f1, &o, &ext, mid_weak)));
    for k in [2, 4] {
        let f = frame_of(k);
        let c = pixel(&f, &o, &ext, mid_weak);
        assert!(crack(c), "step {k}: {c:?}");
        assert!(tinted(pixel(&f, &o, &ext, mid_steel)), "step {k}");
        // Beyond the mark (the member's outer quarters): no member drawn, only the ghost.
        let c = pixel(&f, &o, &ext, [0.0, 0.12, 0.0]);
        assert!(!tinted(c) && c.0 > 0.6, "step {k}: {c:?}");
    }
    // No line of the drawing joins the broken member's nodes; the mark spans its middle half.
    let prims = frame_primitives(&results.model, &results.steps[4], &ext, &o);
    let on_broken = |a: &Vector3<f64>, b: &Vector3<f64>| a.x.abs() < 1e-9 && b.x.abs() < 1e-9;
    let joins = prims.iter().any(|p| match p {
        Primitive::Line {
            a,
            b,
            layer: linkage::render::Layer::Over,
            ..
        } => on_broken(a, b) && a.y.min(b.y) < 0.2,
        _ => false,
    });
    assert!(!joins, "the broken member is drawn");
    let marks: Vec<(f64, f64)> = prims
        .iter()
        .filter_map(|p| match p {
            Primitive::Line { a, b, colour, .. } if *colour == CRACK_RED => Some((a.y, b.y)),
            _ => None,
        })
        .collect();
    assert_eq!(marks.len(), 1, "{marks:?}");
    let (lo, hi) = (marks[0].0.min(marks[0].1), marks[0].0.max(marks[0].1));
    // Ends at 0 and 1 (+ the step's 1e-3 m at the top): the middle half.
    assert!(
        (lo - 0.25).abs() < 1e-3 && (hi - 0.75).abs() < 2e-3,
        "{lo} {hi}"
    );
}

#[test]
fn one_gif_palette_serves_every_frame_and_render_out_writes_elsewhere() {
    let out = tempfile::tempdir().unwrap();
    let (_, results) = solve("disk_on_floor", out.path());
    let o = options();
    let ext = RunExtent::of_run(&results, None);
    let frames: Vec<Frame> = results
        .steps
        .iter()
        .map(|s| draw_frame(&results.model, s, &ext, &o).unwrap())
        .collect();
    let refs: Vec<&Frame> = frames.iter().collect();
    let mut gif = GifAnimation::new(o.width, o.height, &refs).unwrap();
    for (i, f) in frames.iter().enumerate() {
        gif.push(f, i + 1 == frames.len()).unwrap();
    }
    let bytes = gif.finish().unwrap();
    // Decoded, every frame is within the dither and the palette's reach of what was drawn:
    // mean error per channel below 3 levels of 255.
    let mut decoder = {
        let mut d = gif::DecodeOptions::new();
        d.set_color_output(gif::ColorOutput::RGBA);
        d.read_info(&bytes[..]).unwrap()
    };
    let mut k = 0;
    while let Some(f) = decoder.read_next_frame().unwrap() {
        let drawn = frames[k].rgba();
        let err: u64 = f
            .buffer
            .iter()
            .zip(&drawn)
            .map(|(a, b)| (*a as i64 - *b as i64).unsigned_abs())
            .sum();
        let mean = err as f64 / drawn.len() as f64;
        assert!(mean < 3.0, "frame {k}: mean error {mean}");
        k += 1;
    }
    assert_eq!(k, frames.len());

    // `render --out`: the frames and the GIF go to the other folder; drawing fewer steps
    // there leaves only those.
    let dir = out.path().join("disk_on_floor");
    let elsewhere = out.path().join("pictures");
    render_run_to(&dir, &elsewhere, &o).unwrap();
    assert!(elsewhere.join("anim.gif").is_file());
    assert!(!dir.join("png").exists() && !dir.join("anim.gif").exists());
    let last = RenderOptions {
        steps: StepSelection::Last,
        gif: false,
        ..o.clone()
    };
    render_run_to(&dir, &elsewhere, &last).unwrap();
    let names: Vec<String> = std::fs::read_dir(elsewhere.join("png"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert_eq!(names, vec!["0004.png".to_string()]);
}
