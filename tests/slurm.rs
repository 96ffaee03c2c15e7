//! `linkage slurm` on a real Slurm cluster: a one-node cluster on this machine (munged,
//! slurmctld and slurmd on localhost, from `tests/slurm.conf`), a sweep of six variants over
//! three array tasks and the collect job after them, checked against a local run. Under
//! `CI=true` a cluster that cannot be started fails the test; elsewhere it is skipped with the
//! reason when Slurm is not installed.

mod common;

use common::{assert_same_results, table_without_seconds};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

/// The daemons this test started, stopped (by their process ids) when it ends, also on failure.
struct Daemons {
    children: Vec<(String, Child)>,
}

impl Drop for Daemons {
    fn drop(&mut self) {
        // slurmd, then slurmctld, then munged: the reverse of their start.
        while let Some((name, mut child)) = self.children.pop() {
            let pid = child.id() as libc::pid_t;
            // SAFETY: signalling a child process this test started and has not yet reaped.
            unsafe { libc::kill(pid, libc::SIGTERM) };
            let deadline = Instant::now() + Duration::from_secs(10);
            loop {
                match child.try_wait() {
                    Ok(Some(_)) => break,
                    Ok(None) if Instant::now() < deadline => {
                        std::thread::sleep(Duration::from_millis(50))
                    }
                    _ => {
                        eprintln!("{name} (pid {pid}) did not stop on SIGTERM: killing it");
                        let _ = child.kill();
                        let _ = child.wait();
                        break;
                    }
                }
            }
        }
    }
}

/// Whether a cluster that cannot be started must fail the test (`CI=true`).
fn required() -> bool {
    std::env::var("CI").is_ok_and(|v| v == "true")
}

