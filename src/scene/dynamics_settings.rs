//! `[dynamics]` and the bodies' initial velocities, checked: what a run in time needs.

use crate::linkage::dynamics::{
    centre_of_mass, BackwardEuler, EnergyMomentum, GeneralizedAlpha, Integrator, Newmark,
    RayleighDamping,
};
use crate::linkage::Body;
use crate::scene::selector::{select_nodes, vector};
use crate::scene::spec::{BodySpec, DynamicsSpec};
use crate::Real;
use nalgebra::Vector3;

/// Which integrator a dynamic scene uses, with its parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IntegratorChoice {
    /// Energy–momentum (default).
    EnergyMomentum,
    /// Newmark (β, γ).
    Newmark(Newmark),
    /// Generalized-α (ρ∞).
    GeneralizedAlpha(GeneralizedAlpha),
    /// Backward Euler.
    BackwardEuler,
}

impl IntegratorChoice {
    /// The integrator itself.
    pub fn integrator(&self) -> Box<dyn Integrator + Send + Sync> {
        match *self {
            IntegratorChoice::EnergyMomentum => Box::new(EnergyMomentum),
            IntegratorChoice::Newmark(n) => Box::new(n),
            IntegratorChoice::GeneralizedAlpha(g) => Box::new(g),
            IntegratorChoice::BackwardEuler => Box::new(BackwardEuler),
        }
    }
}

/// A dynamic scene's settings (`[dynamics]`), and per body what it starts moving with.
#[derive(Clone, Debug, PartialEq)]
pub struct DynamicsSettings {
    /// Simulated time, s.
    pub duration: Real,
    /// The largest time step, s.
    pub time_step: Real,
    /// Stored states after t = 0, evenly spaced over `duration` (frame k at `k·duration/frames`).
    pub frames: usize,
    /// The integrator.
    pub integrator: IntegratorChoice,
    /// Rayleigh damping of every body.
    pub damping: RayleighDamping,
    /// Per body, in scene order: the lumped mass (kg) and initial velocity (m/s) per body DOF.
    pub bodies: Vec<BodyStart>,
}

/// What one body of a dynamic scene starts with.
#[derive(Clone, Debug, PartialEq)]
pub struct BodyStart {
    /// Lumped mass per body DOF, kg.
    pub mass: Vec<Real>,
    /// Initial velocity per body DOF, m/s.
    pub velocity: Vec<Real>,
}

impl DynamicsSettings {
    /// Time steps of full size between two frames: `ceil(duration / frames / time_step)`.
    pub fn steps_per_frame(&self) -> usize {
        let interval = self.duration / self.frames as Real;
        ((interval / self.time_step) * (1.0 - 1e-12))
            .ceil()
            .max(1.0) as usize
    }

    /// The full time step, s: the frame interval divided evenly (≤ `time_step`).
    pub fn step_size(&self) -> Real {
        self.duration / self.frames as Real / self.steps_per_frame() as Real
    }
}

/// The number of full time steps of `duration` at `time_step`, rounded up.
fn total_steps(duration: Real, time_step: Real) -> Real {
    ((duration / time_step) * (1.0 - 1e-12)).ceil().max(1.0)
}

