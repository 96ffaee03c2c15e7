//! The report's 3D viewer in Firefox (issue 35): the checks tests/report.rs runs in Chromium
//! (tests/common/viewer_checks.rs), here in a headless Firefox opening the scene pages from
//! `file://`, driven over WebDriver BiDi (its WebSocket on `--remote-debugging-port`; a
//! minimal client below, no driver program). Firefox's headless mode draws WebGL only with an
//! X display to open GL on (Mesa's llvmpipe), so the test starts a virtual one (Xvfb) for it:
//! nothing is shown anywhere. Under `CI=true` a missing Firefox or Xvfb fails the test;
//! elsewhere it is skipped with the reason.

use serde_json::{json, Value};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{channel, Receiver};
use std::time::{Duration, Instant};

#[path = "common/viewer_checks.rs"]
mod viewer_checks;
use viewer_checks::{check_viewer_scenes, run_viewer_scenes, Tab};

fn required() -> bool {
    std::env::var("CI").is_ok_and(|v| v == "true")
}

/// The first of `names` on PATH.
fn on_path(names: &[&str]) -> Option<PathBuf> {
    let paths = std::env::var_os("PATH")?;
    std::env::split_paths(&paths)
        .flat_map(|d| names.iter().map(move |n| d.join(n)))
        .find(|p| p.is_file())
}

const WAIT: Duration = Duration::from_secs(60);

/// A process this test started, killed (by its id) on drop.
struct Started(Child);

impl Drop for Started {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// A virtual X display (Xvfb choosing a free display number, which it writes on
/// `-displayfd`): its process and `:N`.
fn virtual_display(xvfb: &Path) -> (Started, String) {
    let mut child = Command::new(xvfb)
        .args(["-displayfd", "1", "-nolisten", "tcp", "-screen", "0"])
        .arg("1400x900x24")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let number = line.trim().to_string();
    assert!(
        !number.is_empty() && number.bytes().all(|b| b.is_ascii_digit()),
        "Xvfb gave no display number: {line:?}"
    );
    (Started(child), format!(":{number}"))
}

/// A headless Firefox on `display` with a new profile: its process and the port of its
/// WebDriver BiDi server (from the line it prints on stderr).
fn firefox(program: &Path, display: &str, profile: &Path) -> (Started, u16) {
    let mut child = Command::new(program)
        .args(["--headless", "--no-remote", "--remote-debugging-port", "0"])
        .arg("--profile")
        .arg(profile)
        .arg("about:blank")
        .env("DISPLAY", display)
        .env("MOZ_CRASHREPORTER_DISABLE", "1")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let stderr = child.stderr.take().unwrap();
    let started = Started(child);
    let (send, receive) = channel();
    // Reads stderr to its end (Firefox must never block on a full pipe).
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            if let Some(url) = line.split("WebDriver BiDi listening on ws://").nth(1) {
                let port = url.rsplit(':').next().and_then(|p| p.trim().parse().ok());
                let _ = send.send(port);
            }
        }
    });
    let port = receive
        .recv_timeout(WAIT)
        .unwrap_or_else(|e| panic!("Firefox said no WebDriver BiDi port within {WAIT:?}: {e}"))
        .expect("a port number");
    (started, port)
}

/// One WebSocket frame of `payload` (text) from a client: final, masked (RFC 6455 §5.2).
fn client_frame(payload: &[u8]) -> Vec<u8> {
    let mask = [0x5a, 0x17, 0xc3, 0x88];
    let mut frame = vec![0x81];
    match payload.len() {
        n if n < 126 => frame.push(0x80 | n as u8),
        n if n < 1 << 16 => {
            frame.push(0x80 | 126);
            frame.extend((n as u16).to_be_bytes());
        }
        n => {
            frame.push(0x80 | 127);
            frame.extend((n as u64).to_be_bytes());
        }
    }
    frame.extend(mask);
    frame.extend(payload.iter().enumerate().map(|(i, b)| b ^ mask[i % 4]));
    frame
}

/// The messages of a server's WebSocket (text frames, continued ones joined) as JSON, until
/// it closes.
fn read_messages(mut from: TcpStream, send: std::sync::mpsc::Sender<Value>) {
    let mut message = Vec::new();
    loop {
        let mut head = [0u8; 2];
        if from.read_exact(&mut head).is_err() {
            return;
        }
        let mut n = (head[1] & 0x7f) as u64;
        if n == 126 {
            let mut b = [0u8; 2];
            from.read_exact(&mut b).unwrap();
            n = u16::from_be_bytes(b) as u64;
        } else if n == 127 {
            let mut b = [0u8; 8];
            from.read_exact(&mut b).unwrap();
            n = u64::from_be_bytes(b);
        }
        let mut payload = vec![0u8; n as usize];
        if from.read_exact(&mut payload).is_err() {
            return;
        }
        match head[0] & 0x0f {
            0x0..=0x2 => message.extend(payload),
            0x8 => return,
            _ => continue, // ping, pong: nothing to keep
        }
        if head[0] & 0x80 != 0 {
            if let Ok(v) = serde_json::from_slice::<Value>(&message) {
                if send.send(v).is_err() {
                    return;
                }
            }
            message.clear();
        }
    }
}

