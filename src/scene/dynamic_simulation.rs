//! A world solved in time: the clock (time steps, halvings, stored frames), one function that
//! solves one time step for all bodies, and each frame's result, energies and momenta.

use crate::linkage::dynamics::{
    angular_momentum, kinetic_energy, momentum, strain_energy, time_factor, BodyMotion, Integrator,
    TimeStepFailure, TimeStepReport,
};
use crate::linkage::fracture::breaks_members;
use crate::linkage::{Body, PhaseTimes, SolveError};
use crate::scene::dynamic_contact::{ContactTrialSteps, DynamicContact};
use crate::scene::dynamic_fracture::BreakingBodies;
use crate::scene::dynamics_settings::DynamicsSettings;
use crate::scene::results::{
    BodyFracture, BodyMomentum, BodyResult, BodySize, BreakRecord, StepEnergy, StepResult,
    StepSummary,
};
use crate::scene::run_error::RunError;
use crate::scene::simulation::empty_summary;
use crate::scene::World;
use crate::Real;

/// Halvings of the time step allowed: down to `time_step / 1024`.
pub const MAX_TIME_STEP_HALVINGS: usize = 10;

/// Ticks of the smallest step in a full step: steps are whole numbers of ticks, so they land
/// exactly on the frame times.
const TICKS: usize = 1 << MAX_TIME_STEP_HALVINGS;

/// Solve one time step from `t0` of length `h` (s) for every body, each with its own
/// [`BodyMotion`] (the inertia term of its integrator): all bodies advance, or, when one fails,
/// none does (every motion is restored) and the failing body and why are returned. This is the
/// one place a step of all bodies is solved: a scene with contact will route it to the contact
/// solver, which takes the same inertia terms.
pub fn solve_time_step(
    motions: &mut [BodyMotion],
    bodies: &[Body],
    integrator: &dyn Integrator,
    (t0, h, duration): (Real, Real, Real),
) -> Result<Vec<TimeStepReport>, (usize, TimeStepFailure)> {
    let saved: Vec<_> = motions.iter().map(|m| m.motion.clone()).collect();
    let mut reports = Vec::with_capacity(motions.len());
    for (k, (m, body)) in motions.iter_mut().zip(bodies).enumerate() {
        match m.step(body, integrator, t0, h, duration) {
            Ok(r) => reports.push(r),
            Err(failure) => {
                for (m, s) in motions.iter_mut().zip(saved) {
                    m.motion = s;
                }
                return Err((k, failure));
            }
        }
    }
    Ok(reports)
}

/// A world stepping through time, frame by frame.
pub struct DynamicSimulation<'w> {
    world: &'w World,
    settings: &'w DynamicsSettings,
    integrator: Box<dyn Integrator + Send + Sync>,
    /// Per body its motion, in scene order.
    pub motions: Vec<BodyMotion>,
    /// The time reached, s.
    time: Real,
    /// The last frame reached.
    frame: usize,
    /// Halvings of the full step in force, and successes in a row since the last change.
    depth: usize,
    streak: usize,
    /// Work of the applied forces and supports, and damping's dissipation, since t = 0, J.
    external_work: Real,
    dissipated: Real,
    /// The bodies' breaking members, when some break (their own copies of the bodies).
    fracture: Option<BreakingBodies>,
    /// The contact solver, in a scene with contact (obstacles or `[contact]`).
    contact: Option<DynamicContact>,
}

