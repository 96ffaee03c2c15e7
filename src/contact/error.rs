//! Why a scene with contact could not be solved.

use crate::contact::SurfaceProblem;
use crate::linalg::CholeskyError;
use crate::linkage::SolveError;
use crate::Real;

/// Why a contact step failed. Node numbers are 1-based.
#[derive(Debug, thiserror::Error)]
pub enum ContactError {
    /// A body could not be prepared (validation, size).
    #[error(transparent)]
    Body(#[from] SolveError),
    /// The run was asked to stop ([`crate::linkage::Interrupt`]) while `step` was solved.
    #[error("step {step}: interrupted")]
    Interrupted {
        /// The step.
        step: usize,
    },
    /// A body not held by its supports found no contacts that hold it.
    #[error("step {step}: body '{body}' is not held by its supports and found no contact that holds it in {iterations} contact iterations ({contacts} contacts at the end): a load pushes it away from every surface, or the surface is far; support it, start it touching the surface, or raise [contact] max_iterations")]
    Unsupported {
        /// The step.
        step: usize,
        /// Body name.
        body: String,
        /// Contact iterations done.
        iterations: usize,
        /// Active contacts at the end.
        contacts: usize,
    },
    /// A body touching surfaces that, with its supports, leave some of its rigid motions free
    /// (a frictionless floor under a body without supports): named, with the part of its
    /// loads along them when there is one (then it slides).
    #[error("step {step}: body '{body}' {}", free_text(motions, push))]
    Free {
        /// The step.
        step: usize,
        /// Body name.
        body: String,
        /// The free motions in words ("slide along x and z and turn about y").
        motions: String,
        /// The direction ("along x") and size (N) of the part of its loads along the free
        /// slides, when there is one.
        push: Option<(String, Real)>,
    },
    /// A body is a mechanism (nodes move without stretching a member) and no contact held it.
    #[error(
        "step {step}: {mechanism}; no contact held it either in the contact iterations allowed"
    )]
    Mechanism {
        /// The step.
        step: usize,
        /// The moving nodes.
        mechanism: Box<crate::linkage::Mechanism>,
    },
    /// A step did not converge even with its increment halved `depth` (= the smallest
    /// `[bodies.newton] max_cuts`) times.
    #[error("step {step}: equilibrium with contact did not converge, even with its increment cut to 1/{} of the step ({depth} halvings deep, the most [bodies.newton] max_cuts allows; {cuts} halvings in this step in all, as the increment grows again after two successes): {reason}; relative residuals of the last attempt: [{}]. Use more steps (smaller increments), raise [bodies.newton] max_cuts or max_iterations, or a smaller [contact] penalty", 1u64 << (*.depth).min(63), history.iter().map(|r| format!("{r:.1e}")).collect::<Vec<_>>().join(", "))]
    NotConverged {
        /// The step.
        step: usize,
        /// Halvings of the increment in force when it failed.
        depth: usize,
        /// Halvings in this step in all.
        cuts: usize,
        /// Why the last attempt failed.
        reason: String,
        /// Relative residual after each Newton iteration of the last attempt.
        history: Vec<Real>,
    },
    /// The sparse factorization failed for another reason.
    #[error("the sparse factorization of the bodies in contact failed: {0}")]
    Factorization(CholeskyError),
    /// An arc-length path in a scene with contact that is not one body against fixed
    /// frictionless half-spaces (which the body's own Newton takes as stops).
    #[error("body '{body}': [bodies.path] method = \"arc_length\" with contact (obstacles or a [contact] table) is followed only for one body against fixed, frictionless half_space obstacles; here {reason}. To run it: {remedy}")]
    ArcLength {
        /// Body name.
        body: String,
        /// Why this scene is not one the arc length can follow.
        reason: String,
        /// What to change.
        remedy: String,
    },
    /// A 3D body's patches cannot be a contact surface.
    #[error("body '{body}': its patches cannot be a contact surface: {}", match problem {
        SurfaceProblem::NotClosed([a, b]) => format!("the edge from node {a} to node {b} belongs to one patch only (the surface is open); contact needs a closed surface: add the missing patches, or remove `patches`"),
        SurfaceProblem::Inconsistent([a, b]) => format!("two patches run along the edge from node {a} to node {b} the same way, so they face opposite sides: list every patch counter-clockwise seen from outside"),
    })]
    Surface {
        /// Body name.
        body: String,
        /// What is wrong.
        problem: SurfaceProblem,
    },
    /// An obstacle could not be built.
    #[error("an obstacle could not be built: {0}")]
    Obstacle(String),
    /// The bodies of a contact scene are not all 2D or all 3D.
    #[error("body '{first}' is {first_dimension}D and body '{other}' is {other_dimension}D: the bodies of a scene with contact must all be 2D or all 3D (a 2D body lies in z = 0 and cannot touch a 3D one): give every body the same dimension, or put them in separate scenes")]
    MixedDimensions {
        /// The first body.
        first: String,
        /// Its dimension (2 or 3).
        first_dimension: usize,
        /// The first body of another dimension.
        other: String,
        /// Its dimension.
        other_dimension: usize,
    },
    /// A node lies inside an obstacle or another body at step 0, deeper than the tolerance.
    #[error(transparent)]
    StartsInside(Box<crate::contact::StartOverlap>),
    /// A body pushed along its contacts by more than friction can hold: no static equilibrium.
    #[error("step {step}: body '{body}' slides: its loads push it along its contacts with {load:.6e} N, more than the {capacity:.6e} N (μ times the normal force) friction can hold, so it has no static equilibrium. Lower the tangential load, raise [contact] friction, or hold the body with a support")]
    Sliding {
        /// The step.
        step: usize,
        /// Body name.
        body: String,
        /// The tangential part of the body's applied loads at the step, N.
        load: Real,
        /// The largest tangential force its contacts can hold, N: μ times the part of its
        /// loads pressing it on them.
        capacity: Real,
    },
    /// A body pushed along its contacts by exactly what friction can hold (to 1e-6): at the
    /// edge of sliding, where no state sticks firmly.
    #[error("step {step}: body '{body}' is at the edge of sliding: its loads push it along its contacts with {load:.6e} N, the {capacity:.6e} N (μ times the normal force) friction can hold at most, so the answer is friction at its limit μ N with the slip left undetermined, and the solver finds no state that settles. Lower the tangential load a little (it then sticks) or raise it (it slides), raise [contact] friction, or hold the body with a support")]
    EdgeOfSliding {
        /// The step.
        step: usize,
        /// Body name.
        body: String,
        /// The tangential part of the body's applied loads at the step, N.
        load: Real,
        /// The largest tangential force its contacts can hold, N.
        capacity: Real,
    },
    /// A time step was given another number of inertia terms than there are bodies.
    #[error("a time step was given {terms} inertia terms for {bodies} bodies: give one per body, in scene order")]
    InertiaCount {
        /// Inertia terms given.
        terms: usize,
        /// Bodies.
        bodies: usize,
    },
    /// A body's inertia term does not fit it.
    #[error("body '{body}': its inertia term for the time step is unusable ({problem}): give one mass (kg, at least 0) and one predictor value (m) per body DOF, all finite, and a finite coefficient of at least 0 (1/s²)")]
    Inertia {
        /// Body name.
        body: String,
        /// What is wrong, with the DOF and node (1-based) where one is.
        problem: String,
    },
    /// A time step's position along the loads' and obstacles' schedules is not finite.
    #[error("a time step was asked for at pseudo-time {at}: it must be finite (step units of the schedules)")]
    TimeStepPosition {
        /// The pseudo-time given.
        at: Real,
    },
    /// A time step left a node deeper inside what it touches than allowed: the step was too
    /// long for the contact set (the time driver halves it).
    #[error("the time step left a node {depth:.3e} m deep, more than the {limit:.3e} m allowed: the contact set changed too much within the step")]
    TimeStepTooDeep {
        /// The largest penetration at the step's solution, m.
        depth: Real,
        /// The most allowed, m.
        limit: Real,
    },
    /// The result is not finite.
    #[error("step {step}: the solution with contact is not finite: check the penalty ([contact] penalty) and the loads")]
    NotFinite {
        /// The step.
        step: usize,
    },
}

/// The text of [`ContactError::Free`] after the body's name.
fn free_text(motions: &str, push: &Option<(String, Real)>) -> String {
    match push {
        Some((direction, force)) => format!(
            "slides {direction}: its loads push it {direction} with {force:.6e} N, along the surface it rests on, and nothing resists that motion (the contact has no friction), so it has no static equilibrium (free: {motions}). Add friction or a support that holds it"
        ),
        None => format!(
            "can {motions}: nothing holds it there (its supports and contacts leave these rigid motions free, so its equilibrium is not determined); add friction or a support"
        ),
    }
}
