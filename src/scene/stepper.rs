//! What steps a world: its load steps ([`Simulation`]) or, with `[dynamics]`, its frames in
//! time ([`DynamicSimulation`]). The driver and `linkage check` take either.

use crate::linkage::PhaseTimes;
use crate::scene::dynamic_simulation::DynamicSimulation;
use crate::scene::results::{BodySize, StepResult, StepSummary};
use crate::scene::run_error::RunError;
use crate::scene::simulation::Simulation;
use crate::scene::World;
use crate::Real;

/// A world ready to step, quasi-statically or in time.
#[allow(clippy::large_enum_variant)]
pub enum Stepper<'w> {
    /// Load steps.
    Static(Simulation<'w>),
    /// Frames in time.
    Dynamic(DynamicSimulation<'w>),
}

impl<'w> Stepper<'w> {
    /// The stepper `world` needs: in time when it has `[dynamics]`.
    pub fn new(world: &'w World) -> Result<Self, RunError> {
        Ok(match world.dynamics {
            Some(_) => Stepper::Dynamic(DynamicSimulation::new(world)?),
            None => Stepper::Static(Simulation::new(world)?),
        })
    }

    /// The world being stepped.
    pub fn world(&self) -> &'w World {
        match self {
            Stepper::Static(s) => s.world,
            Stepper::Dynamic(d) => d.world(),
        }
    }

    /// The result and summary line of step (or frame) `step`, 0..=`world.steps`.
    pub fn step(&mut self, step: usize) -> Result<(StepResult, StepSummary), RunError> {
        match self {
            Stepper::Static(s) => s.step(step),
            Stepper::Dynamic(d) => d.step(step),
        }
    }

    /// Model sizes.
    pub fn sizes(&self) -> Vec<BodySize> {
        match self {
            Stepper::Static(s) => s.sizes(),
            Stepper::Dynamic(d) => d.sizes(),
        }
    }

    /// Phase times so far, and the contact query time, s.
    pub fn times(&self) -> (PhaseTimes, Real) {
        match self {
            Stepper::Static(s) => s.times(),
            Stepper::Dynamic(d) => (d.times(), d.query_seconds()),
        }
    }
}
