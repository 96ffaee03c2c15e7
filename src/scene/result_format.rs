//! `[output] format`: whether a run writes its step files and model as JSON or as NumPy `.npz`.

/// Above this many members (all bodies together) a run writes `.npz` unless the scene says
/// otherwise: a step file of a large model is 2.5 times smaller and many times faster to write
/// and read as binary (see `docs/PERFORMANCE.md`, *Binary results*).
pub const NPZ_ABOVE_MEMBERS: usize = 100_000;

/// How a run stores `steps/NNNN.*` and `model.*` (`summary.json` is always JSON).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ResultFormat {
    /// `steps/NNNN.json` and `model.json`.
    Json,
    /// `steps/NNNN.npz` and `model.npz`: NumPy archives with the same fields as arrays.
    Npz,
}

impl ResultFormat {
    /// The format of a scene that does not say: JSON up to [`NPZ_ABOVE_MEMBERS`] members in
    /// all, `.npz` above.
    pub fn default_for(members: usize) -> Self {
        if members > NPZ_ABOVE_MEMBERS {
            ResultFormat::Npz
        } else {
            ResultFormat::Json
        }
    }

    /// `"json"` or `"npz"`; anything else is `None`.
    pub fn parse(name: &str) -> Option<Self> {
        match name {
            "json" => Some(ResultFormat::Json),
            "npz" => Some(ResultFormat::Npz),
            _ => None,
        }
    }

    /// The file name extension, without the dot: `"json"` or `"npz"`.
    pub fn extension(self) -> &'static str {
        match self {
            ResultFormat::Json => "json",
            ResultFormat::Npz => "npz",
        }
    }

    /// The model file's name: `model.json` or `model.npz`.
    pub fn model_file(self) -> &'static str {
        match self {
            ResultFormat::Json => "model.json",
            ResultFormat::Npz => "model.npz",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_up_to_a_hundred_thousand_members_npz_above() {
        assert_eq!(ResultFormat::default_for(0), ResultFormat::Json);
        assert_eq!(ResultFormat::default_for(100_000), ResultFormat::Json);
        assert_eq!(ResultFormat::default_for(100_001), ResultFormat::Npz);
        assert_eq!(ResultFormat::default_for(1_500_000), ResultFormat::Npz);
    }

    #[test]
    fn names_and_files() {
        assert_eq!(ResultFormat::parse("npz"), Some(ResultFormat::Npz));
        assert_eq!(ResultFormat::parse("json"), Some(ResultFormat::Json));
        assert_eq!(ResultFormat::parse("NPZ"), None);
        assert_eq!(ResultFormat::Npz.model_file(), "model.npz");
        assert_eq!(ResultFormat::Json.extension(), "json");
    }
}
