//! A fingerprint of a scene's values, kept in `summary.json` so a batch run again over the same
//! `--out` skips a job only when its results came from the same scene.

/// FNV-1a (64 bit) of the scene's values, as 16 hex digits: of the TOML as `toml` writes it
/// back after parsing (so comments and layout do not count, and a sweep's variant has the
/// digest of a scene written by hand with its values), or of `text` itself when it is not TOML.
/// Portable and stable; not a cryptographic hash. Files a scene reads are not included.
pub fn scene_digest(text: &str) -> String {
    let canonical = text
        .parse::<toml::Table>()
        .ok()
        .and_then(|t| toml::to_string(&t).ok());
    fnv1a_64(canonical.as_deref().unwrap_or(text))
}

/// FNV-1a (64 bit) of `text`'s bytes, as 16 hex digits.
fn fnv1a_64(text: &str) -> String {
    const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
    const PRIME: u64 = 0x0000_0100_0000_01b3;
    let hash = text
        .bytes()
        .fold(OFFSET, |h, b| (h ^ u64::from(b)).wrapping_mul(PRIME));
    format!("{hash:016x}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a_64_test_vectors() {
        // The published FNV-1a 64 vectors (Fowler, Noll, Vo).
        assert_eq!(fnv1a_64(""), "cbf29ce484222325");
        assert_eq!(fnv1a_64("a"), "af63dc4c8601ec8c");
        assert_eq!(fnv1a_64("foobar"), "85944171f73967e8");
    }

    #[test]
    fn comments_and_layout_do_not_count_values_do() {
        let a = scene_digest("name = \"s\"\nsteps = 2 # two\n");
        assert_eq!(a, scene_digest("# a scene\nname=\"s\"\n\nsteps =   2\n"));
        assert_ne!(a, scene_digest("name = \"s\"\nsteps = 3\n"));
    }
}
