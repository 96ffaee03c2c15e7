//! Time integration: bodies with inertia. A time step is a load step with inertia (see
//! `DESIGN.md`): an integrator turns one time step into the problem a load step is, with the
//! residual gaining an inertia term and the tangent its matrix.
#![doc = include_str!("README.md")]

pub use self::backward_euler::BackwardEuler;
pub use self::body_motion::{BodyMotion, TimeStepFailure, TimeStepReport};
pub use self::discrete_gradient::{
    discrete_gradient_block, discrete_gradient_forces, strain_energy,
};
pub use self::energy::{angular_momentum, centre_of_mass, kinetic_energy, momentum};
pub use self::energy_momentum::EnergyMomentum;
pub use self::generalized_alpha::GeneralizedAlpha;
pub use self::inertia::InertiaTerm;
pub use self::integrator::{Integrator, Motion, StepForm};
pub use self::lumped_mass::{lumped_mass, node_masses, MassError};
pub use self::newmark::Newmark;
pub use self::rayleigh::RayleighDamping;
pub use self::time_schedule::{loads_at_time, prescribed_at_time, time_factor};

mod backward_euler;
mod body_motion;
mod discrete_gradient;
mod energy;
mod energy_momentum;
mod generalized_alpha;
mod inertia;
mod integrator;
mod lumped_mass;
mod newmark;
mod rayleigh;
mod time_schedule;
