//! What a contact Newton works on, shared by the settle loop, the solvers and the report: the
//! problem held fixed during one contact set, and the scene-wide Newton limits.

use crate::contact::body_part::BodyPart;
use crate::contact::detect::Geometry;
use crate::contact::evaluate::{evaluate, Evaluation};
use crate::contact::{ActiveContact, ContactError, ContactSet, FrictionHistory};
use crate::linkage::dynamics::InertiaTerm;
use crate::linkage::{follower_forces, Body, Convergence};
use crate::Real;
use nalgebra::Vector3;
use std::borrow::Cow;
use std::collections::HashMap;

/// The stabilisation of a singular tangent, relative to its largest diagonal entry: small
/// enough that the stabilised matrix is still the tangent to 9 digits, large enough to factor.
pub const STABILISATION: Real = 1e-9;

/// The relative residual above which a stabilised correction that does not reduce it moves a
/// loaded rigid motion that no contact of the set holds (a body resting on a surface at a
/// depth of round-off carries its whole load so: 0.93 on a tilted floor): the contacts are
/// looked for again. Below, it is the round-off of an unloaded free motion, and Newton goes
/// on to its tolerance or its round-off floor.
pub const LOADED_RIGID_MOTION: Real = 1e-6;

/// See [`ContactSolver::force_floor`].
pub const FORCE_FLOOR: Real = 1e-10;

/// Converged states kept for the extrapolated start of an increment (three: up to a
/// quadratic through them, as a body's Newton).
pub(crate) const PATH_POINTS: usize = 3;

/// What a contact Newton iterates on: the bodies and their surfaces, the contact set held
/// fixed, and the step's loads and limits.
pub(crate) struct Problem<'a> {
    /// The bodies, in scene order.
    pub(crate) bodies: &'a [Body],
    /// Their surfaces and the obstacles.
    pub(crate) geometry: &'a Geometry,
    /// The contacts held fixed.
    pub(crate) set: &'a ContactSet,
    /// Applied force per body DOF of each body, N (nodal loads; a linear body's pressure is
    /// among them, on its undeformed faces).
    pub(crate) forces: &'a [Vec<Real>],
    /// The pseudo-time (step units) and steps at which the following pressures of bodies
    /// under large displacements are evaluated, on their deformed faces ([`Problem::applied`]).
    pub(crate) time: (Real, usize),
    /// Obstacle offsets along their travel, m.
    pub(crate) offsets: &'a [Vector3<Real>],
    /// The step (for messages).
    pub(crate) step: usize,
    /// Converged when the relative residual is at most this.
    pub(crate) tolerance: Real,
    /// Newton iterations allowed.
    pub(crate) max_iterations: usize,
    /// Largest nodal move of a stabilised iteration, m.
    pub(crate) move_cap: Real,
    /// The smallest force scale of a residual, N.
    pub(crate) force_floor: Real,
    /// The out-of-balance the coordinates' round-off leaves in the set's penalties, N (see
    /// [`round_off_residual`]): a Newton stalled below it has converged.
    pub(crate) round_off: Real,
    /// Friction and its history (`None`: every pair frictionless).
    pub(crate) friction: Option<&'a FrictionHistory>,
    /// Per body, the inertia term of a time step (`None`: a load step, no inertia).
    pub(crate) inertia: Option<&'a [InertiaTerm]>,
}

