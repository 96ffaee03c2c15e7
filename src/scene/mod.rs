//! Scene files, the load-step driver and the result files.

pub use self::build::{build_world, build_world_until, build_world_with, load_scene, SceneError};
pub use self::check::{
    check_world, obstacle_offset_bytes, output_warning, step_file_bytes, stored_steps, CheckReport,
    BYTES_PER_VALUE, NPZ_BYTES_PER_VALUE, OUTPUT_WARNING_BYTES,
};
pub use self::contact_concentration::{CONCENTRATED_SHARE, NEIGHBOUR_SLOPE};
pub use self::driver::{run, run_in_memory, run_into, run_with};
pub use self::dynamic_fracture::{
    BreakingBodies, StepSolve, TimedBreak, TrialSteps, AT_STRENGTH, EVENT_TIME,
};
pub use self::dynamic_simulation::{solve_time_step, DynamicSimulation, MAX_TIME_STEP_HALVINGS};
pub use self::inline_files::InlineFiles;
pub use self::model_file::{ModelBody, ModelFile, ModelObstacle, SupportedNode, HALF_SPACE_PATCH};
pub use self::pictures::{PictureSettings, MAX_FRAME_SIDE};
pub use self::plot_settings::{
    load_name, NamedSupport, PlotNode, PlotPlace, PlotSettings, PLOT_SETTINGS,
};
pub use self::prepared_body::{prepare_file, read_outline, write_prepared};
pub use self::result_format::{ResultFormat, NPZ_ABOVE_MEMBERS};
pub use self::results::{
    BodyFracture, BodyResult, BodySize, BreakRecord, Collapse, ContactForce, NodeForce, PairForce,
    PhaseSeconds, StepResult, StepSummary, Summary, SummaryBreak,
};
pub use self::run_error::RunError;
pub use self::run_results::{step_digits, step_stem, RunResults, MIN_STEP_DIGITS};
pub use self::scene_digest::{scene_and_files_digest, scene_digest};
pub use self::selector::{far_nearest_warning, select_nodes, select_nodes_in, FAR_NEAREST};
pub use self::simulation::{Simulation, WorldSolver};
pub use self::stepper::Stepper;
pub use self::stored_run::{StoredRun, StoredRunError};
pub use self::strain_warning::LINEAR_STRAIN_WARNING;
pub use self::sweep::{expand_sweep, with_values, SweepMode, Variant};
pub use self::vtk::{write_vtk, VtkError};
pub use self::vtu_arrays::VtkEncoding;
pub use self::world::{OutputSettings, World};
pub use self::writers::DrawResults;

mod arc_length_stops;
pub mod atomic_file;
pub mod batch;
mod bounds;
mod build;
mod capacity;
mod check;
mod contact_concentration;
mod contact_pairs;
mod driver;
mod dynamic_contact;
mod dynamic_fracture;
mod dynamic_simulation;
pub mod dynamics_settings;
pub mod fits_machine;
pub mod import;
mod inline_files;
mod instability;
mod link_lines;
mod mesh_file;
mod model_file;
pub(crate) mod npz_archive;
mod npz_files;
mod obstacles;
pub mod paper_files;
mod peak_stress;
mod pictures;
mod plot_settings;
mod prepared_body;
mod pressures;
pub mod publish;
mod result_format;
mod results;
mod run_error;
mod run_results;
mod scene_digest;
mod selector;
mod simulation;
pub mod spec;
mod step_writer;
mod stepper;
mod stored_run;
mod strain_warning;
pub mod sweep;
mod toml_error;
mod vtk;
mod vtu_arrays;
mod world;
mod writers;
