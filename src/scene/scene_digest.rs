//! A fingerprint of a scene's values, kept in `summary.json` so a batch run again over the same
//! `--out` skips a job only when its results came from the same scene.

/// FNV-1a (64 bit) of the scene's values, as 16 hex digits: of the TOML as `toml` writes it
/// back after parsing (so comments and layout do not count, and a sweep's variant has the
/// digest of a scene written by hand with its values), or of `text` itself when it is not TOML.
/// Portable and stable; not a cryptographic hash. Files a scene reads are not included (see
/// [`scene_and_files_digest`]).
pub fn scene_digest(text: &str) -> String {
    format!("{:016x}", fnv1a_64(FNV_OFFSET, canonical(text).as_bytes()))
}

/// [`scene_digest`] of `text` and of the contents of the files it names: every string value
/// of the scene (at any depth, in the order written) that is a file beside the scene in
/// `folder` (or an absolute path of one): the paper's nodes, links and patches files, meshes,
/// outlines and model files. Editing one of them changes the digest, so a re-run solves again.
pub fn scene_and_files_digest(text: &str, folder: &std::path::Path) -> String {
    let mut hash = fnv1a_64(FNV_OFFSET, canonical(text).as_bytes());
    if let Ok(table) = text.parse::<toml::Table>() {
        let value = toml::Value::Table(table);
        let mut names = Vec::new();
        strings(&value, &mut names);
        for name in names {
            let path = folder.join(name);
            if !path.is_file() {
                continue;
            }
            let Ok(bytes) = std::fs::read(&path) else {
                continue;
            };
            // The name and the length separate one file from the next.
            hash = fnv1a_64(hash, name.as_bytes());
            hash = fnv1a_64(hash, &(bytes.len() as u64).to_le_bytes());
            hash = fnv1a_64(hash, &bytes);
        }
    }
    format!("{hash:016x}")
}

/// Every string value in `value`, depth first in the order written.
fn strings<'a>(value: &'a toml::Value, out: &mut Vec<&'a str>) {
    match value {
        toml::Value::String(s) => out.push(s),
        toml::Value::Array(items) => items.iter().for_each(|v| strings(v, out)),
        toml::Value::Table(t) => t.values().for_each(|v| strings(v, out)),
        _ => {}
    }
}

/// The TOML of `text` as `toml` writes it back after parsing, or `text` when it is not TOML.
fn canonical(text: &str) -> String {
    text.parse::<toml::Table>()
        .ok()
        .and_then(|t| toml::to_string(&t).ok())
        .unwrap_or_else(|| text.to_string())
}

const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

/// FNV-1a (64 bit) of `bytes`, continuing from `hash` ([`FNV_OFFSET`] to start).
fn fnv1a_64(hash: u64, bytes: &[u8]) -> u64 {
    const PRIME: u64 = 0x0000_0100_0000_01b3;
    bytes
        .iter()
        .fold(hash, |h, &b| (h ^ u64::from(b)).wrapping_mul(PRIME))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a_64_test_vectors() {
        // The published FNV-1a 64 vectors (Fowler, Noll, Vo).
        let hex = |t: &str| format!("{:016x}", fnv1a_64(FNV_OFFSET, t.as_bytes()));
        assert_eq!(hex(""), "cbf29ce484222325");
        assert_eq!(hex("a"), "af63dc4c8601ec8c");
        assert_eq!(hex("foobar"), "85944171f73967e8");
    }

    #[test]
    fn comments_and_layout_do_not_count_values_do() {
        let a = scene_digest("name = \"s\"\nsteps = 2 # two\n");
        assert_eq!(a, scene_digest("# a scene\nname=\"s\"\n\nsteps =   2\n"));
        assert_ne!(a, scene_digest("name = \"s\"\nsteps = 3\n"));
    }

    #[test]
    fn the_files_a_scene_names_count() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("a.nodes"), "1 0 0\n").unwrap();
        let text = "name = \"s\"\n[[bodies]]\nnodes = \"a.nodes\"\nmaterial = \"steel\"\n";
        let before = scene_and_files_digest(text, dir.path());
        assert_eq!(before, scene_and_files_digest(text, dir.path()));
        assert_ne!(before, scene_digest(text));
        std::fs::write(dir.path().join("a.nodes"), "1 0 1\n").unwrap();
        assert_ne!(before, scene_and_files_digest(text, dir.path()));
        // Without the file, only the text counts.
        std::fs::remove_file(dir.path().join("a.nodes")).unwrap();
        assert_eq!(scene_and_files_digest(text, dir.path()), scene_digest(text));
    }
}
