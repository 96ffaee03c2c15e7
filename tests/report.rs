//! The HTML report of `linkage run --png` in a real browser: headless Chromium opens
//! `DIR/index.html` and a scene's page from disk, driven over the DevTools protocol on a pipe
//! (`--remote-debugging-pipe`: fd 3 in, fd 4 out, messages ended by NUL); every image must
//! load (naturalWidth > 0), every job of the batch (skipped ones too) must have its row, and
//! no page may log a console error. Under `CI=true` a missing Chromium fails the test;
//! elsewhere it is skipped with the reason.

use serde_json::{json, Value};
use std::io::{BufRead, BufReader, Write};
use std::os::fd::{FromRawFd, OwnedFd};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{channel, Receiver};
use std::time::{Duration, Instant};

#[path = "common/viewer_checks.rs"]
mod viewer_checks;
use viewer_checks::{check_viewer_scenes, click, run_viewer_scenes, Tab, VIEWER_STATE};

fn required() -> bool {
    std::env::var("CI").is_ok_and(|v| v == "true")
}

/// The Chromium on PATH (Debian: `chromium`).
fn chromium() -> Option<PathBuf> {
    let paths = std::env::var_os("PATH")?;
    std::env::split_paths(&paths)
        .flat_map(|d| ["chromium", "chromium-browser"].map(|n| d.join(n)))
        .find(|p| p.is_file())
}

fn linkage() -> Command {
    Command::new(env!("CARGO_BIN_EXE_linkage"))
}

/// A browser this test started, driven over its DevTools pipe; killed (by its id) on drop.
struct Browser {
    child: Child,
    to: std::fs::File,
    from: Receiver<Value>,
    next: u64,
    /// Events received while waiting for replies, kept for [`Browser::errors`].
    events: Vec<Value>,
    _profile: tempfile::TempDir,
}

impl Drop for Browser {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

const WAIT: Duration = Duration::from_secs(60);

impl Browser {
    fn start(program: &Path) -> Browser {
        let profile = tempfile::tempdir().unwrap();
        let mut to_browser = [0; 2];
        let mut from_browser = [0; 2];
        // SAFETY: pipe2 fills the arrays with two new descriptors each, owned below.
        unsafe {
            assert_eq!(libc::pipe2(to_browser.as_mut_ptr(), libc::O_CLOEXEC), 0);
            assert_eq!(libc::pipe2(from_browser.as_mut_ptr(), libc::O_CLOEXEC), 0);
        }
        let (child_in, child_out) = (to_browser[0], from_browser[1]);
        let mut command = Command::new(program);
        command
            .args([
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--disable-quic",
                "--no-first-run",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
                "--remote-debugging-pipe",
                // WebGL without a GPU, for the report's 3D viewer.
                "--use-angle=swiftshader",
                "--enable-unsafe-swiftshader",
            ])
            .arg(format!("--user-data-dir={}", profile.path().display()))
            .arg("about:blank")
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null());
        // SAFETY: only async-signal-safe fcntl and dup2 between fork and exec; dup2 clears
        // close-on-exec on its copies, so the browser gets the pipes as fds 3 and 4.
        unsafe {
            command.pre_exec(move || {
                // Copies above 10 first: a pipe end may itself be fd 3 or 4 (dup2 onto
                // itself would keep its close-on-exec flag).
                let a = libc::fcntl(child_in, libc::F_DUPFD, 10);
                let b = libc::fcntl(child_out, libc::F_DUPFD, 10);
                if a < 0 || b < 0 || libc::dup2(a, 3) < 0 || libc::dup2(b, 4) < 0 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
        let child = command.spawn().unwrap();
        // SAFETY: each descriptor is owned once from here on.
        let (to, from) = unsafe {
            drop(OwnedFd::from_raw_fd(child_in));
            drop(OwnedFd::from_raw_fd(child_out));
            (
                std::fs::File::from_raw_fd(to_browser[1]),
                std::fs::File::from_raw_fd(from_browser[0]),
            )
        };
        let (send, receive) = channel();
        std::thread::spawn(move || {
            let mut reader = BufReader::new(from);
            loop {
                let mut message = Vec::new();
                match reader.read_until(0, &mut message) {
                    Ok(0) | Err(_) => break,
                    Ok(_) => {
                        message.pop_if(|b| *b == 0);
                        if let Ok(v) = serde_json::from_slice::<Value>(&message) {
                            if send.send(v).is_err() {
                                break;
                            }
                        }
                    }
                }
            }
        });
        Browser {
            child,
            to,
            from: receive,
            next: 1,
            events: Vec::new(),
            _profile: profile,
        }
    }

    /// Send `method` with `params` (to `session`, or the browser) and wait for its result.
    fn call(&mut self, session: Option<&str>, method: &str, params: Value) -> Value {
        let id = self.next;
        self.next += 1;
        let mut message = json!({"id": id, "method": method, "params": params});
        if let Some(s) = session {
            message["sessionId"] = json!(s);
        }
        let mut bytes = serde_json::to_vec(&message).unwrap();
        bytes.push(0);
        self.to.write_all(&bytes).unwrap();
        let deadline = Instant::now() + WAIT;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            let v = self
                .from
                .recv_timeout(left)
                .unwrap_or_else(|e| panic!("no reply to {method} within {WAIT:?}: {e}"));
            if v["id"] == json!(id) {
                assert!(v.get("error").is_none(), "{method}: {v}");
                return v["result"].clone();
            }
            self.events.push(v);
        }
    }

    /// Wait for event `method` of `session`.
    fn wait_for(&mut self, session: &str, method: &str) {
        if let Some(k) = self
            .events
            .iter()
            .position(|e| e["method"] == method && e["sessionId"] == session)
        {
            self.events.remove(k);
            return;
        }
        let deadline = Instant::now() + WAIT;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            let v = self
                .from
                .recv_timeout(left)
                .unwrap_or_else(|e| panic!("no {method} within {WAIT:?}: {e}"));
            if v["method"] == method && v["sessionId"] == session {
                return;
            }
            self.events.push(v);
        }
    }

