//! Bodies prepared from closed triangle meshes (isosurface stuffing) and 2D outlines.

pub use self::error::PrepareError;
pub use self::mesh_body::{
    prepare_mesh, prepare_mesh_until, PreparedBody, MAX_SPACING_FRACTION, MEMORY_LIMIT,
};
pub use self::outline::{
    prepare_outline, prepare_outline_until, MAX_TRIANGLES, MIN_TRIANGLE_ANGLE,
};
pub use self::quality::{dihedral_angles, enclosed_volume, PrepareReport};
pub use self::stuffing::{ALPHA_LONG, ALPHA_SHORT};

mod bcc_lattice;
mod closed_surface;
mod error;
mod mesh_body;
mod outline;
mod quality;
mod self_intersection;
mod stuffing;
mod tet_mesh;
