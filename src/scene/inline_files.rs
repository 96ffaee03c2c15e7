//! The texts of the paper's files held in memory instead of on disk: a scene built by a
//! program (the Python package's `Body` from arrays) names its nodes and links files as a scene
//! file does, and [`crate::scene::build_world_with`] reads them from here first.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// File texts by the path a scene's key resolves to (the scene file's folder joined with the
/// name the key gives): read instead of the disk, and written out by [`InlineFiles::write`].
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct InlineFiles {
    texts: BTreeMap<PathBuf, String>,
}

impl InlineFiles {
    /// Hold `text` as the file at `path` (replacing an earlier text of that path).
    pub fn insert(&mut self, path: PathBuf, text: String) {
        self.texts.insert(path, text);
    }

    /// The text held for `path`, if any.
    pub fn get(&self, path: &Path) -> Option<&str> {
        self.texts.get(path).map(String::as_str)
    }

    /// Whether no file is held.
    pub fn is_empty(&self) -> bool {
        self.texts.is_empty()
    }

    /// The held files, by path.
    pub fn iter(&self) -> impl Iterator<Item = (&Path, &str)> {
        self.texts.iter().map(|(p, t)| (p.as_path(), t.as_str()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_held_text_is_found_by_its_path_only() {
        let mut files = InlineFiles::default();
        assert!(files.is_empty());
        files.insert(PathBuf::from("a/truss.nodes"), "0 0\n1 0\n".into());
        assert_eq!(files.get(Path::new("a/truss.nodes")), Some("0 0\n1 0\n"));
        assert_eq!(files.get(Path::new("truss.nodes")), None);
        assert_eq!(files.iter().count(), 1);
    }
}
