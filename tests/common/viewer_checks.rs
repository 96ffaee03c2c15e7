//! The report's 3D viewer checked alike in every browser (tests/report.rs drives Chromium,
//! tests/viewer_firefox.rs Firefox): two runs with pictures, the viewer's state read from
//! `window.linkageViewer`, and the checks of issue 35 (no console errors, the canvas drawn,
//! the slider's last step and each toggle change the picture).

use serde_json::{json, Value};
use std::path::Path;
use std::process::Command;

/// A browser tab the checks drive.
pub trait Tab {
    /// Open `file` (a `file://` page) and wait until it has loaded.
    fn open(&mut self, file: &Path);
    /// `expression`, which returns a JSON text, evaluated in the page and parsed.
    fn evaluate(&mut self, expression: &str) -> Value;
    /// The console errors and uncaught exceptions the tab logged since [`Tab::clear`].
    fn errors(&mut self) -> Vec<Value>;
    /// Forget what the tab logged so far.
    fn clear(&mut self);
}

/// The viewer's state: whether it has WebGL, its frames, and the picture's drawn pixels, the
/// box around them and its fingerprint.
pub const VIEWER_STATE: &str = "JSON.stringify((() => { const v = window.linkageViewer; \
    if (!v) return {ready: false}; if (!v.webgl) return {ready: true, webgl: false}; \
    return {ready: true, webgl: true, frames: v.frames, frame: v.frame(), \
    label: document.getElementById('viewer-label').textContent, ...v.pixels()}; })())";

/// Move the viewer's slider to frame `k` as a user does (an `input` event).
pub fn slide(k: usize) -> String {
    format!(
        "(() => {{ const s = document.getElementById('viewer-slider'); s.value = '{k}'; \
         s.dispatchEvent(new Event('input')); return JSON.stringify(1); }})()"
    )
}

/// Click the viewer's checkbox `name` (`contacts`, `broken`, `obstacles`).
pub fn click(name: &str) -> String {
    format!("(() => {{ document.getElementById('viewer-{name}').click(); return JSON.stringify(1); }})()")
}

/// The scenes of [`check_viewer_scenes`] with the toggles each checks: the notched beam (2D,
/// pressed by a cylinder: contact; breaking: fracture) and the shell pressed by a rising
/// block (3D, contact).
const SCENES: [(&str, [&str; 2]); 2] = [
    ("notched_beam", ["contacts", "broken"]),
    ("shell_on_block_moving", ["contacts", "obstacles"]),
];

/// Run the scenes of [`check_viewer_scenes`] into `out` with pictures (and so the report).
pub fn run_viewer_scenes(out: &Path) {
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let o = Command::new(env!("CARGO_BIN_EXE_linkage"))
        .arg("run")
        .args(SCENES.map(|(s, _)| scenes.join(format!("{s}.toml"))))
        .arg("--out")
        .arg(out)
        .arg("--png")
        .output()
        .unwrap();
    assert!(o.status.success(), "{o:?}");
}

/// Open each scene page of [`run_viewer_scenes`] in `out`: WebGL runs, every stored step is a
/// frame, the canvas is drawn (over 0.5 % of it), the slider's last step changes the picture
/// and says `N of N`, each toggle changes it and restores it, and the page logs no error.
/// `browser` names the browser in the messages.
pub fn check_viewer_scenes(tab: &mut impl Tab, out: &Path, browser: &str) {
    for (scene, toggles) in SCENES {
        let dir = out.join(scene);
        let stored = std::fs::read_dir(dir.join("steps")).unwrap().count();
        tab.clear();
        tab.open(&dir.join("index.html"));
        let first = tab.evaluate(VIEWER_STATE);
        assert_eq!(first["webgl"], json!(true), "{browser}, {scene}: {first}");
        assert_eq!(
            first["frames"],
            json!(stored),
            "{browser}, {scene}: every stored step"
        );
        let total = first["total"].as_u64().unwrap();
        let drawn = first["drawn"].as_u64().unwrap();
        assert!(
            drawn * 200 > total,
            "{browser}, {scene}: the canvas is drawn (over 0.5 % of it): {first}"
        );
        tab.evaluate(&slide(stored - 1));
        let last = tab.evaluate(VIEWER_STATE);
        assert_eq!(last["frame"], json!(stored - 1), "{browser}: {last}");
        assert_ne!(
            last["hash"], first["hash"],
            "{browser}, {scene}: the last step looks different"
        );
        assert!(
            last["label"]
                .as_str()
                .unwrap()
                .contains(&format!("{stored} of {stored}")),
            "{browser}: {last}"
        );
        for t in toggles {
            tab.evaluate(&click(t));
            let off = tab.evaluate(VIEWER_STATE);
            assert_ne!(
                off["hash"], last["hash"],
                "{browser}, {scene}: switching {t} off changes the picture"
            );
            tab.evaluate(&click(t));
            let on = tab.evaluate(VIEWER_STATE);
            assert_eq!(
                on["hash"], last["hash"],
                "{browser}, {scene}: switching {t} on again restores it"
            );
        }
        let errors = tab.errors();
        assert!(
            errors.is_empty(),
            "{browser}, {scene}'s page logged errors: {errors:?}"
        );
    }
}
