//! Publishing a run's results folder: built under a staging name, put in place atomically, never
//! at the cost of earlier complete results or of files a user keeps there.
//!
//! A run writes `DIR/.<name>.partial-<pid>-<k>/` and, when it is complete, exchanges it with
//! `DIR/<name>/` in one step (Linux `renameat2(RENAME_EXCHANGE)`; elsewhere two renames), then
//! deletes what it exchanged out. Files in `DIR/<name>/` that `linkage` does not write (a user's
//! notes, a CSV) are moved into the new folder first, so a re-run keeps them. A run that stopped
//! early (its step could not be solved) never replaces complete results: its folder goes to
//! `DIR/<name>.failed/` beside them. Staging folders of processes that no longer exist (killed
//! runs) are removed by the next run of the same scene.

use std::io;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// What `linkage run` writes into a results folder; anything else there is the user's.
pub const WRITTEN: &[&str] = &[
    "summary.json",
    "model.json",
    "model.npz",
    "steps",
    "vtk",
    "png",
    "anim.gif",
    "plots",
    "index.html",
];

/// The suffix of the folder a failed run's results go to when complete results exist.
pub const FAILED_SUFFIX: &str = ".failed";

/// How many times publishing retries when another run puts its folder in place at the same
/// moment.
const ATTEMPTS: usize = 100;

/// A fresh staging folder name for a run of `name` in `out`: `.<name>.partial-<pid>-<k>`,
/// unique within the process (two runs of one name in a batch never share one).
pub fn staging_dir(out: &Path, name: &str) -> PathBuf {
    static RUNS: AtomicUsize = AtomicUsize::new(0);
    out.join(format!(
        ".{name}.partial-{}-{}",
        std::process::id(),
        RUNS.fetch_add(1, Ordering::Relaxed)
    ))
}

/// Remove staging and exchanged-out folders of `name` in `out` left by processes that no longer
/// exist (a run killed by SIGKILL cannot clean up after itself). Returns the folders removed.
/// Where it cannot tell whether a process lives (no `/proc`), it removes nothing.
pub fn remove_stale(out: &Path, name: &str) -> Vec<PathBuf> {
    let mut removed = Vec::new();
    let Ok(entries) = std::fs::read_dir(out) else {
        return removed;
    };
    for entry in entries.flatten() {
        let file_name = entry.file_name().to_string_lossy().into_owned();
        let Some(pid) = leftover_pid(&file_name, name) else {
            continue;
        };
        if pid != std::process::id() && process_is_gone(pid) {
            let path = entry.path();
            if std::fs::remove_dir_all(&path).is_ok() {
                removed.push(path);
            }
        }
    }
    removed
}

/// The process id in `.<name>.partial-<pid>-<k>` or `.<name>.old-<pid>-<k>`.
fn leftover_pid(file_name: &str, name: &str) -> Option<u32> {
    let rest = file_name.strip_prefix('.')?.strip_prefix(name)?;
    let rest = rest
        .strip_prefix(".partial-")
        .or_else(|| rest.strip_prefix(".old-"))?;
    let (pid, k) = rest.split_once('-')?;
    k.parse::<usize>().ok()?;
    pid.parse().ok()
}

/// Whether process `pid` is known not to exist.
fn process_is_gone(pid: u32) -> bool {
    Path::new("/proc/self").exists() && !Path::new(&format!("/proc/{pid}")).exists()
}

/// Whether `dir/summary.json` describes a run that solved every step (no `failure`).
pub fn holds_complete_results(dir: &Path) -> bool {
    let Ok(bytes) = std::fs::read(dir.join("summary.json")) else {
        return false;
    };
    match serde_json::from_slice::<serde_json::Value>(&bytes) {
        Ok(serde_json::Value::Object(map)) => !map.contains_key("failure"),
        _ => false,
    }
}

