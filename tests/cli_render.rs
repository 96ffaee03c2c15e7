//! `linkage run --png --vtk` and `linkage render` end to end.

use std::process::Command;

fn linkage() -> Command {
    Command::new(env!("CARGO_BIN_EXE_linkage"))
}

#[test]
fn run_png_vtk_then_render_again_with_other_options() {
    let out = tempfile::tempdir().unwrap();
    let o = linkage()
        .args(["run", "scenes/paper_square.toml", "--png", "--vtk", "--out"])
        .arg(out.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let dir = out.path().join("paper_square");
    for f in [
        "png/0000.png",
        "png/0001.png",
        "anim.gif",
        "vtk/0000.vtu",
        "vtk/0001.vtu",
        "vtk/paper_square.pvd",
        "model.json",
    ] {
        assert!(dir.join(f).is_file(), "{f} missing");
    }

    // Render reads the stored run and solves nothing: the results (and the GIF it is not
    // asked for) keep their bytes and modification times, and no timing of a solve is
    // printed; only the asked-for frame is drawn anew, and it replaces `png/` as a whole (the
    // frame of step 0, not drawn this time, is gone; a user's file there stays).
    std::fs::write(dir.join("png/notes.txt"), "mine").unwrap();
    let results = [
        "summary.json",
        "model.json",
        "steps/0000.json",
        "steps/0001.json",
        "anim.gif",
        "vtk/0001.vtu",
        "vtk/paper_square.pvd",
    ];
    let stamp = |f: &str| {
        let path = dir.join(f);
        let modified = std::fs::metadata(&path).unwrap().modified().unwrap();
        (std::fs::read(&path).unwrap(), modified)
    };
    let before: Vec<_> = results.iter().map(|f| stamp(f)).collect();
    let frame_before = stamp("png/0001.png");
    let listing = |d: &std::path::Path| {
        let mut names: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        names.sort();
        names
    };
    let steps_before = listing(&dir.join("steps"));
    let o = linkage()
        .arg("render")
        .arg(&dir)
        .args([
            "--width", "300", "--height", "200", "--steps", "last", "--no-gif",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let png =
        tiny_skia::Pixmap::decode_png(&std::fs::read(dir.join("png/0001.png")).unwrap()).unwrap();
    assert_eq!((png.width(), png.height()), (300, 200));
    let frame_after = stamp("png/0001.png");
    assert_ne!(
        frame_after.0, frame_before.0,
        "the last frame was drawn again"
    );
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("drew 1 step"), "{stdout}");
    for solved in ["phases", "residual", "max |u|", "factorization"] {
        assert!(
            !stdout.contains(solved),
            "render solved ({solved:?}): {stdout}"
        );
    }
    for (f, was) in results.iter().zip(&before) {
        let now = stamp(f);
        assert!(now.0 == was.0, "render changed the bytes of {f}");
        assert_eq!(now.1, was.1, "render rewrote {f}");
    }
    assert_eq!(listing(&dir.join("steps")), steps_before);
    assert_eq!(listing(&dir.join("png")), ["0001.png", "notes.txt"]);
    assert_eq!(
        listing(out.path()),
        ["batch.csv", "index.html", "paper_square"],
        "no staging folder left"
    );
    assert_eq!(
        listing(&dir),
        [
            "anim.gif",
            "index.html",
            "model.json",
            "plot_settings.json",
            "plots",
            "png",
            "steps",
            "summary.json",
            "vtk"
        ],
        "no staging folder left"
    );

    let o = linkage()
        .arg("render")
        .arg(&dir)
        .args(["--projection", "fisheye"])
        .output()
        .unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("orthographic") && err.contains("perspective"),
        "{err}"
    );

    let o = linkage()
        .arg("render")
        .arg(out.path().join("missing"))
        .output()
        .unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("summary.json") && err.contains("linkage run"),
        "{err}"
    );
}

#[test]
fn bundled_scenes_produce_their_frames_and_gifs() {
    let out = tempfile::tempdir().unwrap();
    let scenes: Vec<_> = std::fs::read_dir("scenes")
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    assert!(scenes.len() >= 5);
    let o = linkage()
        .arg("run")
        .args(&scenes)
        .args(["--png", "--out"])
        .arg(out.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stdout));
    let mut folders = 0;
    for entry in std::fs::read_dir(out.path()).unwrap() {
        let dir = entry.unwrap().path();
        if !dir.is_dir() {
            continue; // batch.csv
        }
        folders += 1;
        let steps = std::fs::read_dir(dir.join("steps")).unwrap().count();
        let frames = std::fs::read_dir(dir.join("png")).unwrap().count();
        assert_eq!(frames, steps, "{}", dir.display());
        let mut decoder = gif::DecodeOptions::new()
            .read_info(std::fs::File::open(dir.join("anim.gif")).unwrap())
            .unwrap();
        let mut n = 0;
        while decoder.read_next_frame().unwrap().is_some() {
            n += 1;
        }
        assert_eq!(n, steps, "{}", dir.display());
        assert!(
            steps >= 2,
            "{}: step 0 and at least one solved",
            dir.display()
        );
    }
    // One results folder per scene: the loop above saw them all.
    assert_eq!(
        folders,
        scenes.len(),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
}

/// A run of 10,000 steps or more names its step files, frames and VTK files with enough digits
/// for its last step, so the names sort in step order, and `linkage render` and the `.pvd`
/// read them at that width.
#[test]
fn file_names_have_enough_digits_for_the_last_step() {
    let dir = tempfile::tempdir().unwrap();
    let src = std::fs::read_to_string("scenes/paper_square.toml")
        .unwrap()
        .replace("steps = 1", "steps = 10000");
    let here = std::env::current_dir().unwrap().join("scenes");
    let src = src
        .replace(
            "\"square.nodes\"",
            &format!("{:?}", here.join("square.nodes")),
        )
        .replace(
            "\"square.links\"",
            &format!("{:?}", here.join("square.links")),
        );
    let scene = dir.path().join("long.toml");
    std::fs::write(&scene, format!("{src}\n[output]\nevery = 4000\n")).unwrap();
    let out = dir.path().join("out");
    let o = linkage()
        .arg("run")
        .arg(&scene)
        .args(["--png", "--vtk", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stdout));
    let run = out.join("paper_square");
    let listing = |d: &str| {
        let mut names: Vec<String> = std::fs::read_dir(run.join(d))
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        names.sort();
        names
    };
    assert_eq!(
        listing("steps"),
        ["00000.json", "04000.json", "08000.json", "10000.json"]
    );
    assert_eq!(
        listing("png"),
        ["00000.png", "04000.png", "08000.png", "10000.png"]
    );
    assert_eq!(
        listing("vtk"),
        [
            "00000.vtu",
            "04000.vtu",
            "08000.vtu",
            "10000.vtu",
            "paper_square.pvd"
        ]
    );
    let pvd = std::fs::read_to_string(run.join("vtk/paper_square.pvd")).unwrap();
    assert!(pvd.contains("file=\"04000.vtu\""), "{pvd}");
    // `linkage render` reads the 5-digit files and names its frames the same way.
    let o = linkage()
        .arg("render")
        .arg(&run)
        .args(["--width", "64", "--height", "48", "--steps", "4000,10000"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(run.join("png/04000.png").is_file());
    assert!(run.join("png/10000.png").is_file());
}
