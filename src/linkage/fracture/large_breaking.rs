//! Members that break (or soften by teeth) in a nonlinear body: large displacements, cables
//! or struts, followed by Newton under load control.
//!
//! A nonlinear body's stresses are not linear in its loads, so the critical load of a member
//! is not on the secant of its stress between two solved states (what
//! [`BreakingEquilibrium`](super::BreakingEquilibrium) uses, exact for a linear body). As the
//! event search in time does ([`crate::scene::BreakingBodies`]), the load is searched: from a
//! state solved at pseudo-time `t₀` with every intact breaking member within its strength, the
//! body is solved to the step's end `t₁`; when a member is then beyond its strength, the body
//! is solved again from `t₀` (the saved Newton state) to `t₀ + θ (t₁ − t₀)`, `θ` from the
//! secant of each member's stress between the bracket's ends ([`critical_fraction`]), the
//! bracket narrowed (Illinois: a side kept twice in a row moves the next guess halfway to the
//! middle), until the first member is at its strength to [`AT_STRENGTH`] with no member
//! beyond it by more, or the bracket is narrower than [`EVENT_LOAD`] of the step. There every
//! member at its strength breaks in one event (symmetric members together): its modulus
//! factor becomes 0 ([`Body::member_factors`]; a softening member's, its next tooth's), and
//! the weakened body is solved again at that load.
//!
//! When the weakened body is beyond the strength of a member at the break's load (a
//! snap-back: it fails at a lower load), it is solved lower, at the step's start and else
//! unloaded, and the search runs between there and the break's state: the next break is
//! recorded at its lower load (a fraction of the step's increment below the previous break's,
//! below 0 when it lies in an earlier step's), as the linear path records it. When even the
//! unloaded weakened body has a member beyond its strength (or cannot be solved lower), those
//! members break at the break's load. An elastic body (without friction) has no history but its
//! broken members, so solving it lower is as good as unloading it.
//!
//! A break after which the weakened body cannot be solved at the break's load (its tangent is
//! singular there, as a linear body's stiffness is when something comes loose) leaves pieces
//! without support (as without contact: connected parts without supports, and nodes on fewer
//! intact members than their DOFs, see [`released_pieces`]). They are decided as
//! [`BreakingEquilibrium`](super::BreakingEquilibrium) decides them: a loaded piece still
//! hanging on the rest by intact members (a mechanism under load: it would swing, not fall),
//! or a loss that leaves the rest with nothing that loads it, is the structure's collapse
//! ([`SolveError::Collapse`]); otherwise the pieces fell off and are taken out of the solve
//! (their members carry nothing, their loads are dropped, their nodes are held where they were
//! made) and the rest goes on. When nothing came loose, or the rest cannot be solved either,
//! the break is the collapse, as a break that leaves the weakened body unable to take the rest
//! of the step's load is. A loaded node left hanging on one member in tension is solved (the
//! tension holds it sideways under large displacements: a pendulum at rest) and goes on; one
//! balanced on a strut is solved too, but unstable (a negative pivot): that is the collapse
//! (with conjugate gradients the pivots are not counted, and it goes on).

use crate::linkage::body_state::member_response_at;
use crate::linkage::fracture::{
    critical_fraction, member_limits, member_teeth, released_pieces, strength_ratio, BreakEvent,
    FallenPiece, FractureState, MemberLimits, Tooth, AT_STRENGTH,
};
use crate::linkage::SavedNewton;
use crate::linkage::{Body, NewtonEquilibrium, PathMethod, PhaseTimes, SolveError, StepState};
use crate::linkage::{PressureFaces, Support};
use crate::Real;

/// The load search stops when its bracket is narrower than this fraction of a step.
pub const EVENT_LOAD: Real = 1e-12;

/// Trial solves allowed to find one event.
const MAX_REFINEMENTS: usize = 80;

