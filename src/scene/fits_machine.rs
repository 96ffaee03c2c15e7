//! Whether a run fits the machine: its memory and disk estimates against what the machine has
//! (`/proc/meminfo`'s `MemAvailable`, `statvfs` of the output folder), checked before anything
//! is allocated, so that an absurd size (`steps = 4294967296`) is refused with a message
//! instead of aborting on an allocation.

use crate::scene::check::{obstacle_offset_bytes, step_file_bytes, stored_steps};
use crate::scene::results::StepSummary;
use crate::scene::World;
use std::path::Path;

/// Bytes the run of `world` holds in memory whatever its model: one summary line per step
/// (`(steps + 1) × size_of::<StepSummary>()`), the obstacles' offsets of `model.json`, and with
/// `keeps_steps` (pictures or VTK drawn after the steps) every stored step's result (about its
/// file's size).
pub fn memory_estimate(world: &World, keeps_steps: bool) -> u64 {
    let lines = (world.steps as u64)
        .saturating_add(1)
        .saturating_mul(std::mem::size_of::<StepSummary>() as u64);
    let kept = if keeps_steps {
        stored_steps(&world.output, world.steps).saturating_mul(step_file_bytes(world))
    } else {
        0
    };
    lines
        .saturating_add(kept)
        .saturating_add(obstacle_offset_bytes(world))
}

/// Bytes of the files the run of `world` writes: its stored step files and the obstacles'
/// offsets.
pub fn disk_estimate(world: &World) -> u64 {
    stored_steps(&world.output, world.steps)
        .saturating_mul(step_file_bytes(world))
        .saturating_add(obstacle_offset_bytes(world))
}

/// The machine's available memory, bytes (`MemAvailable` of `/proc/meminfo`; `None` where it
/// cannot be read).
pub fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb.saturating_mul(1024))
}

/// Free bytes for an unprivileged user on the file system of `folder` (`statvfs`; `None`
/// where it cannot be asked).
pub fn free_disk(folder: &Path) -> Option<u64> {
    use std::os::unix::ffi::OsStrExt;
    let path = std::ffi::CString::new(folder.as_os_str().as_bytes()).ok()?;
    // SAFETY: `path` is a NUL-terminated string and `stat` a plain struct statvfs fills.
    let mut stat: libc::statvfs = unsafe { std::mem::zeroed() };
    let r = unsafe { libc::statvfs(path.as_ptr(), &mut stat) };
    // The field types differ between platforms (u32 or u64).
    #[allow(clippy::unnecessary_cast)]
    let (blocks, size) = (stat.f_bavail as u64, stat.f_frsize as u64);
    (r == 0).then(|| blocks.saturating_mul(size))
}

/// Why the run of `world` into `out` cannot fit (`None` when it can, or when the machine
/// cannot be asked): the estimate, what the machine has, and what to change.
pub fn refusal(world: &World, out: &Path, keeps_steps: bool) -> Option<String> {
    let gb = |b: u64| b as f64 / 1e9;
    // A dynamic run's steps are its stored frames ([dynamics] frames).
    let steps = if world.dynamics.is_some() {
        "frames"
    } else {
        "load steps"
    };
    let memory = memory_estimate(world, keeps_steps);
    if let Some(have) = available_memory().filter(|&have| memory > have) {
        return Some(format!(
            "the run would need about {:.1} GB of memory for its {} {steps} (and the stored steps the pictures or VTK files need) but the machine has {:.1} GB available: use fewer {steps}{}",
            gb(memory),
            world.steps,
            gb(have),
            if keeps_steps { ", or write no pictures and VTK files" } else { "" }
        ));
    }
    let disk = disk_estimate(world);
    if let Some(free) = free_disk(out).filter(|&free| disk > free) {
        return Some(format!(
            "the run would write about {:.1} GB of step files but {} has {:.1} GB free: write fewer steps with [output] every = k or last_only = true, or use fewer {steps}",
            gb(disk),
            out.display(),
            gb(free)
        ));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_machine_reports_memory_and_disk() {
        let memory = available_memory().expect("/proc/meminfo");
        assert!(memory > 1 << 20, "{memory}");
        let disk = free_disk(Path::new(".")).expect("statvfs");
        assert!(disk > 0);
        assert!(free_disk(Path::new("/no/such/folder")).is_none());
    }
}
