//! Contact between deformable bodies and rigid obstacles: obstacles held in rapier, penalty forces with their stiffness, and the settle loop.

pub use self::boundary::boundary_loop;
pub use self::contact_set::{ActiveContact, ContactSet, NodeContact, Target};
pub use self::error::ContactError;
pub use self::fracture::{ContactFracture, FractureStop, AT_STRENGTH};
pub use self::friction::{
    return_mapping, Committed, FrictionHistory, FrictionKey, FrictionPair, FrictionSettings,
    SlipState, Tangential,
};
pub use self::mesh_orientation::{orient_outward, MeshProblem, Orientation};
pub use self::obstacle::{Obstacle, ObstacleShape};
pub use self::obstacle_features::{sharp_sample_estimate, MAX_SHARP_SAMPLES, SAMPLE_SPACING};
pub use self::obstacles::{mesh_collider, primitive_collider, ObstacleProjection, Obstacles};
pub use self::patch_surface::{PatchSurface, SurfaceProblem};
pub use self::penalty::{default_penalty, penetration_tolerance, Penalty, PENALTY_FACTOR};
pub use self::report::ContactStep;
pub use self::self_contact::{self_contact_on, SELF_REACH_MEMBERS, SELF_RINGS};
pub use self::self_watch::{SelfContactWatch, SelfTouch};
pub use self::settings::ContactSettings;
pub use self::settle::ContactSolver;
pub use self::start::StartOverlap;
pub use self::surface::{cut_by_z0, obstacle_surface, Surface};
pub use self::time_step::TimeStepState;

mod body_part;
mod boundary;
mod condensed;
mod contact_set;
mod coupled;
mod coupled_iterative;
mod coupled_system;
mod cylinder_rim;
mod detect;
mod error;
mod evaluate;
mod fracture;
mod free_motions;
mod friction;
mod increments;
mod mesh_orientation;
mod obstacle;
mod obstacle_features;
mod obstacles;
mod patch_surface;
mod penalty;
mod pressing;
mod problem;
mod report;
mod self_contact;
mod self_watch;
mod settings;
mod settle;
mod start;
mod surface;
mod ties;
mod time_step;
mod unheld;