impl Problem<'_> {
    /// The applied force per body DOF of body `b` at its displacement `u` (per body DOF, m),
    /// N: its nodal loads plus its following pressures on the faces deformed by `u` at
    /// [`Problem::time`] (`F + F_p(u)`, as a body's own Newton,
    /// [`crate::linkage::follower_forces`]).
    pub(crate) fn applied(&self, b: usize, u: &[Real]) -> Cow<'_, [Real]> {
        let body = &self.bodies[b];
        if body.pressures.is_empty() {
            return Cow::Borrowed(&self.forces[b]);
        }
        let (t, steps) = self.time;
        let mut follower = vec![0.0; u.len()];
        follower_forces(body, u, t, steps, &mut follower);
        Cow::Owned(
            self.forces[b]
                .iter()
                .zip(&follower)
                .map(|(f, p)| f + p)
                .collect(),
        )
    }

    /// Every contact of the set evaluated at the bodies' current displacements.
    pub(crate) fn evaluate(
        &self,
        normals: &mut HashMap<ActiveContact, Vector3<Real>>,
        parts: &[BodyPart],
    ) -> Evaluation {
        evaluate(
            self.geometry,
            normals,
            self.bodies,
            parts,
            self.set,
            self.offsets,
            self.friction,
        )
    }

    /// Record the residual `rnorm` against `scale` (N) after `iterations` and decide: converged
    /// (`true`) when the relative residual is within the tolerance, stalled, or the last step
    /// (m) was at most 1e-12 of `size` (m: a correction that no longer moves anything, round-off
    /// over a force scale of round-off, has converged too); `Err` when it is not finite or the
    /// iterations are used up.
    pub(crate) fn converged(
        &self,
        monitor: &mut Convergence,
        rnorm: Real,
        scale: Real,
        iterations: usize,
        last_step: Real,
        size: Real,
    ) -> Result<bool, ContactError> {
        if interrupted(self.bodies) {
            return Err(ContactError::Interrupted { step: self.step });
        }
        monitor
            .record(Convergence::relative(rnorm, scale))
            .map_err(|_| ContactError::NotFinite { step: self.step })?;
        if monitor.within_tolerance()
            || monitor.stalled()
            || (scale > 0.0 && monitor.stalled_within(self.round_off / scale))
            || (iterations > 0 && last_step <= 1e-12 * size)
        {
            return Ok(true);
        }
        if iterations >= self.max_iterations {
            return Err(ContactError::NotConverged {
                step: self.step,
                depth: 0,
                cuts: 0,
                reason: format!("no convergence in {iterations} Newton iterations"),
                history: monitor.history.clone(),
            });
        }
        Ok(false)
    }

    /// The fraction of a stabilised correction to take when its largest nodal move (m) is
    /// beyond the move cap (`None`: a Newton step).
    pub(crate) fn capped(&self, largest: Real) -> Option<Real> {
        (largest > self.move_cap).then(|| self.move_cap / largest)
    }
}

/// Whether the run was asked to stop (the bodies' [`crate::linkage::NewtonSettings`] carry the
/// run's interrupt).
pub(crate) fn interrupted(bodies: &[Body]) -> bool {
    bodies.iter().any(|b| b.newton.interrupt.is_raised())
}

/// The Newton tolerance of a contact scene (the smallest of the bodies', at most 1e-10) and the
/// iterations allowed per contact set (the largest of the bodies').
pub(crate) fn newton_limits(bodies: &[Body]) -> (Real, usize) {
    let tolerance = bodies
        .iter()
        .map(|b| b.newton.tolerance)
        .fold(Real::INFINITY, Real::min)
        .min(1e-10);
    let max_iterations = bodies
        .iter()
        .map(|b| b.newton.max_iterations)
        .max()
        .unwrap_or(30);
    (tolerance, max_iterations)
}

/// The out-of-balance, N, that the round-off of coordinates as large as `extent` (m) leaves in
/// `contacts` active contacts of penalty up to `penalty` (N/m): a gap `n·(x − p)` is known to
/// a few units of round-off of `extent` (ε = 2.2e-16), each of its three components to
/// `4 ε extent`, and the penalty turns that into force. A steel block's 15 contacts at a
/// penalty of 3.1e10 N/m, 0.22 m from the origin, leave 2e-5 N (2.7e-7 of its 77 N weight):
/// Newton on a tilted floor stalls at 1.1e-8 of it, above 100 tolerances.
pub(crate) fn round_off_residual(extent: Real, penalty: Real, contacts: usize) -> Real {
    4.0 * Real::EPSILON * extent * penalty * (3.0 * contacts as Real).sqrt()
}
