//! What every time integrator gives: the form of one step (an [`InertiaTerm`] and the
//! velocity the damping sees, both affine in the solved configuration) and the update of the
//! motion from the solved displacements. See the module README for the formulas.

use crate::linkage::dynamics::InertiaTerm;
use crate::Real;

/// The motion of a body at one time: displacement (m), velocity (m/s) and acceleration (m/s²)
/// per body DOF.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Motion {
    /// Displacement per body DOF, m.
    pub u: Vec<Real>,
    /// Velocity per body DOF, m/s.
    pub v: Vec<Real>,
    /// Acceleration per body DOF, m/s² (only Newmark and generalized-α carry it from step to
    /// step; the others report `(v_{n+1} − v_n)/h`).
    pub a: Vec<Real>,
}

/// One time step in the form the solvers take: find the configuration
/// `y = b u_{n+1} + (1 − b) u_n` (per body DOF, m) where
///
/// `f_int(y) + C v_eval(y) + inertia.coefficient · M (y − inertia.predictor) = F(t_n + b h)`
///
/// with `v_eval = velocity_coefficient · (y − velocity_predictor)` the velocity the damping
/// sees, and `f_int` the member forces at `y` or, for the energy–momentum method, their discrete
/// gradient between `u_n` and `u_{n+1}`.
#[derive(Clone, Debug, PartialEq)]
pub struct StepForm {
    /// `b`: the weight of the step's end in the configuration solved for (1: `u_{n+1}`
    /// itself, ½: the midpoint, `1 − α_f`: generalized-α).
    pub blend: Real,
    /// The inertia term in `y`.
    pub inertia: InertiaTerm,
    /// Factor of `y` in the velocity the damping sees, 1/s.
    pub velocity_coefficient: Real,
    /// The configuration at which that velocity vanishes, per body DOF, m.
    pub velocity_predictor: Vec<Real>,
    /// Whether member forces are the discrete gradient of their energy between the step's two
    /// ends (energy–momentum) rather than the forces at `y`.
    pub discrete_gradient: bool,
}

/// A time integrator: one per file of this module, as OpenSees keeps one class per
/// integrator.
pub trait Integrator {
    /// The scene's name of the integrator (`integrator = "..."`).
    fn name(&self) -> &'static str;
    /// The form of the step of `h` (s) from `start`, with lumped `mass` per body DOF (kg).
    fn form(&self, start: &Motion, mass: &[Real], h: Real) -> StepForm;
    /// Velocities and accelerations at the step's end, from `start` and the solved
    /// displacements `u` at its end.
    fn finish(&self, start: &Motion, u: Vec<Real>, h: Real) -> Motion;
    /// Whether the acceleration carried from step to step must start balanced,
    /// `a₀ = M⁻¹(F(0) − f_int(u₀) − C v₀)` (Newmark and generalized-α).
    fn needs_initial_acceleration(&self) -> bool {
        false
    }
}

/// `a + s · b`, element by element.
pub(crate) fn axpy(a: &[Real], s: Real, b: &[Real]) -> Vec<Real> {
    a.iter().zip(b).map(|(x, y)| x + s * y).collect()
}

/// The Newmark predictor `u_n + h v_n + h² (½ − β) a_n` (the displacement at which
/// `a_{n+1} = 0`), per body DOF, m.
pub(crate) fn newmark_predictor(start: &Motion, h: Real, beta: Real) -> Vec<Real> {
    let with_v = axpy(&start.u, h, &start.v);
    axpy(&with_v, h * h * (0.5 - beta), &start.a)
}

/// The step's end of a Newmark (β, γ) family member: `a_{n+1} = (u_{n+1} − ũ)/(β h²)` with
/// `ũ` the [`newmark_predictor`], `v_{n+1} = v_n + h((1 − γ) a_n + γ a_{n+1})`.
pub(crate) fn newmark_finish(
    start: &Motion,
    u: Vec<Real>,
    h: Real,
    beta: Real,
    gamma: Real,
) -> Motion {
    let p = newmark_predictor(start, h, beta);
    let a: Vec<Real> = u
        .iter()
        .zip(&p)
        .map(|(x, q)| (x - q) / (beta * h * h))
        .collect();
    let v = start
        .v
        .iter()
        .zip(&start.a)
        .zip(&a)
        .map(|((v, a0), a1)| v + h * ((1.0 - gamma) * a0 + gamma * a1))
        .collect();
    Motion { u, v, a }
}

/// The form of a step of the generalized-α family (Newmark is `α_m = α_f = 0`): forces at
/// `y = (1 − α_f) u_{n+1} + α_f u_n`, inertia `M ((1 − α_m) a_{n+1} + α_m a_n)`, damping
/// velocity `(1 − α_f) v_{n+1} + α_f v_n` (see the README for the algebra).
pub(crate) fn alpha_form(
    start: &Motion,
    mass: &[Real],
    h: Real,
    (beta, gamma): (Real, Real),
    (alpha_m, alpha_f): (Real, Real),
) -> StepForm {
    let b = 1.0 - alpha_f;
    let p = newmark_predictor(start, h, beta);
    // The configuration y where a_{n+1} = 0: (1 − b) u_n + b ũ.
    let y0: Vec<Real> = start
        .u
        .iter()
        .zip(&p)
        .map(|(un, q)| (1.0 - b) * un + b * q)
        .collect();
    let coefficient = (1.0 - alpha_m) / (b * beta * h * h);
    let predictor = axpy(&y0, -alpha_m * b * beta * h * h / (1.0 - alpha_m), &start.a);
    let velocity_coefficient = gamma / (beta * h);
    let velocity_predictor = y0
        .iter()
        .zip(&start.v)
        .zip(&start.a)
        .map(|((y, v), a)| y - (beta * h / gamma) * (v + b * h * (1.0 - gamma) * a))
        .collect();
    StepForm {
        blend: b,
        inertia: InertiaTerm {
            mass: mass.to_vec(),
            coefficient,
            predictor,
        },
        velocity_coefficient,
        velocity_predictor,
        discrete_gradient: false,
    }
}
