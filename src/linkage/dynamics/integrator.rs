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
/// with `v_eval = velocity_coefficient · (y − u_n − velocity_predictor)` the velocity the damping
/// sees, and `f_int` the member forces at `y` or, for the energy–momentum method, their discrete
/// gradient between `u_n` and `u_{n+1}`.
#[derive(Clone, Debug, PartialEq)]
pub struct StepForm {
    /// `b`: the weight of the step's end in the configuration solved for (1: `u_{n+1}`
    /// itself, ½: the midpoint, `1 − α_f`: generalized-α).
    pub blend: Real,
    /// The inertia term in `y`.
    pub inertia: InertiaTerm,
    /// `inertia.predictor − u_n` per body DOF (m), formed from the velocities and
    /// accelerations without `u_n`: the solvers carry the increment `y − u_n`, so the inertia
    /// force `c M ((y − u_n) − (y* − u_n))` has no round-off of the size of `|u_n|` (which
    /// would drift the momenta of a body far from its start).
    pub predictor_increment: Vec<Real>,
    /// Factor of `y` in the velocity the damping sees, 1/s.
    pub velocity_coefficient: Real,
    /// The configuration at which that velocity vanishes, less `u_n`, per body DOF, m.
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
    /// Displacements, velocities and accelerations at the step's end, from `start` and the
    /// solved increment `du = u_{n+1} − u_n` (per body DOF, m). Velocities come from `du`
    /// itself, never from `u_{n+1} − u_n` re-formed from absolute displacements.
    fn finish(&self, start: &Motion, du: Vec<Real>, h: Real) -> Motion;
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

/// The increment of the Newmark predictor, `h v_n + h² (½ − β) a_n` (`ũ − u_n`, the
/// displacement at which `a_{n+1} = 0`, less `u_n`), per body DOF, m.
pub(crate) fn newmark_predictor_increment(start: &Motion, h: Real, beta: Real) -> Vec<Real> {
    start
        .v
        .iter()
        .zip(&start.a)
        .map(|(v, a)| h * v + h * h * (0.5 - beta) * a)
        .collect()
}

/// `u_n + du`, the displacements at the step's end, per body DOF, m.
pub(crate) fn advanced(start: &Motion, du: &[Real]) -> Vec<Real> {
    start.u.iter().zip(du).map(|(u, d)| u + d).collect()
}

/// The step's end of a Newmark (β, γ) family member from the increment `du`:
/// `a_{n+1} = (du − (ũ − u_n))/(β h²)` with `ũ` the Newmark predictor,
/// `v_{n+1} = v_n + h((1 − γ) a_n + γ a_{n+1})`.
pub(crate) fn newmark_finish(
    start: &Motion,
    du: Vec<Real>,
    h: Real,
    beta: Real,
    gamma: Real,
) -> Motion {
    let p = newmark_predictor_increment(start, h, beta);
    let a: Vec<Real> = du
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
    Motion {
        u: advanced(start, &du),
        v,
        a,
    }
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
    let p = newmark_predictor_increment(start, h, beta);
    // The configuration y where a_{n+1} = 0, less u_n: b (ũ − u_n).
    let y0: Vec<Real> = p.iter().map(|q| b * q).collect();
    let coefficient = (1.0 - alpha_m) / (b * beta * h * h);
    let predictor_increment = axpy(&y0, -alpha_m * b * beta * h * h / (1.0 - alpha_m), &start.a);
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
            predictor: advanced(start, &predictor_increment),
        },
        predictor_increment,
        velocity_coefficient,
        velocity_predictor,
        discrete_gradient: false,
    }
}
