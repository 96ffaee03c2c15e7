//! One time step of bodies with inertia in contact: the settle loop with each body's
//! [`InertiaTerm`] in its residual and tangent.
//!
//! # How inertia enters the contact solve
//!
//! A time step is a load step with inertia (`DESIGN.md`). The integrator (the `dyn` branch's
//! `linkage::dynamics`) turns the step into the problem: find `y` (per body DOF) with
//!
//! `f_int(y) + c M (y − y*) + f_c(y) = f_ext(t*)`,
//!
//! `M` the lumped mass, `c` and the predictor `y*` from the integrator and the step size (the
//! midpoint rule: `y = (u_n + u_{n+1})/2`, `c = 4/h²`, `y* = u_n + h v_n / 2`). The contact
//! solver treats `y` as its displacements: the contacts are found and evaluated at `y` (the
//! penalty force `k · depth(y)` along the normal, friction's return mapping against the
//! history committed at the last time step solved), the coupled Newton's out-of-balance
//! gains `− c M (y − y*)` at every free DOF (and the reactions at held DOFs gain the inertia
//! of the held mass), its force scale gains the norm of the inertia force (a body in free
//! flight has no other), and its tangent gains `c M` on the diagonal: `K_T + c M + K_c`. A
//! factor of the tangent kept for a linear body's next Newton iteration serves only with the
//! same coefficients. `c M` makes the tangent positive definite for every body, so a body needs
//! no supports and the stabilisation of a body held only by contact is never needed.
//!
//! The contact set is settled within the step as in a load step; the step is never cut here
//! (a failure returns the error with the state of the last time step kept, and the driver
//! halves the time step; [`ContactSolver::solve_time_step_within`] also fails a step that
//! leaves a node deeper than a given depth, for the driver to halve it). The condensed path (every body linear, factored once) is not used
//! for time steps: its factor is `K` alone (a solver made by [`ContactSolver::new`] leaves it
//! at its first time step). Giving it `K + c M`, refactored when `c` changes, with the step's
//! load `f_ext + c M y*` solved once per step, is the next step.
//!
//! # Energy under the midpoint rule
//!
//! The midpoint rule applies the force at `y` over the whole step: `M (v_{n+1} − v_n) = h F(y)`
//! and `u_{n+1} − u_n = h (v_n + v_{n+1})/2`, so the kinetic energy changes by
//! `F(y) · (u_{n+1} − u_n)`. For a force with a quadratic potential `V` (linear members, and
//! a penalty `½ k g²` against a plane, where the gap `g` is linear in the position) that is
//! exactly `−[V(u_{n+1}) − V(u_n)]`: energy is conserved to the Newton tolerance. The penalty
//! is quadratic only piecewise (`½ k max(0, −g)²`): a step within which a node comes into or
//! out of contact applies `k · depth(y)` (or nothing) where the true work is the integral over
//! the part of the path inside. The error of such a step is at most the penalty energy of that
//! node over the step, `≈ ½ k (v_n h)²` for a node arriving at `v_n`, of either sign; against a
//! plane with the contact set unchanged within a step it is zero. Against a curved obstacle
//! the normal turns along the path and the error is of the order `depth / radius` of the
//! penalty work. The scene tests of `tests/dynamic_contact.rs` measure it: a bar bouncing off
//! a wall keeps its energy to 1e-3 (2.2e-4 measured).

use crate::contact::contact_set::{ActiveContact, ContactSet};
use crate::contact::friction::FrictionHistory;
use crate::contact::report::ContactStep;
use crate::contact::{ContactError, ContactSettings, ContactSolver, Obstacle};
use crate::linkage::dynamics::InertiaTerm;
use crate::linkage::Body;
use crate::Real;
use nalgebra::Vector3;
use std::collections::HashMap;

impl ContactSolver {
    /// The solver of a dynamic world: the bodies of [`ContactSolver::new`], to be solved by
    /// [`ContactSolver::solve_time_step`]. A body needs no supports (its inertia holds it: a
    /// body may fly free), and every body is solved on the coupled path (the condensed one
    /// factors `K` alone, without the `c M` of a time step).
    pub fn dynamic(
        bodies: &[Body],
        obstacles: &[Obstacle],
        settings: ContactSettings,
    ) -> Result<Self, ContactError> {
        ContactSolver::build(
            bodies,
            obstacles,
            ContactSettings {
                condense: false,
                ..settings
            },
        )
    }

    /// Set the pseudo-time (step units) the first time step starts from: where the obstacles
    /// stand before it (the crossings of the first step are found from there).
    pub fn start_time_steps_at(&mut self, at: Real) {
        if self.time_steps == 0 {
            self.time_at = at;
        }
    }

