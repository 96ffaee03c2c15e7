//! Pictures: what is drawn (colours, placement, shading), determinism, frames and GIF of a run.

use linkage::render::{
    draw_frame, render_run, view_for, viewport_for, Colouring, Frame, Projection, RenderOptions,
    Rgb, RunExtent, StepSelection,
};
use linkage::scene::{
    build_world, run_with, BodyResult, ModelBody, ModelFile, StepResult, SupportedNode,
};
use nalgebra::Vector3;
use std::path::Path;

/// A 2D square of four members with chosen stresses, undisplaced: member 1 (bottom) in
/// tension, 2 (top) in compression, 3 (left) overloaded, 4 (right) unstressed.
fn square() -> (ModelFile, StepResult) {
    let nodes = vec![
        vec![0.0, 0.0],
        vec![1.0, 0.0],
        vec![0.0, 1.0],
        vec![1.0, 1.0],
    ];
    let model = ModelFile {
        scene: "square".into(),
        obstacles: Vec::new(),
        up: None,
        bodies: vec![ModelBody {
            name: "b".into(),
            dimension: 2,
            nodes: nodes.clone(),
            members: vec![[1, 2], [3, 4], [1, 3], [2, 4]],
            patches: vec![],
            supports: vec![SupportedNode {
                node: 1,
                fix: vec!["x".into(), "y".into()],
            }],
            member_materials: Vec::new(),
            strengths: vec![[Some(8e6), Some(8e6)]; 4],
        }],
    };
    let stresses = vec![5e6, -5e6, 9e6, 0.0];
    let step = StepResult {
        step: 1,
        load_factor: 1.0,
        time: None,
        bodies: vec![BodyResult {
            name: "b".into(),
            displacements: vec![vec![0.0, 0.0]; 4],
            positions: nodes,
            axial_forces: stresses.iter().map(|s| s * 1e-4).collect(),
            strains: vec![0.0; 4],
            stresses,
            overloaded: vec![3],
            reactions: vec![],
            loads: vec![],
            contacts: vec![],
            fracture: None,
            velocities: Vec::new(),
        }],
    };
    (model, step)
}

fn extent(model: &ModelFile, step: &StepResult, magnification: Option<f64>) -> RunExtent {
    RunExtent::measure(model, &[1], magnification, |_| {
        Ok::<_, String>(step.clone())
    })
    .unwrap()
}

fn options() -> RenderOptions {
    RenderOptions {
        width: 640,
        height: 360,
        ..RenderOptions::default()
    }
}

/// The frame's colour at the projection of world point `p`.
fn colour_at(frame: &Frame, options: &RenderOptions, ext: &RunExtent, p: [f64; 3]) -> Rgb {
    let q = view_for(options, ext).project(&Vector3::new(p[0], p[1], p[2]));
    frame.rgb(q[0] as u32, q[1] as u32).unwrap()
}

#[test]
fn overloaded_member_is_black_tension_red_compression_blue() {
    let (model, step) = square();
    let ext = extent(&model, &step, Some(1.0));
    let o = options();
    let frame = draw_frame(&model, &step, &ext, &o).unwrap();
    let tension = colour_at(&frame, &o, &ext, [0.5, 0.0, 0.0]);
    let compression = colour_at(&frame, &o, &ext, [0.5, 1.0, 0.0]);
    let overloaded = colour_at(&frame, &o, &ext, [0.0, 0.5, 0.0]);
    let background = colour_at(&frame, &o, &ext, [0.5, 0.5, 0.0]);
    assert!(
        tension.0 > tension.2 + 0.2,
        "tension member should be reddish: {tension:?}"
    );
    assert!(
        compression.2 > compression.0 + 0.2,
        "compression member should be bluish: {compression:?}"
    );
    assert!(
        overloaded.0 < 0.1 && overloaded.1 < 0.1 && overloaded.2 < 0.1,
        "overloaded member should be black: {overloaded:?}"
    );
    assert!(
        background.0 > 0.95 && background.1 > 0.95 && background.2 > 0.95,
        "inside the square is white: {background:?}"
    );
}