/// A nonlinear body whose members break, followed by Newton (see the module documentation).
pub struct LargeBreakingEquilibrium {
    /// The Newton solver of the body as it breaks.
    pub newton: NewtonEquilibrium,
    /// The body as it is now (broken members of modulus factor 0, softened ones their tooth's).
    pub body: Body,
    original: Body,
    limits: MemberLimits,
    first_limits: MemberLimits,
    teeth: Vec<Vec<Tooth>>,
    tooth: Vec<usize>,
    /// Members broken so far, in order.
    broken: Vec<usize>,
    /// Per member, whether it broke in tension.
    in_tension: Vec<bool>,
    /// Per node, whether it fell off with a piece.
    fallen_node: Vec<bool>,
    /// The last step solved.
    step: usize,
    /// Trial Newton solves of the searches so far (each from a saved state).
    pub trial_solves: usize,
}

/// The state the search stands on: Newton's, its pseudo-time and its members' stresses.
struct Solved {
    newton: SavedNewton,
    t: Real,
    stress: Vec<Real>,
}

impl LargeBreakingEquilibrium {
    /// Validate `body` (nonlinear, by load control) and prepare its Newton solver, each
    /// member's strength from its material (scattered when it has `scatter`).
    pub fn new(body: &Body) -> Result<Self, SolveError> {
        if let PathMethod::ArcLength { .. } = body.newton.path {
            return Err(SolveError::BreakingUnsupported {
                body: body.name.clone(),
                reason: "are not followed along an arc-length path (the search for a member's critical load moves the load, which the arc length sets)".to_string(),
                remedy: "follow the path by its schedules ([bodies.path] method = \"schedules\")".to_string(),
            });
        }
        let limits = member_limits(body);
        Self::with_limits(body, limits)
    }

    /// [`LargeBreakingEquilibrium::new`] with each member's strengths given (tensile,
    /// compressive, Pa; `None`: the member does not break).
    pub fn with_limits(body: &Body, limits: MemberLimits) -> Result<Self, SolveError> {
        let teeth = member_teeth(body, &limits)?;
        let newton = NewtonEquilibrium::new(body)?;
        let n = body.members.len();
        Ok(LargeBreakingEquilibrium {
            newton,
            body: body.clone(),
            original: body.clone(),
            first_limits: limits.clone(),
            limits,
            teeth,
            tooth: vec![0; n],
            broken: Vec::new(),
            in_tension: vec![false; n],
            fallen_node: vec![false; body.nodes.len()],
            step: 0,
            trial_solves: 0,
        })
    }

    /// Time spent in each phase so far, s.
    pub fn times(&self) -> PhaseTimes {
        self.newton.times
    }

    /// Whether member `m` (0-based) broke in tension (its ends apart at the break).
    pub fn broke_in_tension(&self, m: usize) -> bool {
        self.in_tension.get(m).copied().unwrap_or(false)
    }

    /// Per member its stress at the current displacement (Pa, tension positive: its axial
    /// force over its area, as the step's results report it).
    fn stresses(&self) -> Vec<Real> {
        let u = self.newton.displacements();
        (0..self.body.members.len())
            .map(|m| {
                if self.limits[m].is_none() || self.body.modulus_factor(m) == 0.0 {
                    return 0.0;
                }
                let area = self.body.materials[self.body.members[m].material].area;
                member_response_at(&self.body, u, m).force / area
            })
            .collect()
    }

    /// The largest stress over strength of the intact breaking members in `stress`.
    fn worst(&self, stress: &[Real]) -> Real {
        self.limits
            .iter()
            .zip(stress)
            .enumerate()
            .filter(|(m, _)| self.body.modulus_factor(*m) > 0.0)
            .filter_map(|(_, (l, &s))| l.map(|(ft, fc)| strength_ratio(s, ft, fc)))
            .fold(0.0, Real::max)
    }

    /// The smallest fraction of the bracket from stresses `lo` to `hi` at which a member
    /// beyond its strength at `hi` reaches it on the secant; in `[0, 1]`.
    fn secant(&self, lo: &[Real], hi: &[Real]) -> Real {
        let mut first: Real = 1.0;
        for (m, l) in self.limits.iter().enumerate() {
            let Some((ft, fc)) = *l else { continue };
            if self.body.modulus_factor(m) == 0.0 {
                continue;
            }
            if let Some(f) = critical_fraction(lo[m], hi[m] - lo[m], ft, fc) {
                first = first.min(f);
            }
        }
        first.clamp(0.0, 1.0)
    }