    /// Solve one time step: find the configuration `y` (per body DOF, m) where
    ///
    /// `f_int(y) + c M (y − y*) + f_contact(y) = f_ext(at)`
    ///
    /// for every body at once, with `inertia[b]` body b's mass `M`, coefficient `c` and
    /// predictor `y*` ([`InertiaTerm`]; the integrator maps `y` back to the step's end), and
    /// the loads, prescribed displacements and obstacle offsets taken at the pseudo-time `at`
    /// of `steps` (step units, fractional between steps, as in [`ContactSolver::solve_step`]).
    /// The tangent is `K_T + c M + K_c`. Newton starts from the predictor (at the free DOFs)
    /// with the contact set of the last time step solved, and the contact set is settled as in
    /// a load step. The step is not cut here: when it cannot be solved, the state goes back to
    /// the last time step solved and the error is returned (the time driver halves the time
    /// step and calls again). Friction's history is committed once the step is solved, as
    /// after a load step. The report's states are at `y` (their residual includes the inertia
    /// force, and the reactions at held DOFs the inertia of the held mass).
    pub fn solve_time_step(
        &mut self,
        bodies: &[Body],
        obstacles: &[Obstacle],
        at: Real,
        steps: usize,
        inertia: &[InertiaTerm],
    ) -> Result<ContactStep, ContactError> {
        self.solve_time_step_within(bodies, obstacles, (at, steps), inertia, None)
    }

    /// [`ContactSolver::solve_time_step`] that also fails, with the state and the friction
    /// history of the last time step kept, when the solution leaves a node deeper than
    /// `deepest` (m) inside what it touches ([`ContactError::TimeStepTooDeep`]): the time
    /// driver then halves the step, so that the contact set changes little within a step.
    pub fn solve_time_step_within(
        &mut self,
        bodies: &[Body],
        obstacles: &[Obstacle],
        (at, steps): (Real, usize),
        inertia: &[InertiaTerm],
        deepest: Option<Real>,
    ) -> Result<ContactStep, ContactError> {
        check_inertia(bodies, inertia)?;
        if !at.is_finite() {
            return Err(ContactError::TimeStepPosition { at });
        }
        // The condensed path (a solver made by `new`) has no inertia term.
        self.leave_condensed()?;
        let step = self.time_steps + 1;
        self.linear_before = self.coupled.linear_iterations();
        let saved = self.converged_state();
        self.geometry
            .record_sides(bodies, &self.parts, &self.active);
        let offsets_there: Vec<Vector3<Real>> = obstacles
            .iter()
            .map(|o| o.offset_at(self.time_at, steps))
            .collect();
        self.geometry
            .record_crossings(bodies, &self.parts, &self.active, offsets_there);
        for (part, term) in self.parts.iter_mut().zip(inertia) {
            for &dof in &part.dofs.free {
                part.u[dof] = term.predictor[dof];
            }
        }
        let solved = self
            .settle(bodies, obstacles, (at, steps), step, Some(inertia))
            .and_then(|out| {
                self.report_at(bodies, obstacles, (at, steps), step, Some(inertia), out)
            });
        let solved = match (solved, deepest) {
            (Ok(r), Some(limit)) if r.max_penetration > limit => {
                Err(ContactError::TimeStepTooDeep {
                    depth: r.max_penetration,
                    limit,
                })
            }
            (other, _) => other,
        };
        match solved {
            Ok(reported) => {
                self.commit_friction(bodies, obstacles, at, steps, step);
                self.time_steps = step;
                self.time_at = at;
                Ok(reported)
            }
            Err(e) => {
                self.restore(saved);
                Err(e)
            }
        }
    }
}

/// What a solved time step changes in a [`ContactSolver`]: the displacements it starts the
/// next step from, the contact set and its normals, friction's committed history (stick
/// anchors, slips), the step count and pseudo-time, and the force floor. Saved by
/// [`ContactSolver::time_step_state`] and put back by
/// [`ContactSolver::restore_time_step_state`], a solved time step is undone exactly: the next
/// one solves as if it had never been (the event search of a breaking step tries several
/// lengths of one sub-step from the same state).
#[derive(Clone, Debug)]
pub struct TimeStepState {
    u: Vec<Vec<Real>>,
    active: ContactSet,
    normals: HashMap<ActiveContact, Vector3<Real>>,
    friction: Option<FrictionHistory>,
    time_steps: usize,
    time_at: Real,
    largest_force_scale: Real,
}

impl ContactSolver {
    /// The state the next time step starts from (see [`TimeStepState`]).
    pub fn time_step_state(&self) -> TimeStepState {
        TimeStepState {
            u: self.parts.iter().map(|p| p.u.clone()).collect(),
            active: self.active.clone(),
            normals: self.normals.clone(),
            friction: self.friction.clone(),
            time_steps: self.time_steps,
            time_at: self.time_at,
            largest_force_scale: self.largest_force_scale,
        }
    }

    /// Forget the factored tangent the next time step would reuse (a body's member factors
    /// changed: members broke, or a trial that broke them was undone).
    pub fn forget_kept_factor(&mut self) {
        self.coupled.forget_factor();
    }

