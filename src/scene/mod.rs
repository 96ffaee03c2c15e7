//! Scene files, the load-step driver and the result files.

pub use self::build::{build_world, load_scene, SceneError};
pub use self::results::{
    BodyResult, BodySize, ContactForce, NodeForce, PhaseSeconds, StepResult, StepSummary, Summary,
};
pub use self::selector::select_nodes;
pub use self::simulation::{run, RunError, Simulation};
pub use self::world::{OutputSettings, World};

mod build;
mod results;
mod selector;
mod simulation;
pub mod spec;
mod world;