    fn here(&self, t: Real) -> Solved {
        Solved {
            newton: self.newton.save(),
            t,
            stress: self.stresses(),
        }
    }

    /// Back to the original body, undeformed (step 0).
    fn start_over(&mut self) -> Result<(), SolveError> {
        if self.fallen_node.iter().any(|&f| f) {
            // Its fallen nodes are held: give the solver the whole body back.
            self.fallen_node.iter_mut().for_each(|f| *f = false);
            self.newton.refit(&self.original, &[], 0.0)?;
        }
        self.body = self.original.clone();
        self.limits = self.first_limits.clone();
        self.tooth.iter_mut().for_each(|t| *t = 0);
        self.broken.clear();
        self.in_tension.iter_mut().for_each(|t| *t = false);
        self.newton.start_over();
        self.step = 0;
        Ok(())
    }

    /// The state at `step` of `steps` after every break the step's load causes (step 0:
    /// undeformed, unloaded). Steps are solved in order from the last one solved; asking for
    /// an earlier step starts over. [`SolveError::Collapse`] when a break leaves the body
    /// unable to carry its load.
    pub fn solve_step(
        &mut self,
        _body: &Body,
        step: usize,
        steps: usize,
    ) -> Result<StepState, SolveError> {
        if step == 0 || step < self.step {
            self.start_over()?;
        }
        let cg_before = self.newton.linear_iterations();
        let mut counts = (0, 0);
        let mut fracture = FractureState::default();
        while self.step < step {
            let target = self.step + 1;
            fracture.breaks.clear();
            fracture.fallen.clear();
            self.advance_step(
                target,
                steps,
                (&mut fracture.breaks, &mut fracture.fallen),
                &mut counts,
            )?;
            self.step = target;
        }
        fracture.broken = self.broken.clone();
        let mut state = self
            .newton
            .state_of_step(&self.body, (step, steps), counts, cg_before)?;
        state.fracture = Some(fracture);
        Ok(state)
    }

    /// Solve from step `step − 1`'s state to `step`'s load, breaking members at their events
    /// (appended to `events`; pieces that fall off to `fallen`); Newton iterations and cuts are
    /// added to `counts`.
    fn advance_step(
        &mut self,
        step: usize,
        steps: usize,
        (events, fallen): (&mut Vec<BreakEvent>, &mut Vec<FallenPiece>),
        counts: &mut (usize, usize),
    ) -> Result<(), SolveError> {
        let start = (step - 1) as Real;
        let end = step as Real;
        let mut at = self.here(start);
        loop {
            if self.body.newton.interrupt.is_raised() {
                return Err(SolveError::Interrupted {
                    body: self.body.name.clone(),
                    step,
                });
            }
            let event = if self.worst(&at.stress) > 1.0 + AT_STRENGTH {
                // A snap-back: the weakened body is beyond a strength at this load already.
                self.below(&at, step, steps, counts)
            } else {
                let solved = self.newton.advance(&self.body, (at.t, end), step, steps);
                match solved {
                    Ok((i, c)) => {
                        counts.0 += i;
                        counts.1 += c;
                    }
                    Err(e) => return Err(self.collapse_or(e, step, events)),
                }
                let top = self.here(end);
                if self.worst(&top.stress) <= 1.0 + AT_STRENGTH {
                    return Ok(());
                }
                self.search(&at, top, step, steps, counts)?
            };
            // Break every member at its strength there, in one event.
            let (t, stress) = (event.t, event.stress.clone());
            self.newton.restore(event.newton);
            let members: Vec<usize> = (0..self.body.members.len())
                .filter(|&m| {
                    self.body.modulus_factor(m) > 0.0
                        && self.limits[m].is_some_and(|(ft, fc)| {
                            strength_ratio(stress[m], ft, fc) >= 1.0 - AT_STRENGTH
                        })
                })
                .collect();
            for &m in &members {
                let tooth = self.break_member(m, stress[m] > 0.0);
                events.push(BreakEvent {
                    member: m,
                    fraction: t - start,
                    tooth,
                });
            }
            let name = self.body.name.clone();
            let collapse = |events: &[BreakEvent], member: usize| SolveError::Collapse {
                body: name.clone(),
                step,
                member,
                breaks: events.to_vec(),
                state: None,
            };
            let first = members.first().copied().unwrap_or(0);
            if let Ok(i) = self.newton.solve_again_at(&self.body, t, step, steps) {
                counts.0 += i;
                // Solved: a loaded piece hanging on the rest by a mechanism is held only when
                // the solution is stable (a pendulum in tension); balanced on a strut (a
                // negative pivot) it is the collapse.
                if self.newton.negative_pivots() > 0 && self.hanging_loaded() {
                    return Err(collapse(events, self.releasing(&members)));
                }
                at = self.here(t);
                continue;
            }
            // The weakened body cannot be solved (its tangent singular, as a linear body's
            // stiffness is): what no longer holds on falls off, or is the collapse (named
            // after the member whose break released it, as without large displacements).
            let member = self.releasing(&members);
            let pieces = match self.release_pieces() {
                Some(pieces) if !pieces.is_empty() => pieces,
                Some(_) => return Err(collapse(events, first)),
                None => return Err(collapse(events, member)),
            };
            let held: Vec<usize> = pieces.iter().flatten().copied().collect();
            self.newton.refit(&self.body, &held, t)?;
            fallen.extend(
                pieces
                    .into_iter()
                    .map(|nodes| FallenPiece { member, nodes }),
            );
            match self.newton.solve_again_at(&self.body, t, step, steps) {
                Ok(i) => counts.0 += i,
                Err(_) => return Err(collapse(events, member)),
            }
            at = self.here(t);
        }
    }