/// A WebDriver BiDi session with one browsing context (the first tab).
struct Bidi {
    to: TcpStream,
    from: Receiver<Value>,
    next: u64,
    /// Events received while waiting for replies.
    events: Vec<Value>,
    context: String,
}

impl Bidi {
    fn connect(port: u16) -> Bidi {
        let mut to = TcpStream::connect(("127.0.0.1", port)).unwrap();
        write!(
            to,
            "GET /session HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nUpgrade: websocket\r\n\
             Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\
             Sec-WebSocket-Version: 13\r\n\r\n"
        )
        .unwrap();
        // The handshake's reply, a byte at a time so that no frame is read with it.
        let mut reply = Vec::new();
        let mut byte = [0u8; 1];
        while !reply.ends_with(b"\r\n\r\n") {
            to.read_exact(&mut byte).unwrap();
            reply.push(byte[0]);
        }
        let reply = String::from_utf8_lossy(&reply).to_string();
        assert!(reply.starts_with("HTTP/1.1 101"), "{reply}");
        let from = to.try_clone().unwrap();
        let (send, receive) = channel();
        std::thread::spawn(move || read_messages(from, send));
        let mut bidi = Bidi {
            to,
            from: receive,
            next: 1,
            events: Vec::new(),
            context: String::new(),
        };
        bidi.call("session.new", json!({"capabilities": {}}));
        bidi.call("session.subscribe", json!({"events": ["log.entryAdded"]}));
        let tree = bidi.call("browsingContext.getTree", json!({}));
        bidi.context = tree["contexts"][0]["context"].as_str().unwrap().to_string();
        bidi
    }

    /// Send `method` with `params` and wait for its result.
    fn call(&mut self, method: &str, params: Value) -> Value {
        let id = self.next;
        self.next += 1;
        let message = json!({"id": id, "method": method, "params": params});
        self.to
            .write_all(&client_frame(&serde_json::to_vec(&message).unwrap()))
            .unwrap();
        let deadline = Instant::now() + WAIT;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            let v = self
                .from
                .recv_timeout(left)
                .unwrap_or_else(|e| panic!("no reply to {method} within {WAIT:?}: {e}"));
            if v["id"] == json!(id) {
                assert_eq!(v["type"], "success", "{method}: {v}");
                return v["result"].clone();
            }
            self.events.push(v);
        }
    }
}

impl Tab for Bidi {
    fn open(&mut self, file: &Path) {
        let url = format!("file://{}", file.display());
        let context = self.context.clone();
        self.call(
            "browsingContext.navigate",
            json!({"context": context, "url": url, "wait": "complete"}),
        );
    }

    fn evaluate(&mut self, expression: &str) -> Value {
        let context = self.context.clone();
        let r = self.call(
            "script.evaluate",
            json!({"expression": expression, "target": {"context": context},
                   "awaitPromise": false}),
        );
        assert_eq!(r["type"], "success", "{expression}: {r}");
        serde_json::from_str(r["result"]["value"].as_str().unwrap()).unwrap()
    }

    fn errors(&mut self) -> Vec<Value> {
        // A round trip so every event sent before it has arrived.
        self.evaluate("JSON.stringify(1)");
        self.events
            .iter()
            .filter(|e| e["method"] == "log.entryAdded" && e["params"]["level"] == "error")
            .cloned()
            .collect()
    }

    fn clear(&mut self) {
        self.events.clear();
    }
}

#[test]
fn the_viewer_draws_a_2d_and_a_3d_run_in_firefox_and_its_slider_and_toggles_change_the_picture() {
    let (Some(program), Some(xvfb)) = (on_path(&["firefox", "firefox-esr"]), on_path(&["Xvfb"]))
    else {
        let why = "no firefox or Xvfb on PATH (Debian: apt-get install firefox-esr xvfb)";
        assert!(!required(), "CI=true: {why}");
        eprintln!("skipped: {why}");
        return;
    };
    let out = tempfile::tempdir().unwrap();
    run_viewer_scenes(out.path());
    let profile = tempfile::tempdir().unwrap();
    let (_display, number) = virtual_display(&xvfb);
    let (_firefox, port) = firefox(&program, &number, profile.path());
    let mut tab = Bidi::connect(port);
    // The checks can fail: a page whose script throws logs an error.
    let control = out.path().join("control.html");
    std::fs::write(&control, "<!DOCTYPE html><script>notDefined();</script>").unwrap();
    tab.open(&control);
    assert!(!tab.errors().is_empty(), "an uncaught error is logged");
    check_viewer_scenes(&mut tab, out.path(), "firefox");
}