/// Where the results of a run of `final_dir` go: `final_dir` itself, or for a run that stopped
/// early while `final_dir` holds complete results, `<final_dir>.failed` beside it.
pub fn destination(final_dir: &Path, complete: bool) -> PathBuf {
    if complete || !holds_complete_results(final_dir) {
        return final_dir.to_path_buf();
    }
    let mut name = final_dir
        .file_name()
        .map(|n| n.to_os_string())
        .unwrap_or_default();
    name.push(FAILED_SUFFIX);
    final_dir.with_file_name(name)
}

/// Put the complete folder `staging` at `target`, replacing an earlier folder there in one
/// step; entries of the earlier folder not in [`WRITTEN`] are moved into the new one first.
/// Safe against another run publishing the same `target` at the same moment: whichever
/// finishes last is what stays.
pub fn publish(staging: &Path, target: &Path) -> io::Result<()> {
    publish_keeping(staging, target, &|name| WRITTEN.iter().any(|w| name == *w))
}

/// [`publish`] for any folder of `linkage`'s: the entries of the earlier folder for which
/// `written` is false (not written by `linkage`, so the user's) are moved into the new one
/// first; the others go with the earlier folder. `linkage render` publishes its `png/` so.
pub fn publish_keeping(
    staging: &Path,
    target: &Path,
    written: &dyn Fn(&std::ffi::OsStr) -> bool,
) -> io::Result<()> {
    let mut last = None;
    for _ in 0..ATTEMPTS {
        if target.exists() {
            keep_foreign_entries(target, staging, written)?;
            match exchange(staging, target) {
                // `staging` now holds the earlier folder.
                Ok(()) => return std::fs::remove_dir_all(staging),
                // The target went away meanwhile (another run exchanged it out): try again.
                Err(e) if e.kind() == io::ErrorKind::NotFound => last = Some(e),
                Err(e) => return Err(e),
            }
        } else {
            match std::fs::rename(staging, target) {
                Ok(()) => return Ok(()),
                // Another run put its folder there meanwhile: exchange with it instead.
                Err(e) if is_occupied(&e) => last = Some(e),
                Err(e) => return Err(e),
            }
        }
    }
    Err(last.unwrap_or_else(|| io::Error::other("the results folder kept changing")))
}

/// Whether a rename failed because its target is a folder that is not empty.
fn is_occupied(e: &io::Error) -> bool {
    matches!(e.raw_os_error(), Some(code) if code == libc::ENOTEMPTY || code == libc::EEXIST)
        || e.kind() == io::ErrorKind::AlreadyExists
        || e.kind() == io::ErrorKind::DirectoryNotEmpty
}

/// Move the entries of `from` that `linkage` does not write (`written` is false) into `to`.
fn keep_foreign_entries(
    from: &Path,
    to: &Path,
    written: &dyn Fn(&std::ffi::OsStr) -> bool,
) -> io::Result<()> {
    let entries = match std::fs::read_dir(from) {
        Ok(entries) => entries,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(e),
    };
    for entry in entries {
        let entry = entry?;
        let name = entry.file_name();
        if written(&name) {
            continue;
        }
        match std::fs::rename(entry.path(), to.join(&name)) {
            Ok(()) => {}
            Err(e) if e.kind() == io::ErrorKind::NotFound => {}
            Err(e) => return Err(e),
        }
    }
    Ok(())
}

/// Exchange the folders `a` and `b` atomically.
#[cfg(target_os = "linux")]
fn exchange(a: &Path, b: &Path) -> io::Result<()> {
    use std::ffi::CString;
    use std::os::unix::ffi::OsStrExt;
    let a = CString::new(a.as_os_str().as_bytes()).map_err(io::Error::other)?;
    let b = CString::new(b.as_os_str().as_bytes()).map_err(io::Error::other)?;
    // SAFETY: both paths are valid NUL-terminated strings that outlive the call.
    let r = unsafe {
        libc::syscall(
            libc::SYS_renameat2,
            libc::AT_FDCWD,
            a.as_ptr(),
            libc::AT_FDCWD,
            b.as_ptr(),
            libc::RENAME_EXCHANGE,
        )
    };
    if r == 0 {
        Ok(())
    } else {
        Err(io::Error::last_os_error())
    }
}

