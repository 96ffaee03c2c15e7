//! Generators for the paper's shapes: a disk (Fig. 1), a rectangle (Fig. 4–6), a cylindrical shell (Fig. 7) and a box lattice.

pub use self::box_lattice::box_lattice;
pub use self::cylindrical_shell::cylindrical_shell;
pub use self::disk::disk;
pub use self::error::GeneratorError;
pub use self::rectangle::rectangle;

mod box_lattice;
mod cylindrical_shell;
mod disk;
mod error;
mod rectangle;
#[cfg(test)]
mod rigidity;
