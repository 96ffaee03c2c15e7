//! `linkage bench --read`: reading the paper's files of a large 3D box lattice (nodes, links
//! with a material column, patches), and checking its members, best of several reads.

use crate::linkage::check_members;
use crate::linkage::generators::box_lattice;
use crate::scene::paper_files::{
    read_links, read_nodes, read_patches, write_links, write_nodes, write_patches,
};
use crate::Real;
use std::path::Path;
use std::time::Instant;

/// The files' sizes and the best time of each phase, s.
#[derive(Clone, Debug, PartialEq)]
pub struct ReadTiming {
    /// Cells per direction.
    pub cells: [usize; 3],
    /// Nodes.
    pub nodes: usize,
    /// Members (lines of the links file).
    pub members: usize,
    /// Patches.
    pub patches: usize,
    /// Bytes of the links file.
    pub links_bytes: u64,
    /// Reading and parsing the nodes file, s.
    pub nodes_seconds: Real,
    /// Reading and parsing the links file, its members checked (as a scene's load does), s.
    pub links_seconds: Real,
    /// The member check alone (part of `links_seconds`), s.
    pub check_seconds: Real,
    /// Reading and parsing the patches file, s.
    pub patches_seconds: Real,
}

/// The paper's files of a box lattice written by [`write_lattice_files`].
#[derive(Clone, Debug, PartialEq)]
pub struct LatticeFiles {
    /// The nodes file.
    pub nodes: std::path::PathBuf,
    /// The links file (each line with the material column `steel`).
    pub links: std::path::PathBuf,
    /// The patches file.
    pub patches: std::path::PathBuf,
    /// Nodes, members and patches written.
    pub counts: [usize; 3],
}

/// Write the paper's files of a box lattice of `cells` (0.01 m cells, from the origin) into
/// `dir` as `lattice.nodes`, `lattice.links` (material `steel`) and `lattice.patches`.
pub fn write_lattice_files(cells: [usize; 3], dir: &Path) -> Result<LatticeFiles, String> {
    let size = cells.map(|c| c as Real * 0.01);
    let g = box_lattice(size, cells).map_err(|e| e.to_string())?;
    let names = vec!["steel".to_string(); g.members.len()];
    let files = LatticeFiles {
        nodes: dir.join("lattice.nodes"),
        links: dir.join("lattice.links"),
        patches: dir.join("lattice.patches"),
        counts: [g.nodes.len(), g.members.len(), g.patches.len()],
    };
    let io = |e: std::io::Error| format!("{}: {e}", dir.display());
    write_nodes(&files.nodes, g.dimension, &g.nodes).map_err(io)?;
    write_links(&files.links, &g.members, Some(&names)).map_err(io)?;
    write_patches(&files.patches, &g.patches).map_err(io)?;
    Ok(files)
}

/// Write the files of a lattice of `cells` (0.01 m cells) into `dir`, then read them `repeats`
/// times and keep each phase's best time.
pub fn measure_read(cells: [usize; 3], dir: &Path, repeats: usize) -> Result<ReadTiming, String> {
    let files = write_lattice_files(cells, dir)?;
    let (nodes_path, links_path, patches_path) = (&files.nodes, &files.links, &files.patches);
    let io = |e: std::io::Error| format!("{}: {e}", dir.display());
    let mut t = ReadTiming {
        cells,
        nodes: files.counts[0],
        members: files.counts[1],
        patches: files.counts[2],
        links_bytes: std::fs::metadata(links_path).map_err(io)?.len(),
        nodes_seconds: Real::INFINITY,
        links_seconds: Real::INFINITY,
        check_seconds: Real::INFINITY,
        patches_seconds: Real::INFINITY,
    };
    for _ in 0..repeats.max(1) {
        let clock = Instant::now();
        let (_, nodes) = read_nodes(nodes_path).map_err(|e| e.to_string())?;
        t.nodes_seconds = t.nodes_seconds.min(clock.elapsed().as_secs_f64());
        let clock = Instant::now();
        let links = read_links(links_path, &nodes).map_err(|e| e.to_string())?;
        t.links_seconds = t.links_seconds.min(clock.elapsed().as_secs_f64());
        let clock = Instant::now();
        check_members(&nodes, links.iter().map(|r| r.nodes)).map_err(|p| format!("{p:?}"))?;
        t.check_seconds = t.check_seconds.min(clock.elapsed().as_secs_f64());
        let clock = Instant::now();
        read_patches(patches_path, nodes.len()).map_err(|e| e.to_string())?;
        t.patches_seconds = t.patches_seconds.min(clock.elapsed().as_secs_f64());
        if links.len() != t.members {
            return Err(format!(
                "read {} members back, wrote {}",
                links.len(),
                t.members
            ));
        }
    }
    Ok(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_small_lattice_reads_back_whole() {
        let dir = std::env::temp_dir().join(format!("linkage-bench-read-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let t = measure_read([3, 2, 2], &dir, 1).unwrap();
        assert_eq!(t.nodes, 4 * 3 * 3);
        assert!(t.members > 0 && t.links_seconds.is_finite());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