    /// Whether the pieces left without support now (see [`released_pieces`]) include a loaded
    /// one hanging on the rest by intact members.
    fn hanging_loaded(&self) -> bool {
        let l = self.loose();
        hanging_loaded(&self.body, &l.members, &l.intact, &l.pieces, &l.released)
    }

    /// The body's members (node pairs), which of them are intact and which nodes are
    /// supported.
    fn topology(&self) -> (Vec<[usize; 2]>, Vec<bool>, Vec<bool>) {
        let body = &self.body;
        let members: Vec<[usize; 2]> = body.members.iter().map(|x| x.nodes).collect();
        let intact: Vec<bool> = (0..members.len())
            .map(|j| body.modulus_factor(j) > 0.0)
            .collect();
        let dofs = &self.newton.dofs;
        let mut supported = vec![false; body.nodes.len()];
        for &dof in &dofs.supported {
            supported[dof / dofs.dofs_per_node] = true;
        }
        (members, intact, supported)
    }

    /// The pieces left without support now (see [`released_pieces`]), with the topology they
    /// were found in.
    fn loose(&self) -> Loose {
        let (members, intact, supported) = self.topology();
        let pieces = released_pieces(
            &members,
            &intact,
            &supported,
            &self.fallen_node,
            self.newton.dofs.dofs_per_node,
        );
        let mut released = self.fallen_node.clone();
        for &n in pieces.iter().flatten() {
            released[n] = true;
        }
        Loose {
            members,
            intact,
            pieces,
            released,
        }
    }

    /// The member of an event (`members`, in the order they broke) whose break released
    /// pieces, the members after it left intact (the first, when none did): the member the
    /// linear path names, which removes them one by one.
    fn releasing(&self, members: &[usize]) -> usize {
        let body = &self.body;
        let (nodes, mut intact, supported) = self.topology();
        for &m in members {
            intact[m] = true;
        }
        for &m in members {
            intact[m] = body.modulus_factor(m) > 0.0;
            let released = released_pieces(
                &nodes,
                &intact,
                &supported,
                &self.fallen_node,
                self.newton.dofs.dofs_per_node,
            );
            if !released.is_empty() {
                return m;
            }
        }
        members.first().copied().unwrap_or(0)
    }

