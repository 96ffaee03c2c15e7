//! How a body relates member forces to node motion, and how its nonlinear equilibrium is found.

use crate::linkage::Interrupt;
use crate::Real;

/// The kinematics of a body's members.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Kinematics {
    /// The paper's small-displacement model: a member's stretch is the displacement difference
    /// projected on its undeformed axis, and its force acts along that axis.
    #[default]
    Linear,
    /// Geometrically exact members: the engineering strain `ε = (l − L)/L` of the current
    /// length `l` gives the axial force `N = E A ε`, which acts along the current axis.
    /// Rigid motions of any size cause no force.
    Large,
}

/// How the load path of a nonlinearly solved body is followed.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum PathMethod {
    /// Load (and prescribed displacement) control: the schedules give every step's loads and
    /// support displacements; Newton finds the equilibrium there.
    #[default]
    Schedules,
    /// Crisfield's cylindrical arc-length method: the loads at full value are a reference
    /// pattern scaled by an unknown load factor λ, and each step advances the free
    /// displacements by `length` (m, Euclidean norm over the free DOFs). Follows limit points
    /// and snap-through.
    ArcLength {
        /// Arc length of one step, m.
        length: Real,
    },
}

/// Settings of the Newton–Raphson solve of a nonlinear body (large kinematics, or members
/// that act in tension or compression only).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonSettings {
    /// Converged when the out-of-balance force at the free DOFs is at most this fraction of
    /// the larger of the applied force and reaction norms.
    pub tolerance: Real,
    /// ... and the last displacement correction is at most this fraction of the displacement
    /// norm.
    pub displacement_tolerance: Real,
    /// Newton iterations allowed per load increment before the increment is halved.
    pub max_iterations: usize,
    /// The smallest increment is `1/2^max_cuts` of a step (of the arc length): when it fails,
    /// the run stops with an error.
    pub max_cuts: usize,
    /// How the load path is followed.
    pub path: PathMethod,
    /// Whether the tangent includes the load stiffness of pressures that follow the
    /// deformation (default true; false only to compare convergence).
    pub load_stiffness: bool,
    /// Asks the solves to stop between iterations (the run was interrupted): not part of
    /// the physics, never read from a scene.
    pub interrupt: Interrupt,
}

impl Default for NewtonSettings {
    fn default() -> Self {
        NewtonSettings {
            tolerance: 1e-8,
            displacement_tolerance: 1e-6,
            max_iterations: 30,
            max_cuts: 10,
            path: PathMethod::Schedules,
            load_stiffness: true,
            interrupt: Interrupt::default(),
        }
    }
}