impl<'w> DynamicSimulation<'w> {
    /// The world being stepped.
    pub fn world(&self) -> &'w World {
        self.world
    }

    /// Prepare every body of the dynamic `world` (its `dynamics` must be set): patterns
    /// analyzed, initial velocities in place, and for Newmark and generalized-α the balanced
    /// initial acceleration. No supports are needed.
    pub fn new(world: &'w World) -> Result<Self, RunError> {
        let Some(settings) = world.dynamics.as_ref() else {
            return Err(RunError::Solve {
                scene: world.source.clone(),
                source: SolveError::Factorization {
                    body: String::new(),
                    message: "the scene has no [dynamics] table".to_string(),
                },
            });
        };
        let integrator = settings.integrator.integrator();
        // A large body's following pressure is not in the time step's residual: refused,
        // never left out in silence.
        if let Some(body) = world.bodies.iter().find(|b| !b.pressures.is_empty()) {
            return Err(RunError::Solve {
                scene: world.source.clone(),
                source: SolveError::FollowingPressureInTime {
                    body: body.name.clone(),
                },
            });
        }
        let fracture = BreakingBodies::new(&world.bodies).map_err(|source| RunError::Solve {
            scene: world.source.clone(),
            source,
        })?;
        let mut motions = Vec::with_capacity(world.bodies.len());
        for (body, start) in world.bodies.iter().zip(&settings.bodies) {
            let mut m = BodyMotion::new(
                body,
                start.mass.clone(),
                start.velocity.clone(),
                settings.damping,
            )
            .map_err(|source| RunError::Solve {
                scene: world.source.clone(),
                source,
            })?;
            if integrator.needs_initial_acceleration() {
                m.balance_initial_acceleration(body, settings.duration);
            }
            motions.push(m);
        }
        let contact = if world.has_contact() {
            Some(DynamicContact::new(world, settings.duration)?)
        } else {
            None
        };
        Ok(DynamicSimulation {
            contact,
            world,
            settings,
            integrator,
            motions,
            time: 0.0,
            frame: 0,
            depth: 0,
            streak: 0,
            external_work: 0.0,
            dissipated: 0.0,
            fracture,
        })
    }

    /// The time of frame `k`, s: `k · duration / frames` (the last exactly `duration`).
    pub fn frame_time(&self, k: usize) -> Real {
        if k >= self.settings.frames {
            self.settings.duration
        } else {
            self.settings.duration * k as Real / self.settings.frames as Real
        }
    }

    /// The result and summary line of `frame` (0..=frames), solving the time steps from the
    /// last frame reached (frames come in order).
    pub fn step(&mut self, frame: usize) -> Result<(StepResult, StepSummary), RunError> {
        let world = self.world;
        let duration = self.settings.duration;
        let mut summary = empty_summary(frame, 0.0);
        let mut time_steps = 0;
        let mut smallest = Real::INFINITY;
        let mut last_history: Vec<Real> = Vec::new();
        let mut most = 0;
        if frame > self.frame {
            let full = self.settings.step_size();
            let total = (frame - self.frame) * self.settings.steps_per_frame() * TICKS;
            let start = self.time;
            let mut pos = 0;
            let mut iterations = vec![0; self.motions.len()];
            while pos < total {
                let ticks = (TICKS >> self.depth).min(total - pos);
                let h = full * (ticks as Real / TICKS as Real);
                let t0 = start + full * (pos as Real / TICKS as Real);
                let integrator = self.integrator.as_ref();
                let may_cut = self.depth < MAX_TIME_STEP_HALVINGS;
                let solved = match (self.contact.as_mut(), self.fracture.as_mut()) {
                    (Some(c), Some(f)) => f.solve_trial_step(
                        &mut self.motions,
                        &mut ContactTrialSteps {
                            contact: c,
                            integrator,
                            may_cut,
                            summary: &mut summary,
                        },
                        (t0, h, duration),
                        integrator.needs_initial_acceleration(),
                    ),
                    (Some(c), None) => c
                        .solve(
                            &mut self.motions,
                            &world.bodies,
                            integrator,
                            (t0, h, may_cut),
                        )
                        .map(|s| s.record(&mut summary)),
                    (None, Some(f)) => f.solve_step(
                        &mut self.motions,
                        &mut |m, b, t, h| solve_time_step(m, b, integrator, (t, h, duration)),
                        (t0, h, duration),
                        integrator.needs_initial_acceleration(),
                    ),
                    (None, None) => solve_time_step(
                        &mut self.motions,
                        &world.bodies,
                        integrator,
                        (t0, h, duration),
                    ),
                };
                match solved {
                    Ok(reports) => {
                        pos += ticks;
                        time_steps += 1;
                        smallest = smallest.min(h);
                        for (k, r) in reports.iter().enumerate() {
                            iterations[k] += r.iterations;
                            self.external_work += r.external_work;
                            self.dissipated += r.dissipated;
                            summary.residual = summary
                                .residual
                                .max(r.residual_history.last().copied().unwrap_or(0.0));
                            if r.iterations >= most {
                                most = r.iterations;
                                last_history = r.residual_history.clone();
                            }
                        }
                        self.streak += 1;
                        if self.streak >= 2 && self.depth > 0 {
                            self.depth -= 1;
                            self.streak = 0;
                        }
                    }
                    Err((k, failure)) => {
                        self.streak = 0;
                        if self.depth >= MAX_TIME_STEP_HALVINGS {
                            return Err(RunError::Solve {
                                scene: world.source.clone(),
                                source: SolveError::TimeStepNotConverged {
                                    body: world.bodies[k].name.clone(),
                                    time: t0,
                                    step: h,
                                    halvings: self.depth,
                                    reason: failure.reason,
                                    history: failure.history.into_boxed_slice(),
                                },
                            });
                        }
                        self.depth += 1;
                        summary.cuts += 1;
                    }
                }
            }
            summary.iterations = iterations.into_iter().max().unwrap_or(0);
            self.time = self.frame_time(frame);
            self.frame = frame;
        }
        summary.residuals = last_history;
        let t = self.time;
        summary.load_factor = time_load_factor(world, t, duration);
        let mut result = StepResult {
            step: frame,
            load_factor: summary.load_factor,
            time: Some(t),
            bodies: Vec::with_capacity(world.bodies.len()),
        };
        let mut energy = StepEnergy {
            time: t,
            external_work: self.external_work,
            dissipated: self.dissipated,
            time_steps,
            smallest_time_step: if time_steps > 0 { smallest } else { 0.0 },
            ..Default::default()
        };
        let breaks = self.fracture.as_mut().map(|f| f.take_breaks());
        let bodies = self
            .fracture
            .as_ref()
            .map_or(&world.bodies[..], |f| &f.bodies[..]);
        for (k, (body, m)) in bodies.iter().zip(&self.motions).enumerate() {
            let state = m.state(body, t, duration);
            summary.overloaded += state.overloaded.len();
            summary.max_displacement = state
                .displacements
                .iter()
                .map(|u| u.norm())
                .fold(summary.max_displacement, Real::max);
            let mut written = BodyResult::new(body, &state);
            let d = body.dimension.dofs_per_node();
            written.velocities = m.motion.v.chunks(d).map(|c| c.to_vec()).collect();
            if let (Some(f), Some(breaks)) = (&self.fracture, &breaks) {
                if breaks_members(body) {
                    written.fracture = Some(BodyFracture {
                        broken: f.broken[k].iter().map(|j| j + 1).collect(),
                        breaks: breaks[k]
                            .iter()
                            .map(|b| BreakRecord {
                                member: b.member + 1,
                                load_factor: time_load_factor(world, b.time, duration),
                                tooth: None,
                                time: Some(b.time),
                            })
                            .collect(),
                        fallen: Vec::new(),
                        collapse: false,
                    });
                }
            }
            if let Some(quantity) = written
                .non_finite()
                .or_else(|| (!m.motion.v.iter().all(|v| v.is_finite())).then_some("velocities"))
            {
                return Err(RunError::Solve {
                    scene: world.source.clone(),
                    source: SolveError::Overflow {
                        body: body.name.clone(),
                        quantity,
                    },
                });
            }
            energy.kinetic_energy += kinetic_energy(&m.mass, &m.motion.v);
            energy.strain_energy += strain_energy(body, &m.motion.u);
            energy.momenta.push(BodyMomentum {
                body: body.name.clone(),
                momentum: momentum(body, &m.mass, &m.motion.v),
                angular_momentum: angular_momentum(body, &m.mass, &m.motion.u, &m.motion.v),
            });
            if let Some(c) = &self.contact {
                c.write_contacts(k, body, &mut written);
            }
            result.bodies.push(written);
        }
        if let Some(c) = &self.contact {
            c.summarize(&world.bodies, &mut summary);
            energy.contact_energy = c.penalty_energy;
        }
        energy.total_energy = energy.kinetic_energy + energy.strain_energy + energy.contact_energy
            - energy.external_work
            + energy.dissipated;
        summary.dynamics = Some(energy);
        Ok((result, summary))
    }

    /// Model sizes, as `summary.json` reports them.
    pub fn sizes(&self) -> Vec<BodySize> {
        self.world
            .bodies
            .iter()
            .zip(&self.motions)
            .map(|(b, m)| BodySize {
                name: b.name.clone(),
                dimension: b.dimension.dofs_per_node(),
                nodes: b.nodes.len(),
                members: b.members.len(),
                patches: b.patches.len(),
                free_dofs: m.assembly.n,
                solver: m.solver_used().to_string(),
            })
            .collect()
    }

    /// Time spent in each phase, summed over the bodies and the contact solver, s.
    pub fn times(&self) -> PhaseTimes {
        let mut sum = PhaseTimes::default();
        let contact = self.contact.as_ref().map(|c| c.times());
        for t in self
            .motions
            .iter()
            .map(|m| &m.times)
            .chain(contact.as_ref())
        {
            sum.assembly += t.assembly;
            sum.symbolic += t.symbolic;
            sum.numeric += t.numeric;
            sum.solve += t.solve;
        }
        sum
    }

    /// Time spent finding contacts (projecting nodes on obstacles and bodies), s; 0 without
    /// contact.
    pub fn query_seconds(&self) -> Real {
        self.contact.as_ref().map_or(0.0, |c| c.query_seconds())
    }
}

/// The load factor reported at time `t` of `duration`: the common schedule's factor when every
/// load and prescribed displacement follows one schedule, else `t / duration`.
fn time_load_factor(world: &World, t: Real, duration: Real) -> Real {
    match crate::scene::world::common_schedule(&world.bodies) {
        Some(first) => time_factor(first, t, duration),
        _ => t / duration,
    }
}