    /// A new tab, attached: its session id.
    fn tab(&mut self) -> String {
        let target = self.call(None, "Target.createTarget", json!({"url": "about:blank"}));
        let attached = self.call(
            None,
            "Target.attachToTarget",
            json!({"targetId": target["targetId"], "flatten": true}),
        );
        let session = attached["sessionId"].as_str().unwrap().to_string();
        for domain in ["Page.enable", "Runtime.enable", "Log.enable"] {
            self.call(Some(&session), domain, json!({}));
        }
        session
    }

    /// Open `file` in the tab of `session` and wait until it and its images have loaded.
    fn open(&mut self, session: &str, file: &Path) {
        let url = format!("file://{}", file.display());
        let r = self.call(Some(session), "Page.navigate", json!({"url": url}));
        assert!(r.get("errorText").is_none(), "{url}: {r}");
        self.wait_for(session, "Page.loadEventFired");
    }

    /// `expression` evaluated in the page of `session`, as JSON.
    fn evaluate(&mut self, session: &str, expression: &str) -> Value {
        let r = self.call(
            Some(session),
            "Runtime.evaluate",
            json!({"expression": expression, "returnByValue": true}),
        );
        assert!(r.get("exceptionDetails").is_none(), "{expression}: {r}");
        serde_json::from_str(r["result"]["value"].as_str().unwrap()).unwrap()
    }

    /// The console errors, uncaught exceptions and failed loads the pages of `session` logged.
    fn errors(&mut self, session: &str) -> Vec<Value> {
        // A round trip so every event sent before it has arrived.
        self.call(
            Some(session),
            "Runtime.evaluate",
            json!({"expression": "1"}),
        );
        self.events
            .iter()
            .filter(|e| e["sessionId"] == session)
            .filter(|e| match e["method"].as_str() {
                Some("Runtime.exceptionThrown") => true,
                Some("Runtime.consoleAPICalled") => e["params"]["type"] == "error",
                Some("Log.entryAdded") => e["params"]["entry"]["level"] == "error",
                _ => false,
            })
            .cloned()
            .collect()
    }
}

/// Every image of the page with whether it loaded, and the jobs of its table rows.
const PAGE_STATE: &str = "JSON.stringify({\
    images: [...document.images].map(i => [i.getAttribute('src'), i.complete && i.naturalWidth > 0]),\
    rows: [...document.querySelectorAll('tr[data-job]')].map(r => r.dataset.job)})";

fn check_images(page: &Value, at: &str) -> usize {
    let images = page["images"].as_array().unwrap();
    let broken: Vec<&Value> = images.iter().filter(|i| i[1] != json!(true)).collect();
    assert!(broken.is_empty(), "{at}: broken images {broken:?}");
    images.len()
}

/// A scene whose name needs escaping in HTML would be refused by `run`; a sweep's values do
/// not: its variants' rows show `a < b & c`-like TOML values escaped.
fn sweep_scene(dir: &Path) -> PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    for f in ["square.nodes", "square.links"] {
        std::fs::copy(src.join(f), dir.join(f)).unwrap();
    }
    let text = std::fs::read_to_string(src.join("paper_square.toml"))
        .unwrap()
        .replace("name = \"paper_square\"", "name = \"square_sweep\"");
    let path = dir.join("sweep.toml");
    std::fs::write(
        &path,
        format!(
            "{text}\n[sweep]\n\"bodies.square.loads.1.force\" = [[100.0, 0.0], [200.0, 0.0]]\n"
        ),
    )
    .unwrap();
    path
}

