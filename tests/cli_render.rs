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

    // Render reads the stored run and solves nothing: the results (and the frames and GIF it
    // is not asked for) keep their bytes and modification times, and no timing of a solve is
    // printed; only the asked-for frame is drawn anew.
    let results = [
        "summary.json",
        "model.json",
        "steps/0000.json",
        "steps/0001.json",
        "png/0000.png",
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
        folders += 1;
        let dir = entry.unwrap().path();
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
