//! Whether a run fits the machine: its memory and disk estimates against what the machine has
//! (`/proc/meminfo`'s `MemAvailable`, `statvfs` of the output folder), checked before anything
//! is allocated, so that an absurd size (`steps = 4294967296`) is refused with a message
//! instead of aborting on an allocation.

use crate::linkage::generators::{
    box_lattice_size, cylindrical_shell_size, disk_size, rectangle_size, GeneratedSize,
};
use crate::scene::check::{obstacle_offset_bytes, step_file_bytes, stored_steps};
use crate::scene::results::StepSummary;
use crate::scene::spec::BodySpec;
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

/// Bytes per node of a generated body, at the least, while it is built and solved: its
/// position, displacement, force and reaction (4 × 3 × 8 B) and its degree-of-freedom slots
/// (3 × 16 B).
pub const BYTES_PER_NODE: u64 = 144;
/// Bytes per member of a generated body, at the least, while it is built and solved, besides
/// its stiffness entries: its end nodes as made (16 B), as a member with its material (24 B),
/// and its force and strain (16 B).
pub const BYTES_PER_MEMBER: u64 = 56;
/// Bytes per stiffness entry (an 8 B value and an 8 B row index); a member adds d² entries
/// (its two ends' cross block) for d = 2 or 3 directions per node. Fill-in of the
/// factorization comes on top: the estimate is a lower bound.
pub const BYTES_PER_STIFFNESS_ENTRY: u64 = 16;
/// Bytes per boundary patch (its three nodes).
pub const BYTES_PER_PATCH: u64 = 24;

/// Bytes a generated body of `size` needs at the least to be built and solved, with `dofs`
/// directions per node (2 or 3): `nodes · BYTES_PER_NODE + members · (BYTES_PER_MEMBER +
/// dofs² · BYTES_PER_STIFFNESS_ENTRY) + patches · BYTES_PER_PATCH`. A float: an absurd size is
/// beyond every integer type.
pub fn generated_memory(size: &GeneratedSize, dofs: usize) -> f64 {
    let d = dofs as f64;
    size.nodes * BYTES_PER_NODE as f64
        + size.members * (BYTES_PER_MEMBER as f64 + d * d * BYTES_PER_STIFFNESS_ENTRY as f64)
        + size.patches * BYTES_PER_PATCH as f64
}

/// Why the body a generator would make cannot fit in `available` bytes of memory (`None`
/// when it fits): the generator `key` (e.g. `"box_lattice"`), its `parameters` as written
/// (e.g. `"cells = [1000, 1000, 1000]"`), the counts, the estimate and what to change.
pub fn generated_refusal(
    key: &str,
    parameters: &str,
    size: &GeneratedSize,
    dofs: usize,
    available: u64,
) -> Option<String> {
    let memory = generated_memory(size, dofs);
    (memory > available as f64).then(|| {
        format!(
            "`{key}` with {parameters} would make {:.3e} nodes and {:.3e} members: building and solving them needs at least {:.3e} GB of memory, but the machine has {:.1} GB available: give fewer cells (the memory grows with the member count)",
            size.nodes,
            size.members,
            memory / 1e9,
            available as f64 / 1e9
        )
    })
}

/// Why the body `spec` generates (`disk`, `rectangle`, `cylindrical_shell`, `box_lattice`)
/// cannot fit in the machine's available memory, checked before anything is allocated (see
/// [`generated_refusal`]); `None` when it fits, when the body is not generated, or when the
/// machine cannot be asked.
pub fn generator_refusal(spec: &BodySpec) -> Option<String> {
    let (key, parameters, size, dofs) = if let Some(g) = &spec.disk {
        let p = format!("rings = {}, sectors = {}", g.rings, g.sectors);
        ("disk", p, disk_size(g.rings, g.sectors), 2)
    } else if let Some(g) = &spec.rectangle {
        let p = format!("cells = [{}, {}]", g.cells[0], g.cells[1]);
        ("rectangle", p, rectangle_size(g.cells[0], g.cells[1]), 2)
    } else if let Some(g) = &spec.cylindrical_shell {
        let p = format!("rings = {}, sectors = {}", g.rings, g.sectors);
        let size = cylindrical_shell_size(g.rings, g.sectors);
        ("cylindrical_shell", p, size, 3)
    } else if let Some(g) = &spec.box_lattice {
        let [x, y, z] = g.cells;
        let p = format!("cells = [{x}, {y}, {z}]");
        ("box_lattice", p, box_lattice_size(g.cells), 3)
    } else {
        return None;
    };
    generated_refusal(key, &parameters, &size, dofs, available_memory()?)
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

    /// The estimate by hand: a rectangle of 2 × 1 cells has 6 nodes and 11 members (4
    /// horizontal, 3 vertical, 4 diagonal; 2D), so 6 · 144 + 11 · (56 + 4 · 16) = 864 + 1320
    /// = 2184 B; a box lattice of one cell has 8
    /// nodes, 28 members and 12 patches (3D): 8 · 144 + 28 · (56 + 9 · 16) + 12 · 24 =
    /// 1152 + 5600 + 288 = 7040 B.
    #[test]
    fn the_generated_memory_is_counted_as_by_hand() {
        use crate::linkage::generators::{box_lattice_size, rectangle_size};
        assert_eq!(generated_memory(&rectangle_size(2, 1), 2), 2184.0);
        assert_eq!(generated_memory(&box_lattice_size([1, 1, 1]), 3), 7040.0);
        let size = box_lattice_size([1000, 1000, 1000]);
        let why = generated_refusal(
            "box_lattice",
            "cells = [1000, 1000, 1000]",
            &size,
            3,
            16 << 30,
        )
        .expect("1e9 cells do not fit in 16 GiB");
        for part in [
            "`box_lattice` with cells = [1000, 1000, 1000]",
            "1.003e9 nodes",
            "1.301e10 members",
            "at least 2.747e3 GB of memory",
            "the machine has 17.2 GB available",
            "fewer cells",
        ] {
            assert!(why.contains(part), "{part:?} in {why}");
        }
        assert!(generated_refusal(
            "box_lattice",
            "cells = [1, 1, 1]",
            &box_lattice_size([1, 1, 1]),
            3,
            7040
        )
        .is_none());
        assert!(generated_refusal(
            "box_lattice",
            "cells = [1, 1, 1]",
            &box_lattice_size([1, 1, 1]),
            3,
            7039
        )
        .is_some());
    }
}
