//! Model files made elsewhere (gmsh MSH 4.1, Abaqus/CalculiX INP) read as bodies, and
//! `linkage import`'s scene and paper files of them.

pub use self::error::ModelFileError;
pub use self::imported_model::{
    find_group, read_model, ImportedModel, ModelMaterial, ModelSupport, NodeGroup,
};
pub use self::inp::read_inp;
pub use self::msh::{read_msh, MshElement, MshElementKind, MshMesh};
pub use self::msh_model::model_of_msh;
pub use self::scene_writer::{import_file, ImportError, ImportedScene};

mod error;
mod imported_model;
mod inp;
mod inp_lines;
mod msh;
mod msh_cursor;
mod msh_model;
mod scene_writer;
