//! What the Python package relies on in the library: a run in memory (`run_in_memory`,
//! `Scene.run()`) holds the steps a run into a folder writes, number for number; bodies whose
//! paper files are held in memory (`build_world_with`) are the bodies read from those files;
//! and a scene written back from its spec types (`Scene.to_dict`) builds the same world.

use linkage::linkage::Interrupt;
use linkage::scene::{
    build_world, build_world_with, load_scene, run_in_memory, run_with, InlineFiles, RunResults,
};
use std::path::Path;
use std::sync::atomic::AtomicBool;

#[test]
fn a_run_in_memory_holds_the_steps_a_run_writes() {
    let dir = tempfile::tempdir().unwrap();
    // Contact and 4 steps, every other one written: the stored steps are 0, 2, 4.
    let text =
        std::fs::read_to_string("scenes/two_disks.toml").unwrap() + "\n[output]\nevery = 2\n";
    let scene = dir.path().join("two_disks.toml");
    std::fs::write(&scene, &text).unwrap();
    let world = load_scene(&scene).unwrap();
    let written = run_with(&world, dir.path(), &|| {}, None).unwrap();
    let stored = RunResults::read(&dir.path().join("two_disks")).unwrap();
    let counted = std::sync::atomic::AtomicUsize::new(0);
    let on_step = || {
        counted.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    };
    let (summary, steps, failure) = run_in_memory(&world, &on_step).unwrap();
    assert!(failure.is_none());
    assert_eq!(steps, stored.steps);
    assert_eq!(stored.step_numbers(), vec![0, 2, 4]);
    assert_eq!(
        counted.into_inner(),
        5,
        "on_step after every step, stored or not"
    );
    assert_eq!(summary.steps.len(), written.steps.len());
    for (a, b) in summary.steps.iter().zip(&written.steps) {
        assert_eq!(
            (a.step, a.load_factor, a.iterations),
            (b.step, b.load_factor, b.iterations)
        );
        assert_eq!(a.max_displacement, b.max_displacement);
    }
    assert_eq!(summary.scene_digest, written.scene_digest);
}

#[test]
fn a_stop_flag_set_before_the_run_stops_it_before_step_0() {
    let mut world = load_scene(Path::new("scenes/paper_square.toml")).unwrap();
    let raised: &'static AtomicBool = Box::leak(Box::new(AtomicBool::new(true)));
    world.set_interrupt(Interrupt::on(raised));
    let e = run_in_memory(&world, &|| {}).unwrap_err();
    assert!(e.to_string().contains("interrupted at step 0"), "{e}");
}

#[test]
fn paper_files_held_in_memory_build_the_bodies_the_files_on_disk_build() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string("scenes/paper_square.toml").unwrap();
    let scene = dir.path().join("paper_square.toml");
    let mut held = InlineFiles::default();
    for name in ["square.nodes", "square.links"] {
        held.insert(
            dir.path().join(name),
            std::fs::read_to_string(Path::new("scenes").join(name)).unwrap(),
        );
    }
    // Nothing on disk beside the scene: the files come from memory.
    let from_memory = build_world_with(&text, &scene, &held).unwrap();
    let from_disk = build_world(&text, Path::new("scenes/paper_square.toml")).unwrap();
    assert_eq!(from_memory.bodies, from_disk.bodies);
    // Without them the scene names the missing file at the key's line.
    let e = build_world(&text, &scene).unwrap_err().to_string();
    assert!(
        e.contains("paper_square.toml:12:") && e.contains("square.nodes"),
        "{e}"
    );
    // A problem inside a held file names it and its line.
    held.insert(dir.path().join("square.links"), "1 2\n2 9\n".into());
    let e = build_world_with(&text, &scene, &held)
        .unwrap_err()
        .to_string();
    assert!(e.contains("square.links:2:"), "{e}");
}

#[test]
fn every_bundled_scene_written_back_from_its_spec_types_builds_the_same_world() {
    let mut scenes: Vec<_> = std::fs::read_dir("scenes")
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 20);
    for path in scenes {
        let text = std::fs::read_to_string(&path).unwrap();
        let spec: linkage::scene::spec::SceneSpec = toml::from_str(&text).unwrap();
        let again = toml::to_string(&toml::Value::try_from(&spec).unwrap()).unwrap();
        let a = build_world(&text, &path).unwrap();
        let b = build_world(&again, &path)
            .unwrap_or_else(|e| panic!("{}: {e}\n{again}", path.display()));
        assert_eq!(a.bodies, b.bodies, "{}", path.display());
        assert_eq!(a.obstacles, b.obstacles, "{}", path.display());
        assert_eq!(a.contact, b.contact, "{}", path.display());
        assert_eq!(
            (a.steps, a.output, a.contact_table),
            (b.steps, b.output, b.contact_table)
        );
        assert_eq!(a.pictures, b.pictures, "{}", path.display());
    }
}