/// Exchange the folders `a` and `b`: `b` is moved aside under a unique name, then `a` takes
/// its place and the old `b` is put at `a`.
#[cfg(not(target_os = "linux"))]
fn exchange(a: &Path, b: &Path) -> io::Result<()> {
    static OLD: AtomicUsize = AtomicUsize::new(0);
    let aside = b.with_file_name(format!(
        ".{}.old-{}-{}",
        b.file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default(),
        std::process::id(),
        OLD.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::rename(b, &aside)?;
    std::fs::rename(a, b)?;
    std::fs::rename(&aside, a)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn folder(root: &Path, name: &str, files: &[(&str, &str)]) -> PathBuf {
        let dir = root.join(name);
        std::fs::create_dir_all(&dir).unwrap();
        for (f, text) in files {
            std::fs::write(dir.join(f), text).unwrap();
        }
        dir
    }

    #[test]
    fn replaces_the_folder_and_keeps_the_users_files() {
        let root = tempfile::tempdir().unwrap();
        let target = folder(
            root.path(),
            "scene",
            &[("summary.json", "{\"old\": 1}"), ("notes.txt", "mine")],
        );
        let staging = folder(root.path(), ".scene.partial-1-0", &[("summary.json", "{}")]);
        publish(&staging, &target).unwrap();
        assert_eq!(
            std::fs::read_to_string(target.join("summary.json")).unwrap(),
            "{}"
        );
        assert_eq!(
            std::fs::read_to_string(target.join("notes.txt")).unwrap(),
            "mine"
        );
        assert!(!staging.exists());
        // Nothing else is left beside it.
        let names: Vec<_> = std::fs::read_dir(root.path()).unwrap().flatten().collect();
        assert_eq!(names.len(), 1);
    }

    #[test]
    fn a_failed_run_goes_beside_complete_results() {
        let root = tempfile::tempdir().unwrap();
        let target = root.path().join("scene");
        assert_eq!(destination(&target, false), target);
        folder(root.path(), "scene", &[("summary.json", "{\"steps\": []}")]);
        assert_eq!(destination(&target, true), target);
        assert_eq!(
            destination(&target, false),
            root.path().join("scene.failed")
        );
        // Results of a failed run may be replaced by another failed run.
        folder(
            root.path(),
            "scene",
            &[("summary.json", "{\"steps\": [], \"failure\": \"x\"}")],
        );
        assert_eq!(destination(&target, false), target);
    }

    #[test]
    fn stale_staging_of_a_dead_process_is_removed_and_a_live_ones_kept() {
        let root = tempfile::tempdir().unwrap();
        // A pid above the kernel's limit (2^22) never runs.
        let dead = folder(root.path(), ".scene.partial-4194305-0", &[("a", "")]);
        let old = folder(root.path(), ".scene.old-4194305-3", &[]);
        let mine = folder(
            root.path(),
            &format!(".scene.partial-{}-7", std::process::id()),
            &[],
        );
        let other_scene = folder(root.path(), ".other.partial-4194305-0", &[]);
        let removed = remove_stale(root.path(), "scene");
        assert_eq!(removed.len(), 2, "{removed:?}");
        assert!(!dead.exists() && !old.exists());
        assert!(mine.exists() && other_scene.exists());
    }

    #[test]
    fn concurrent_publishers_of_one_name_all_succeed() {
        let root = tempfile::tempdir().unwrap();
        let target = root.path().join("scene");
        std::thread::scope(|s| {
            for _ in 0..8 {
                s.spawn(|| {
                    for _ in 0..20 {
                        let staging = staging_dir(root.path(), "scene");
                        std::fs::create_dir_all(staging.join("steps")).unwrap();
                        std::fs::write(staging.join("summary.json"), "{}").unwrap();
                        publish(&staging, &target).unwrap();
                    }
                });
            }
        });
        let names: Vec<_> = std::fs::read_dir(root.path()).unwrap().flatten().collect();
        assert_eq!(names.len(), 1, "{names:?}");
        assert!(target.join("summary.json").exists());
    }
}