fn found(program: &str) -> bool {
    std::env::var_os("PATH").is_some_and(|paths| {
        std::env::split_paths(&paths)
            .chain(["/usr/sbin".into(), "/sbin".into()])
            .any(|d| d.join(program).is_file())
    })
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// The logs of the cluster in `dir`, for a failure's message.
fn logs(dir: &Path) -> String {
    let mut out = String::new();
    for name in [
        "munged.stdout",
        "slurmctld.stdout",
        "slurmctld.log",
        "slurmd.stdout",
        "slurmd.log",
    ] {
        let text = std::fs::read_to_string(dir.join(name)).unwrap_or_default();
        let tail: Vec<&str> = text.lines().rev().take(15).collect();
        out.push_str(&format!("--- {name} (last lines)\n"));
        for line in tail.into_iter().rev() {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

/// A Slurm client command reading the test cluster's configuration.
fn client(program: &str, conf: &Path) -> Command {
    let mut c = Command::new(program);
    c.env("SLURM_CONF", conf);
    c
}

fn spawn(
    daemons: &mut Daemons,
    name: &str,
    command: &mut Command,
    dir: &Path,
) -> Result<(), String> {
    let out =
        std::fs::File::create(dir.join(format!("{name}.stdout"))).map_err(|e| e.to_string())?;
    let err = out.try_clone().map_err(|e| e.to_string())?;
    let child = command
        .stdin(Stdio::null())
        .stdout(out)
        .stderr(err)
        .spawn()
        .map_err(|e| format!("cannot start {name}: {e}"))?;
    daemons.children.push((name.to_string(), child));
    Ok(())
}

/// Start munged, slurmctld and slurmd in `dir`; the node is idle when this returns.
fn start_cluster(dir: &Path, daemons: &mut Daemons) -> Result<PathBuf, String> {
    let host = String::from_utf8_lossy(
        &Command::new("hostname")
            .arg("-s")
            .output()
            .map_err(|e| format!("hostname: {e}"))?
            .stdout,
    )
    .trim()
    .to_string();
    let template =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/slurm.conf"))
            .map_err(|e| format!("tests/slurm.conf: {e}"))?;
    let conf = dir.join("slurm.conf");
    std::fs::write(
        &conf,
        template
            .replace("@DIR@", &dir.display().to_string())
            .replace("@HOST@", &host),
    )
    .map_err(|e| e.to_string())?;
    for sub in ["state", "spool"] {
        std::fs::create_dir_all(dir.join(sub)).map_err(|e| e.to_string())?;
    }
    let key = dir.join("munge.key");
    let made = Command::new("mungekey")
        .arg("--create")
        .arg(format!("--keyfile={}", key.display()))
        .output()
        .map_err(|e| format!("mungekey: {e}"))?;
    if !made.status.success() {
        return Err(format!("mungekey --create failed: {}", text(&made)));
    }
    spawn(
        daemons,
        "munged",
        Command::new("munged")
            .arg("--foreground")
            .arg("--force")
            .arg(format!("--socket={}", dir.join("munge.socket").display()))
            .arg(format!("--key-file={}", key.display()))
            .arg(format!("--pid-file={}", dir.join("munged.pid").display()))
            .arg(format!("--log-file={}", dir.join("munged.log").display()))
            .arg(format!("--seed-file={}", dir.join("munged.seed").display())),
        dir,
    )?;
    let deadline = Instant::now() + Duration::from_secs(10);
    while !dir.join("munge.socket").exists() {
        if Instant::now() > deadline {
            return Err(format!("munged did not open its socket\n{}", logs(dir)));
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    spawn(
        daemons,
        "slurmctld",
        Command::new("slurmctld")
            .args(["-D", "-i", "-f"])
            .arg(&conf),
        dir,
    )?;
    spawn(
        daemons,
        "slurmd",
        Command::new("slurmd")
            .args(["-D", "-N", "localhost", "-f"])
            .arg(&conf),
        dir,
    )?;
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        for (name, child) in &mut daemons.children {
            if let Ok(Some(status)) = child.try_wait() {
                return Err(format!("{name} exited ({status})\n{}", logs(dir)));
            }
        }
        let state = client("sinfo", &conf).args(["-h", "-o", "%t"]).output();
        if let Ok(o) = &state {
            if String::from_utf8_lossy(&o.stdout).trim() == "idle" {
                return Ok(conf);
            }
        }
        if Instant::now() > deadline {
            let seen = state.map(|o| text(&o)).unwrap_or_default();
            return Err(format!(
                "the node did not become idle in 30 s (sinfo: {seen})\n{}",
                logs(dir)
            ));
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}

#[test]
fn a_sweep_runs_as_a_slurm_job_array_and_collects_to_the_local_table() {
    let missing: Vec<&str> = [
        "munged",
        "mungekey",
        "slurmctld",
        "slurmd",
        "sbatch",
        "squeue",
        "sinfo",
    ]
    .into_iter()
    .filter(|p| !found(p))
    .collect();
    if !missing.is_empty() {
        let why = format!(
            "Slurm is not installed (no {}): `.ci/run` installs slurm-wlm and munge",
            missing.join(", ")
        );
        assert!(!required(), "CI=true: {why}");
        eprintln!("skipped: {why}");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cluster = dir.path().join("cluster");
    std::fs::create_dir_all(&cluster).unwrap();
    let mut daemons = Daemons {
        children: Vec::new(),
    };
    let conf = match start_cluster(&cluster, &mut daemons) {
        Ok(conf) => conf,
        Err(why) => {
            // Installed but not startable is a failure everywhere: the test cannot say more.
            panic!("cannot start a one-node Slurm cluster: {why}");
        }
    };

    // The sweep: 2 × 3 variants of the paper's square.
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let scene = dir.path().join("sq.toml");
    let base = std::fs::read_to_string(scenes.join("paper_square.toml"))
        .unwrap()
        .replace("name = \"paper_square\"", "name = \"sq\"")
        .replace(
            "\"square.nodes\"",
            &format!("{:?}", scenes.join("square.nodes")),
        )
        .replace(
            "\"square.links\"",
            &format!("{:?}", scenes.join("square.links")),
        );
    std::fs::write(
        &scene,
        format!(
            "{base}\n[sweep]\n\"materials.steel.youngs_modulus\" = [70e9, 200e9]\n\"bodies.square.loads.1.force\" = [[100.0, 0.0], [200.0, 0.0], [400.0, 0.0]]\n"
        ),
    )
    .unwrap();
    let linkage = || Command::new(env!("CARGO_BIN_EXE_linkage"));
    let local = dir.path().join("local");
    let o = linkage()
        .arg("run")
        .arg(&scene)
        .arg("--out")
        .arg(&local)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o));

    let out = dir.path().join("batch");
    let o = linkage()
        .arg("slurm")
        .arg(&scene)
        .args(["--out"])
        .arg(&out)
        .args([
            "--tasks",
            "3",
            "--time",
            "00:05:00",
            "--cpus-per-task",
            "1",
            "--partition",
            "debug",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o));
    let printed = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(printed.contains("6 jobs in 3 array tasks"), "{printed}");
    let submit = printed
        .lines()
        .find(|l| l.trim_start().starts_with("jid=$(sbatch"))
        .unwrap_or_else(|| panic!("no sbatch command in {printed}"))
        .trim();
    // Submit as `linkage slurm` says to.
    let o = client("bash", &conf).args(["-c", submit]).output().unwrap();
    assert!(
        o.status.success(),
        "{submit}: {}\n{}",
        text(&o),
        logs(&cluster)
    );

    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        let q = client("squeue", &conf)
            .args(["-h", "-o", "%i %T"])
            .output()
            .unwrap();
        let queue = String::from_utf8_lossy(&q.stdout).into_owned();
        if q.status.success() && queue.trim().is_empty() {
            break;
        }
        assert!(
            Instant::now() < deadline,
            "the jobs did not finish in 60 s:\n{queue}\n{}",
            logs(&cluster)
        );
        std::thread::sleep(Duration::from_millis(200));
    }
    let task_logs = || -> String {
        let mut s = String::new();
        for f in std::fs::read_dir(out.join("slurm"))
            .into_iter()
            .flatten()
            .flatten()
        {
            s.push_str(&format!(
                "--- {}\n{}",
                f.path().display(),
                std::fs::read_to_string(f.path()).unwrap_or_default()
            ));
        }
        s
    };
    for i in 1..=3 {
        assert!(
            out.join(format!("batch.part-{i}-of-3.csv")).is_file(),
            "task {i}: {}",
            task_logs()
        );
    }
    // The collect job ran after the array; collecting again gives the same table.
    assert!(
        out.join("batch.csv").is_file(),
        "the collect job: {}",
        task_logs()
    );
    let o = linkage().arg("collect").arg(&out).output().unwrap();
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(
        table_without_seconds(&out.join("batch.csv")),
        table_without_seconds(&local.join("batch.csv"))
    );
    for k in 1..=6 {
        assert_same_results(&local.join(format!("sq/{k}")), &out.join(format!("sq/{k}")));
    }
    drop(daemons);
}
