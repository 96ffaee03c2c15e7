//! glTF 2.0 animation of a run (`anim.glb`) for Blender and the web.
#![doc = include_str!("README.md")]

pub use self::document::gltf_of_run;
pub use self::glb::glb_bytes;
pub use self::write_gltf::{write_gltf, GltfReport, GLTF_BUDGET, GLTF_FILE};

mod document;
mod glb;
mod write_gltf;