#[test]
fn the_report_opens_in_chromium_with_every_image_and_every_job() {
    let Some(program) = chromium() else {
        let why = "no chromium on PATH (Debian: apt-get install chromium)";
        assert!(!required(), "CI=true: {why}");
        eprintln!("skipped: {why}");
        return;
    };
    let out = tempfile::tempdir().unwrap();
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let sweep = sweep_scene(out.path());
    // One run draws a linear scene and a contact scene; a second adds the sweep and a scene
    // that cannot be read, and draws the two complete ones from their stored results without
    // solving them (`--png` asks for pictures): their rows are read back.
    let first = [
        scenes.join("paper_overload.toml"),
        scenes.join("disk_on_floor.toml"),
    ];
    let o = linkage()
        .arg("run")
        .args(&first)
        .arg("--out")
        .arg(out.path())
        .arg("--png")
        .output()
        .unwrap();
    assert!(o.status.success(), "{o:?}");
    let missing = out.path().join("missing.toml");
    let o = linkage()
        .arg("run")
        .args(&first)
        .arg(&sweep)
        .arg(&missing)
        .arg("--out")
        .arg(out.path())
        .arg("--png")
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(!o.status.success(), "the missing scene fails the run");
    assert_eq!(said.matches("drew  ").count(), 2, "{said}");
    let index = out.path().join("index.html");
    assert!(index.is_file(), "{said}");
    let table = std::fs::read_to_string(out.path().join("batch.csv")).unwrap();
    let jobs: Vec<String> = table
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().to_string())
        .collect();
    assert_eq!(jobs.len(), 5, "{table}");

    let mut browser = Browser::start(&program);
    let tab = browser.tab();
    // The checks can fail: a page with a missing image shows it broken and logs an error.
    let control = out.path().join("control.html");
    std::fs::write(&control, "<!DOCTYPE html><img src=\"missing.png\">").unwrap();
    browser.open(&tab, &control);
    let page = browser.evaluate(&tab, PAGE_STATE);
    assert_eq!(page["images"], json!([["missing.png", false]]));
    assert!(
        !browser.errors(&tab).is_empty(),
        "a missing image is logged"
    );
    browser.events.clear();
    browser.open(&tab, &index);
    let page = browser.evaluate(&tab, PAGE_STATE);
    let rows: Vec<String> = page["rows"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r.as_str().unwrap().to_string())
        .collect();
    assert_eq!(rows, jobs, "one row per job of batch.csv, in its order");
    let images = check_images(&page, "index.html");
    // Each of the 4 jobs with results shows its animation and at least its
    // load–displacement plot; the failed one shows none.
    assert!(images >= 8, "{images} images: {page}");
    let errors = browser.errors(&tab);
    assert!(errors.is_empty(), "index.html logged errors: {errors:?}");
    // The table fits the page (no sideways scrolling in the default window).
    let fit = browser.evaluate(
        &tab,
        "JSON.stringify([document.documentElement.scrollWidth, document.documentElement.clientWidth])",
    );
    assert!(fit[0].as_u64() <= fit[1].as_u64(), "page {fit} pixels wide");
    // The failure is said once, its path relative to the batch folder (it can move).
    let html = std::fs::read_to_string(&index).unwrap();
    assert_eq!(html.matches("missing.toml").count(), 1, "{html}");
    assert!(!html.contains(&out.path().display().to_string()), "{html}");

    // A scene's page: every frame, the plots, the animation, and the way back.
    let scene_page = out.path().join("disk_on_floor").join("index.html");
    browser.open(&tab, &scene_page);
    let page = browser.evaluate(&tab, PAGE_STATE);
    let frames = std::fs::read_dir(out.path().join("disk_on_floor/png"))
        .unwrap()
        .count();
    let plots = std::fs::read_dir(out.path().join("disk_on_floor/plots"))
        .unwrap()
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().ends_with(".png"))
        .count();
    assert!(plots >= 2, "load_displacement and contact_forces");
    assert_eq!(
        check_images(&page, "disk_on_floor/index.html"),
        frames + plots + 1
    );
    let errors = browser.errors(&tab);
    assert!(
        errors.is_empty(),
        "the scene page logged errors: {errors:?}"
    );
    // A variant's page lies two folders down; its link back must still resolve.
    browser.open(&tab, &out.path().join("square_sweep/2/index.html"));
    let back = browser.evaluate(&tab, "JSON.stringify(document.querySelector('a').href)");
    assert_eq!(
        back.as_str().unwrap(),
        format!("file://{}", index.display())
    );
    let page = browser.evaluate(&tab, PAGE_STATE);
    check_images(&page, "square_sweep/2/index.html");
    let errors = browser.errors(&tab);
    assert!(
        errors.is_empty(),
        "the variant's page logged errors: {errors:?}"
    );
}