#[test]
fn drawing_fills_the_viewport_and_stays_inside_it() {
    let (model, step) = square();
    let ext = extent(&model, &step, Some(1.0));
    let o = RenderOptions {
        colouring: Colouring::Plain,
        ..options()
    };
    let frame = draw_frame(&model, &step, &ext, &o).unwrap();
    let vp = viewport_for(&o);
    // Non-white pixels inside the viewport band (below the caption, above the footnote).
    let (mut x0, mut y0, mut x1, mut y1) = (u32::MAX, u32::MAX, 0, 0);
    for y in vp[1] as u32..vp[3] as u32 {
        for x in 0..frame.width() {
            let c = frame.rgb(x, y).unwrap();
            if c.0 < 0.9 || c.1 < 0.9 || c.2 < 0.9 {
                x0 = x0.min(x);
                x1 = x1.max(x);
                y0 = y0.min(y);
                y1 = y1.max(y);
            }
        }
    }
    // The square is fitted by height: it spans nearly all of the viewport's height, is
    // square on screen and centred horizontally in the viewport.
    let (vw, vh) = (vp[2] - vp[0], vp[3] - vp[1]);
    let (w, h) = ((x1 - x0) as f64, (y1 - y0) as f64);
    assert!(h > 0.85 * vh && h <= vh + 2.0, "height {h} of {vh}");
    assert!((w - h).abs() < 0.05 * h, "{w} × {h}");
    let centre = (x0 + x1) as f64 / 2.0;
    assert!(
        (centre - (vp[0] + vp[2]) / 2.0).abs() < 0.02 * vw,
        "centre {centre}"
    );
    assert!(x0 as f64 >= vp[0] - 15.0 && x1 as f64 <= vp[2] + 15.0);
}

/// Two separate triangles facing the viewer (+z), one tilted towards the key light (upper
/// left, in front), one tilted away from it.
fn two_patches() -> (ModelFile, StepResult) {
    let tri = |centre: [f64; 3], normal: Vector3<f64>| {
        let n = normal.normalize();
        let u = n.cross(&Vector3::y()).normalize();
        let v = n.cross(&u);
        let c = Vector3::from(centre);
        // Counter-clockwise about n (seen from where n points).
        [c + u * 0.5, c + v * 0.5, c - u * 0.4 - v * 0.4]
            .map(|p| vec![p.x, p.y, p.z])
            .to_vec()
    };
    let mut nodes = tri([0.0, 0.0, 0.0], Vector3::new(-0.45, 0.6, 0.66));
    nodes.extend(tri([1.5, 0.0, 0.0], Vector3::new(0.45, -0.6, 0.66)));
    let model = ModelFile {
        scene: "lit".into(),
        obstacles: Vec::new(),
        up: None,
        bodies: vec![ModelBody {
            name: "p".into(),
            dimension: 3,
            nodes: nodes.clone(),
            members: vec![[1, 2], [2, 3], [3, 1], [4, 5], [5, 6], [6, 4]],
            patches: vec![[1, 2, 3], [4, 5, 6]],
            supports: vec![],
            member_materials: Vec::new(),
            strengths: vec![],
        }],
    };
    let step = StepResult {
        step: 1,
        load_factor: 1.0,
        time: None,
        bodies: vec![BodyResult {
            name: "p".into(),
            displacements: vec![vec![0.0; 3]; 6],
            positions: nodes,
            axial_forces: vec![0.0; 6],
            strains: vec![0.0; 6],
            stresses: vec![0.0; 6],
            overloaded: vec![],
            reactions: vec![],
            loads: vec![],
            contacts: vec![],
            fracture: None,
            velocities: Vec::new(),
        }],
    };
    (model, step)
}

#[test]
fn patch_facing_the_light_is_brighter_than_one_facing_away() {
    let (model, step) = two_patches();
    let ext = extent(&model, &step, Some(1.0));
    let o = RenderOptions {
        colouring: Colouring::Plain,
        azimuth: Some(0.0),
        elevation: Some(0.0),
        projection: Some(Projection::Orthographic),
        ..options()
    };
    let frame = draw_frame(&model, &step, &ext, &o).unwrap();
    let centroid = |k: usize| {
        let n = &model.bodies[0].nodes[3 * k..3 * k + 3];
        [0, 1, 2].map(|i| n.iter().map(|p| p[i]).sum::<f64>() / 3.0)
    };
    let lum = |c: Rgb| 0.3 * c.0 + 0.59 * c.1 + 0.11 * c.2;
    let lit = colour_at(&frame, &o, &ext, centroid(0));
    let away = colour_at(&frame, &o, &ext, centroid(1));
    assert!(
        lum(lit) > lum(away) + 0.2,
        "lit {lit:?} should be brighter than away {away:?}"
    );
    // Both are drawn (not background white), and the unlit one is still visible (ambient).
    assert!(lum(lit) < 0.99 && lum(away) > 0.15 && lum(away) < 0.8);
}