    /// After a break: the pieces left without support (see [`released_pieces`]; nodes
    /// ascending, by first node), taken out of the solve (their members' modulus factors 0,
    /// their loads and the pressures on their faces dropped, their nodes held); empty when
    /// nothing came loose. `None` (nothing removed) when what came loose is the structure's
    /// collapse, as [`BreakingEquilibrium`](super::BreakingEquilibrium) decides it: a loaded
    /// piece still hanging on the rest by intact members, or a loss after which nothing loads
    /// the rest (no load, no pressure, no support that moves).
    fn release_pieces(&mut self) -> Option<Vec<Vec<usize>>> {
        let Loose {
            members,
            intact,
            pieces,
            released,
        } = self.loose();
        if pieces.is_empty() {
            return Some(pieces);
        }
        let body = &self.body;
        if hanging_loaded(body, &members, &intact, &pieces, &released) {
            return None;
        }
        let rest_loaded = (0..body.nodes.len()).any(|n| !released[n] && loaded(body, n))
            || body
                .supports
                .iter()
                .any(|s| !released[s.node] && s.displacement != nalgebra::Vector3::zeros());
        if !rest_loaded {
            return None;
        }
        self.fallen_node = released;
        let gone = &self.fallen_node;
        let body = &mut self.body;
        if body.member_factors.len() != body.members.len() {
            body.member_factors = vec![1.0; body.members.len()];
        }
        for (j, &[a, b]) in members.iter().enumerate() {
            if gone[a] || gone[b] {
                body.member_factors[j] = 0.0;
            }
        }
        body.loads.retain(|l| !gone[l.node]);
        for p in &mut body.pressures {
            match &mut p.faces {
                PressureFaces::Patches(faces) => faces.retain(|f| !f.iter().any(|&n| gone[n])),
                PressureFaces::Segments(faces) => faces.retain(|f| !f.iter().any(|&n| gone[n])),
            }
        }
        body.pressures.retain(|p| !p.faces.is_empty());
        body.supports.extend(
            pieces
                .iter()
                .flatten()
                .map(|&n| Support::fixed(n, [true; 3])),
        );
        Some(pieces)
    }

    /// A Newton failure after members broke in this step (`events`) is the body's collapse:
    /// the weakened body cannot take the load; before any, the failure itself.
    fn collapse_or(&self, e: SolveError, step: usize, events: &[BreakEvent]) -> SolveError {
        match (&e, events.last()) {
            (SolveError::NotConverged { .. }, Some(last)) => SolveError::Collapse {
                body: self.body.name.clone(),
                step,
                member: last.member,
                breaks: events.to_vec(),
                state: None,
            },
            _ => e,
        }
    }

    /// The event between `lo` (every member within its strength; Newton's state saved there)
    /// and `hi` (some member beyond it): Illinois on the load fraction over Newton solves from
    /// `lo`. The state at the event (the first member at its strength), or `hi`'s when the
    /// bracket closes on a jump.
    fn search(
        &mut self,
        lo: &Solved,
        hi: Solved,
        step: usize,
        steps: usize,
        counts: &mut (usize, usize),
    ) -> Result<Solved, SolveError> {
        let (a, b) = (lo.t, hi.t);
        let (mut f_lo, mut s_lo) = (0.0, lo.stress.clone());
        let mut f_hi = 1.0;
        let mut hi = hi;
        let mut kept_side = 0i32;
        for _ in 0..MAX_REFINEMENTS {
            if (f_hi - f_lo) * (b - a).abs() <= EVENT_LOAD {
                break;
            }
            let mut theta = f_lo + (f_hi - f_lo) * self.secant(&s_lo, &hi.stress);
            if kept_side.abs() >= 2 {
                theta = 0.5 * (theta + 0.5 * (f_lo + f_hi));
            }
            if theta <= f_lo || theta >= f_hi {
                theta = 0.5 * (f_lo + f_hi);
            }
            let t = a + theta * (b - a);
            self.newton.restore(lo.newton.clone());
            self.trial_solves += 1;
            let (i, c) = self.newton.advance(&self.body, (a, t), step, steps)?;
            counts.0 += i;
            counts.1 += c;
            let trial = self.here(t);
            let worst = self.worst(&trial.stress);
            if worst > 1.0 + AT_STRENGTH {
                f_hi = theta;
                hi = trial;
                kept_side = if kept_side < 0 { kept_side - 1 } else { -1 };
            } else if worst >= 1.0 - AT_STRENGTH {
                return Ok(trial);
            } else {
                f_lo = theta;
                s_lo = trial.stress;
                kept_side = if kept_side > 0 { kept_side + 1 } else { 1 };
            }
        }
        Ok(hi)
    }

