//! Generators for the paper's shapes: a disk (Fig. 1), a rectangle (Fig. 4–6), a cylindrical shell (Fig. 7), a box lattice, and loaded lattices for tests and benchmarks.

pub use self::box_lattice::box_lattice;
pub use self::cylindrical_shell::cylindrical_shell;
pub use self::disk::disk;
pub use self::error::GeneratorError;
pub use self::loaded_lattice::{lattice_body, loaded_lattice};
pub use self::rectangle::rectangle;
pub use self::size::{
    box_lattice_size, cylindrical_shell_size, disk_size, rectangle_size, GeneratedSize,
};

mod box_lattice;
mod cylindrical_shell;
mod disk;
mod error;
mod loaded_lattice;
mod rectangle;
#[cfg(test)]
mod rigidity;
mod size;