    /// Go back to a state saved by [`ContactSolver::time_step_state`] of this solver. The
    /// crossings into sharp obstacle features found since are forgotten (the next time step
    /// records them anew from the restored positions).
    pub fn restore_time_step_state(&mut self, saved: TimeStepState) {
        for (p, u) in self.parts.iter_mut().zip(saved.u) {
            p.u = u;
        }
        self.active = saved.active;
        self.normals = saved.normals;
        self.friction = saved.friction;
        self.time_steps = saved.time_steps;
        self.time_at = saved.time_at;
        self.largest_force_scale = saved.largest_force_scale;
        self.geometry.forget_crossings_found();
    }
}

/// `Err` naming the body whose inertia term does not fit it: one term per body, one mass and
/// one predictor value per body DOF, finite, masses and the coefficient at least zero.
fn check_inertia(bodies: &[Body], inertia: &[InertiaTerm]) -> Result<(), ContactError> {
    if inertia.len() != bodies.len() {
        return Err(ContactError::InertiaCount {
            terms: inertia.len(),
            bodies: bodies.len(),
        });
    }
    for (body, term) in bodies.iter().zip(inertia) {
        let dofs = body.dof_count();
        let problem = if term.mass.len() != dofs {
            Some(format!("{} masses for {dofs} DOFs", term.mass.len()))
        } else if term.predictor.len() != dofs {
            Some(format!(
                "{} predictor values for {dofs} DOFs",
                term.predictor.len()
            ))
        } else if !(term.coefficient.is_finite() && term.coefficient >= 0.0) {
            Some(format!("coefficient {:e} 1/s²", term.coefficient))
        } else if let Some(i) = term.mass.iter().position(|m| !(m.is_finite() && *m >= 0.0)) {
            Some(format!(
                "mass {:e} kg at DOF {} of node {}",
                term.mass[i],
                i % body.dimension.dofs_per_node() + 1,
                i / body.dimension.dofs_per_node() + 1
            ))
        } else {
            term.predictor.iter().position(|p| !p.is_finite()).map(|i| {
                format!(
                    "predictor {:e} m at DOF {} of node {}",
                    term.predictor[i],
                    i % body.dimension.dofs_per_node() + 1,
                    i / body.dimension.dofs_per_node() + 1
                )
            })
        };
        if let Some(problem) = problem {
            return Err(ContactError::Inertia {
                body: body.name.clone(),
                problem,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linkage::{Dimension, Material, Member};

    /// A free 2D bar of two nodes, 1 m along x.
    fn bar() -> Body {
        let mut body = Body::new("bar", Dimension::Two);
        body.materials.push(Material::new("m", 1e9, 1e-4));
        body.nodes = vec![Vector3::zeros(), Vector3::new(1.0, 0.0, 0.0)];
        body.members.push(Member {
            nodes: [0, 1],
            material: 0,
        });
        body
    }

    fn term(mass: Vec<Real>, coefficient: Real, predictor: Vec<Real>) -> InertiaTerm {
        InertiaTerm {
            mass,
            coefficient,
            predictor,
        }
    }

    #[test]
    fn an_inertia_term_that_does_not_fit_its_body_is_named() {
        let bodies = [bar()];
        let good = term(vec![1.0; 4], 4.0, vec![0.0; 4]);
        assert!(check_inertia(&bodies, std::slice::from_ref(&good)).is_ok());
        let count = check_inertia(&bodies, &[]).unwrap_err().to_string();
        assert!(count.contains("0 inertia terms for 1 bodies"), "{count}");
        let short = check_inertia(&bodies, &[term(vec![1.0; 3], 4.0, vec![0.0; 4])])
            .unwrap_err()
            .to_string();
        assert!(short.contains("body 'bar'") && short.contains("3 masses for 4 DOFs"));
        let negative = check_inertia(
            &bodies,
            &[term(vec![1.0, 1.0, -1.0, 1.0], 4.0, vec![0.0; 4])],
        )
        .unwrap_err()
        .to_string();
        assert!(negative.contains("DOF 1 of node 2"), "{negative}");
        let nan = check_inertia(&bodies, &[term(vec![1.0; 4], Real::NAN, vec![0.0; 4])]);
        assert!(nan.unwrap_err().to_string().contains("coefficient NaN"));
    }

    #[test]
    fn a_free_body_without_supports_or_contact_moves_on_its_predictor() {
        // No force acts: the solution of c M (y − y*) = 0 is the predictor itself, for a body
        // the static solve would refuse (nothing holds it).
        let bodies = [bar()];
        let mut solver = ContactSolver::dynamic(&bodies, &[], ContactSettings::default()).unwrap();
        let predictor = vec![1e-3, -2e-3, 1e-3, -2e-3];
        let step = solver
            .solve_time_step(
                &bodies,
                &[],
                1.0,
                1,
                &[term(vec![0.5; 4], 4e6, predictor.clone())],
            )
            .unwrap();
        let u = &step.states[0].displacements;
        for (node, d) in u.iter().enumerate() {
            for k in 0..2 {
                assert!((d[k] - predictor[2 * node + k]).abs() < 1e-15, "{u:?}");
            }
        }
        assert!(step.states[0].residual < 1e-10);
    }
}