    /// After a break at `top` that left members beyond their strength at its load: the load
    /// below at which the weakened body reaches the first of them (see the module
    /// documentation), or `top` itself when none is found.
    fn below(
        &mut self,
        top: &Solved,
        step: usize,
        steps: usize,
        counts: &mut (usize, usize),
    ) -> Solved {
        let start = (step - 1) as Real;
        for lower in [start, 0.0] {
            if lower >= top.t {
                continue;
            }
            self.newton.restore(top.newton.clone());
            let Ok((i, c)) = self.newton.advance(&self.body, (top.t, lower), step, steps) else {
                break;
            };
            counts.0 += i;
            counts.1 += c;
            let lo = self.here(lower);
            if self.worst(&lo.stress) > 1.0 + AT_STRENGTH {
                continue;
            }
            let hi = Solved {
                newton: top.newton.clone(),
                t: top.t,
                stress: top.stress.clone(),
            };
            if let Ok(found) = self.search(&lo, hi, step, steps, counts) {
                return found;
            }
            break;
        }
        self.newton.restore(top.newton.clone());
        Solved {
            newton: top.newton.clone(),
            t: top.t,
            stress: top.stress.clone(),
        }
    }

    /// Member `m` reached its strength (in tension when `tension`): move it to its next tooth
    /// (returned, 1-based: the tooth passed) when it has one, else break it.
    fn break_member(&mut self, m: usize, tension: bool) -> Option<usize> {
        let next = self.tooth[m] + 1;
        if self.body.member_factors.len() != self.body.members.len() {
            self.body.member_factors = vec![1.0; self.body.members.len()];
        }
        match self.teeth[m].get(next).copied() {
            Some(t) => {
                self.tooth[m] = next;
                self.body.member_factors[m] = t.stiffness_factor;
                let (tensile, compressive) = self.first_limits[m].unwrap_or((1.0, 1.0));
                self.limits[m] = Some((
                    t.tensile_strength,
                    compressive * (t.tensile_strength / tensile),
                ));
                Some(next)
            }
            None => {
                self.body.member_factors[m] = 0.0;
                self.broken.push(m);
                self.in_tension[m] = tension;
                None
            }
        }
    }
}

/// Whether one of `pieces` (nodes ascending) of `body` carries a load (a nodal force or a
/// pressure on a face of it) and still hangs on the rest (nodes not `released`) by a member
/// that is `intact`: a mechanism under load.
fn hanging_loaded(
    body: &Body,
    members: &[[usize; 2]],
    intact: &[bool],
    pieces: &[Vec<usize>],
    released: &[bool],
) -> bool {
    let hanging = |piece: &[usize]| {
        members.iter().zip(intact).any(|(&[a, b], &i)| {
            i && (piece.binary_search(&a).is_ok() && !released[b]
                || piece.binary_search(&b).is_ok() && !released[a])
        })
    };
    pieces
        .iter()
        .any(|piece| hanging(piece) && piece.iter().any(|&n| loaded(body, n)))
}

/// Whether node `n` of `body` carries a load: a nodal force, or a pressure on a face of it.
fn loaded(body: &Body, n: usize) -> bool {
    body.loads
        .iter()
        .any(|l| l.node == n && l.force != nalgebra::Vector3::zeros())
        || body
            .pressures
            .iter()
            .filter(|p| p.pressure != 0.0)
            .any(|p| p.faces.nodes().any(|f| f.contains(&n)))
}

/// The pieces a break left without support, and the topology they were found in.
struct Loose {
    /// Each member's nodes.
    members: Vec<[usize; 2]>,
    /// Whether each member is intact.
    intact: Vec<bool>,
    /// The pieces without support (nodes ascending, by first node).
    pieces: Vec<Vec<usize>>,
    /// Every node released: fallen before, or in one of the pieces.
    released: Vec<bool>,
}