/// A tab of the Chromium this test drives, for the checks both browsers share.
struct ChromiumTab<'a> {
    browser: &'a mut Browser,
    session: String,
}

impl Tab for ChromiumTab<'_> {
    fn open(&mut self, file: &Path) {
        self.browser.open(&self.session, file);
    }

    fn evaluate(&mut self, expression: &str) -> Value {
        self.browser.evaluate(&self.session, expression)
    }

    fn errors(&mut self) -> Vec<Value> {
        self.browser.errors(&self.session)
    }

    fn clear(&mut self) {
        self.browser.events.clear();
    }
}

#[test]
fn the_viewer_draws_a_2d_and_a_3d_run_and_its_slider_and_toggles_change_the_picture() {
    let Some(program) = chromium() else {
        let why = "no chromium on PATH (Debian: apt-get install chromium)";
        assert!(!required(), "CI=true: {why}");
        eprintln!("skipped: {why}");
        return;
    };
    let out = tempfile::tempdir().unwrap();
    run_viewer_scenes(out.path());
    let mut browser = Browser::start(&program);
    let session = browser.tab();
    let mut tab = ChromiumTab {
        browser: &mut browser,
        session,
    };
    check_viewer_scenes(&mut tab, out.path(), "chromium");
}

/// A 0.1 m square column 0.5 m tall standing on z = 0 (`up = "z"`), above a wide slab (an
/// obstacle below z = 0): in a y-up view it would lie on its side.
const COLUMN_Z_UP: &str = r#"name = "column_z_up"
steps = 1

[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4

[[bodies]]
name = "column"
box_lattice = { size = [0.1, 0.1, 0.5], cells = [1, 1, 4] }
material = "steel"

[[bodies.supports]]
on_plane = { point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }
fix = ["x", "y", "z"]

[[bodies.loads]]
on_plane = { point = [0.0, 0.0, 0.5], normal = [0.0, 0.0, 1.0] }
total_force = [0.0, 0.0, -1000.0]

[[obstacles]]
name = "slab"
shape = "cuboid"
center = [0.05, 0.05, -0.06]
half_extents = [0.3, 0.3, 0.05]

[output]
up = "z"
"#;

/// The drawn box `[left, top, right, bottom]` of a viewer state, canvas pixels from the top.
fn drawn_box(state: &Value) -> [i64; 4] {
    let b = state["box"].as_array().unwrap_or_else(|| panic!("{state}"));
    [0, 1, 2, 3].map(|k| b[k].as_i64().unwrap())
}

#[test]
fn the_viewer_stands_a_z_up_column_upright_on_its_slab() {
    let Some(program) = chromium() else {
        let why = "no chromium on PATH (Debian: apt-get install chromium)";
        assert!(!required(), "CI=true: {why}");
        eprintln!("skipped: {why}");
        return;
    };
    let out = tempfile::tempdir().unwrap();
    let scene = out.path().join("column_z_up.toml");
    std::fs::write(&scene, COLUMN_Z_UP).unwrap();
    let o = linkage()
        .arg("run")
        .arg(&scene)
        .arg("--out")
        .arg(out.path())
        .arg("--png")
        .output()
        .unwrap();
    assert!(o.status.success(), "{o:?}");
    let mut browser = Browser::start(&program);
    let session = browser.tab();
    let mut tab = ChromiumTab {
        browser: &mut browser,
        session,
    };
    tab.open(&out.path().join("column_z_up/index.html"));
    let with_slab = tab.evaluate(VIEWER_STATE);
    assert_eq!(with_slab["webgl"], json!(true), "{with_slab}");
    tab.evaluate(&click("obstacles"));
    let column = tab.evaluate(VIEWER_STATE);
    let [left, top, right, bottom] = drawn_box(&column);
    // The column alone stands: over twice as tall as wide on the canvas (0.5 m against a
    // 0.1 m square seen from 35° aside: about 3.5 times; lying, it would be wider than tall).
    let (width, height) = (right - left + 1, bottom - top + 1);
    assert!(
        height > 2 * width,
        "the column stands upright: {width} × {height} pixels, {column}"
    );
    // Its base is at the bottom: the slab under it adds pixels below the column and none
    // above it (upside down, the slab would be drawn above the column).
    let [_, slab_top, _, slab_bottom] = drawn_box(&with_slab);
    assert!(
        slab_bottom > bottom + 10,
        "the slab is drawn below the column: bottom {slab_bottom} against {bottom}"
    );
    assert!(
        (slab_top - top).abs() <= 1,
        "nothing above the column's top: top {slab_top} against {top}"
    );
    let errors = tab.errors();
    assert!(errors.is_empty(), "the page logged errors: {errors:?}");
}
