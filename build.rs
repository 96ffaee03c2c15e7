//! Empty: it exists so that `[build-dependencies]` in Cargo.toml count (feature unification of
//! the proc-macros' `syn` with the Python package's build, see there).
fn main() {}