#[test]
fn same_results_give_byte_identical_frames() {
    let (model, step) = two_patches();
    let ext = extent(&model, &step, None);
    let a = draw_frame(&model, &step, &ext, &options()).unwrap();
    let b = draw_frame(&model, &step, &ext, &options()).unwrap();
    assert_eq!(a.png().unwrap(), b.png().unwrap());
    let (model, step) = square();
    let ext = extent(&model, &step, None);
    let a = draw_frame(&model, &step, &ext, &options()).unwrap();
    let b = draw_frame(&model, &step, &ext, &options()).unwrap();
    assert_eq!(a.png().unwrap(), b.png().unwrap());
}

const OVERLOAD: &str = r#"
name = "small_overload"
steps = 4
[[materials]]
name = "brittle"
youngs_modulus = 10e9
area = 1e-4
strength = 4e6
[[bodies]]
name = "solid"
rectangle = { width = 2.0, height = 1.0, cells = [4, 2] }
[[bodies.supports]]
nearest = [0.0, 0.0]
fix = ["x", "y"]
[[bodies.supports]]
nearest = [2.0, 0.0]
fix = ["y"]
[[bodies.loads]]
nearest = [2.0, 1.0]
force = [1000.0, 0.0]
[output]
png = true
width = 320
height = 180
"#;

fn run_scene(text: &str, out: &Path) -> linkage::scene::Summary {
    let world = build_world(text, &out.join("scene.toml")).unwrap();
    run_with(&world, out, &|| {}, Some(&linkage::render::PictureWriter)).unwrap()
}

fn gif_frames(path: &Path) -> usize {
    let file = std::fs::File::open(path).unwrap();
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let mut decoder = options.read_info(file).unwrap();
    let mut n = 0;
    while decoder.read_next_frame().unwrap().is_some() {
        n += 1;
    }
    n
}