/// `[dynamics]` checked (without the bodies' part): every message names its key in backticks
/// so the scene builder finds its line.
pub fn dynamics_from(spec: &DynamicsSpec) -> Result<DynamicsSettings, String> {
    for (key, v) in [("duration", spec.duration), ("time_step", spec.time_step)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(format!(
                "[dynamics] `{key}` = {v}: give a finite time of more than 0 s"
            ));
        }
    }
    let steps = total_steps(spec.duration, spec.time_step);
    if steps > 1e9 {
        return Err(format!(
            "[dynamics] `time_step` = {} s over `duration` = {} s makes {steps:e} steps: give a longer time step (at most 1e9 steps)",
            spec.time_step, spec.duration
        ));
    }
    let frames = match spec.frames {
        Some(0) => return Err("[dynamics] `frames` = 0: give 1 or more stored states".to_string()),
        Some(f) if f as Real > steps => {
            return Err(format!(
                "[dynamics] `frames` = {f} is more than the {steps} time steps of `duration` / `time_step`: give at most {steps} frames, or a shorter time_step"
            ))
        }
        Some(f) => f,
        None => steps as usize,
    };
    let name = spec.integrator.as_deref().unwrap_or("energy_momentum");
    let only = |key: &str, given: bool, owner: &str| -> Result<(), String> {
        if given && name != owner {
            Err(format!(
                "[dynamics] `{key}` is a parameter of integrator = \"{owner}\", not of \"{name}\": remove it or choose \"{owner}\""
            ))
        } else {
            Ok(())
        }
    };
    only("beta", spec.beta.is_some(), "newmark")?;
    only("gamma", spec.gamma.is_some(), "newmark")?;
    only("rho_inf", spec.rho_inf.is_some(), "generalized_alpha")?;
    let integrator = match name {
        "energy_momentum" => IntegratorChoice::EnergyMomentum,
        "backward_euler" => IntegratorChoice::BackwardEuler,
        "newmark" => {
            let beta = spec.beta.unwrap_or(0.25);
            let gamma = spec.gamma.unwrap_or(0.5);
            if !(beta.is_finite() && beta > 0.0 && beta <= 1.0) {
                return Err(format!(
                    "[dynamics] `beta` = {beta}: give Newmark's β in (0, 1] (¼: average acceleration; the explicit β = 0 is not available)"
                ));
            }
            if !(gamma.is_finite() && (0.5..=1.5).contains(&gamma)) {
                return Err(format!(
                    "[dynamics] `gamma` = {gamma}: give Newmark's γ in [½, 1.5] (below ½ the method amplifies every mode)"
                ));
            }
            IntegratorChoice::Newmark(Newmark { beta, gamma })
        }
        "generalized_alpha" => {
            let rho_inf = spec.rho_inf.unwrap_or(0.8);
            if !(rho_inf.is_finite() && (0.0..=1.0).contains(&rho_inf)) {
                return Err(format!(
                    "[dynamics] `rho_inf` = {rho_inf}: give the spectral radius ρ∞ in [0, 1] (1: no numerical damping, 0: the most)"
                ));
            }
            IntegratorChoice::GeneralizedAlpha(GeneralizedAlpha { rho_inf })
        }
        other => {
            return Err(format!(
                "[dynamics] `integrator` = {other:?}: use \"energy_momentum\", \"newmark\", \"generalized_alpha\" or \"backward_euler\""
            ))
        }
    };
    let mut damping = RayleighDamping::default();
    if let Some(d) = &spec.damping {
        for (key, v, out) in [
            ("mass", d.mass, &mut damping.mass),
            ("stiffness", d.stiffness, &mut damping.stiffness),
        ] {
            if let Some(v) = v {
                if !(v.is_finite() && v >= 0.0) {
                    return Err(format!(
                        "[dynamics] `damping` {key} = {v}: give a finite Rayleigh coefficient of 0 or more (mass: 1/s, stiffness: s)"
                    ));
                }
                *out = v;
            }
        }
    }
    Ok(DynamicsSettings {
        duration: spec.duration,
        time_step: spec.time_step,
        frames,
        integrator,
        damping,
        bodies: Vec::new(),
    })
}

/// Where a velocity problem is: the body's own `velocity`/`angular_velocity` keys, or its
/// `k`-th `[[bodies.velocities]]` entry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VelocitySource {
    /// `velocity` or `angular_velocity` of the `[[bodies]]` entry.
    Body,
    /// The 0-based `[[bodies.velocities]]` entry.
    Entry(usize),
}

/// The initial velocity per body DOF (m/s) of `body` from `spec`'s `velocity`,
/// `angular_velocity` (about the centre of mass of the lumped `mass`) and then its
/// `[[bodies.velocities]]` in order. A nonzero component in a direction a support holds is an
/// error (a zero one is fine).
pub fn initial_velocity(
    spec: &BodySpec,
    body: &Body,
    mass: &[Real],
) -> Result<Vec<Real>, (VelocitySource, String)> {
    let d = body.dimension.dofs_per_node();
    let mut v = vec![0.0; body.dof_count()];
    let at_body = |e: String| (VelocitySource::Body, e);
    let translation = match &spec.velocity {
        Some(w) => vector(w, body.dimension, "velocity").map_err(at_body)?,
        None => Vector3::zeros(),
    };
    let omega = match &spec.angular_velocity {
        None => Vector3::zeros(),
        Some(w) if d == 2 => match w.as_slice() {
            [z] if z.is_finite() => Vector3::new(0.0, 0.0, *z),
            _ => {
                return Err(at_body(format!(
                    "`angular_velocity` = {w:?}: a 2D body turns about z: give one finite number (rad/s)"
                )))
            }
        },
        Some(w) => vector(w, body.dimension, "angular_velocity").map_err(at_body)?,
    };
    let centre = centre_of_mass(body, mass);
    for (n, p) in body.nodes.iter().enumerate() {
        let w = translation + omega.cross(&(p - centre));
        for k in 0..d {
            v[n * d + k] = w[k];
        }
    }
    let mut source = vec![VelocitySource::Body; body.nodes.len()];
    for (e, entry) in spec.velocities.iter().enumerate() {
        let entry = entry.get_ref();
        let at = |m: String| (VelocitySource::Entry(e), m);
        let nodes = select_nodes(&entry.selector(), body).map_err(at)?;
        let w = vector(&entry.velocity, body.dimension, "velocity").map_err(at)?;
        for n in nodes {
            v[n * d..n * d + d].copy_from_slice(&w.as_slice()[..d]);
            source[n] = VelocitySource::Entry(e);
        }
    }
    for s in &body.supports {
        for k in (0..d).filter(|&k| s.fixed[k]) {
            let x = v[s.node * d + k];
            if x != 0.0 {
                let key = match source[s.node] {
                    VelocitySource::Body if spec.angular_velocity.is_some() => "angular_velocity",
                    _ => "velocity",
                };
                return Err((
                    source[s.node],
                    format!(
                        "`{key}` gives node {} the velocity {x} m/s in {}, which a support holds: a held direction cannot move; remove the node from the support or give it no velocity there",
                        s.node + 1,
                        ["x", "y", "z"][k]
                    ),
                ));
            }
        }
    }
    Ok(v)
}