#[test]
fn run_with_png_writes_a_frame_per_step_and_a_gif_and_times_drawing() {
    let out = tempfile::tempdir().unwrap();
    let summary = run_scene(OVERLOAD, out.path());
    let dir = out.path().join("small_overload");
    for k in 0..=4 {
        let png = std::fs::read(dir.join(format!("png/{k:04}.png"))).unwrap();
        let p = tiny_skia::Pixmap::decode_png(&png).unwrap();
        assert_eq!((p.width(), p.height()), (320, 180));
    }
    assert_eq!(gif_frames(&dir.join("anim.gif")), 5);
    assert!(summary.phases.drawing > 0.0);
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("summary.json")).unwrap()).unwrap();
    assert!(json["phases"]["drawing"].as_f64().unwrap() > 0.0);
    // model.json holds what the step files do not: members (1-based) and supports.
    let model: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("model.json")).unwrap()).unwrap();
    assert_eq!(model["bodies"][0]["dimension"], 2);
    assert_eq!(model["bodies"][0]["members"][0][0], 1);
    assert_eq!(model["bodies"][0]["supports"][0]["fix"][0], "x");

    // Drawn again with other options: only the chosen steps, no GIF, rewritten atomically.
    let before = std::fs::read(dir.join("png/0004.png")).unwrap();
    let report = render_run(
        &dir,
        &RenderOptions {
            width: 200,
            height: 120,
            steps: StepSelection::List(vec![0, 4]),
            gif: false,
            ..RenderOptions::default()
        },
    )
    .unwrap();
    assert_eq!(report.steps, vec![0, 4]);
    let after =
        tiny_skia::Pixmap::decode_png(&std::fs::read(dir.join("png/0004.png")).unwrap()).unwrap();
    assert_eq!(after.width(), 200);
    assert_ne!(before, std::fs::read(dir.join("png/0004.png")).unwrap());
    // Drawing the same results again with the same options gives the same bytes.
    let again = |o: &RenderOptions| {
        render_run(&dir, o).unwrap();
        std::fs::read(dir.join("png/0003.png")).unwrap()
    };
    let o = RenderOptions {
        width: 240,
        height: 160,
        gif: false,
        ..RenderOptions::default()
    };
    assert_eq!(again(&o), again(&o));
    let names: Vec<String> = std::fs::read_dir(dir.join("png"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert!(names.iter().any(|n| n == "0003.png"), "{names:?}");
    assert!(names.iter().all(|n| !n.starts_with('.')), "{names:?}");
}

#[test]
fn rendering_a_missing_or_torn_folder_says_what_to_do() {
    let out = tempfile::tempdir().unwrap();
    let err = render_run(&out.path().join("nothing"), &RenderOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("model.json") && err.contains("linkage run"),
        "{err}"
    );
    run_scene(OVERLOAD, out.path());
    let dir = out.path().join("small_overload");
    std::fs::write(dir.join("steps/0002.json"), b"{\"step\": 2, \"load").unwrap();
    let err = render_run(&dir, &RenderOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("0002.json") && err.contains("run the scene again"),
        "{err}"
    );
    let err = render_run(
        &dir,
        &RenderOptions {
            steps: StepSelection::List(vec![7]),
            ..RenderOptions::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("step 7 is not stored"), "{err}");
    let err = render_run(
        &dir,
        &RenderOptions {
            width: 3,
            ..RenderOptions::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("width 3"), "{err}");
}

#[test]
fn contact_forces_are_drawn_as_orange_arrows_when_present() {
    let (model, mut step) = square();
    let count_orange = |frame: &Frame| {
        let mut n = 0;
        for y in 0..frame.height() {
            for x in 0..frame.width() {
                let c = frame.rgb(x, y).unwrap();
                if c.0 > 0.8 && (0.35..0.6).contains(&c.1) && c.2 < 0.15 {
                    n += 1;
                }
            }
        }
        n
    };
    let ext = extent(&model, &step, Some(1.0));
    let without = count_orange(&draw_frame(&model, &step, &ext, &options()).unwrap());
    step.bodies[0].contacts.push(linkage::scene::ContactForce {
        node: 2,
        with: "floor".into(),
        depth: 1e-4,
        force: vec![0.0, 300.0],
        ..Default::default()
    });
    let ext = extent(&model, &step, Some(1.0));
    let with = count_orange(&draw_frame(&model, &step, &ext, &options()).unwrap());
    assert_eq!(without, 0);
    assert!(with > 10, "{with} orange pixels");
}

#[test]
fn a_3d_body_without_patches_is_drawn_as_coloured_lines() {
    let (mut model, mut step) = square();
    let b = &mut model.bodies[0];
    b.dimension = 3;
    for p in &mut b.nodes {
        p.push(0.0);
    }
    b.nodes[3][2] = 0.5;
    let r = &mut step.bodies[0];
    r.positions = b.nodes.clone();
    r.displacements = vec![vec![0.0; 3]; 4];
    let ext = extent(&model, &step, Some(1.0));
    let o = options();
    let frame = draw_frame(&model, &step, &ext, &o).unwrap();
    let tension = colour_at(&frame, &o, &ext, [0.5, 0.0, 0.0]);
    let overloaded = colour_at(&frame, &o, &ext, [0.0, 0.5, 0.0]);
    assert!(tension.0 > tension.2 + 0.2, "{tension:?}");
    assert!(overloaded.0 < 0.1 && overloaded.2 < 0.1, "{overloaded:?}");
}

#[test]
fn results_that_do_not_match_the_model_are_an_error_not_a_panic() {
    let (model, mut step) = square();
    let ext = extent(&model, &step, Some(1.0));
    step.bodies[0].positions.pop();
    let err = draw_frame(&model, &step, &ext, &options())
        .unwrap_err()
        .to_string();
    assert!(err.contains("does not match model.json"), "{err}");
    let (mut model, step) = square();
    model.bodies[0].members.push([1, 9]);
    let err = draw_frame(&model, &step, &ext, &options())
        .unwrap_err()
        .to_string();
    assert!(err.contains("member 5"), "{err}");
}

#[test]
fn bad_output_keys_name_the_scene_file() {
    let base = std::fs::read_to_string("scenes/paper_square.toml").unwrap();
    for (keys, expect) in [
        ("width = 5", "[output] width = 5"),
        ("magnification = -2.0", "[output] magnification = -2"),
        ("elevation = 120.0", "[output] elevation = 120"),
        ("png = \"yes\"", "png"),
    ] {
        let text = format!("{base}\n[output]\n{keys}\n");
        let err = build_world(&text, Path::new("scenes/paper_square.toml"))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("paper_square.toml") && err.contains(expect),
            "{keys}: {err}"
        );
    }
}
