//! Coulomb friction with an elastic slip: the return mapping of one contact, the coefficients of every pair, and the slip history committed when an increment converges.
//!
//! At a contact with normal force `f_N` (N) and unit normal `n`, the tangential force is found
//! from the relative motion `Δg` (m) of the pressing side over the surface since the last
//! converged state, as for an elasto-plastic spring (CalculiX's node-to-face penalty friction):
//!
//! - trial `f* = P f_old − k_t P Δg`, with `P = I − n nᵀ` and `f_old` the tangential force
//!   committed at the last converged state, turned into the current tangent plane;
//! - stick when `|f*| ≤ μ f_N`: `f_T = f*`, tangent `k_t P` (symmetric);
//! - slip otherwise: `f_T = μ f_N t` with `t = f*/|f*|`, tangent
//!   `μ f_N k_t / |f*| (P − t tᵀ) + μ k_n t nᵀ` (the last term unsymmetric), and the slip grows
//!   by `(|f*| − μ f_N) / k_t` against `t`.
//!
//! Nothing depends on a velocity: a contact below `μ f_N` holds exactly, with an elastic slip
//! of `|f_T| / k_t` at most. The state is committed only at a converged increment, so a cut
//! increment starts again from the last converged history.

use crate::Real;
use nalgebra::{Matrix3, Vector3};
use std::collections::{HashMap, HashSet};

/// Coulomb friction of `[contact]`: the coefficient of every pair, and the pairs that differ.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrictionSettings {
    /// Coulomb coefficient μ of every contact pair (0: frictionless, the default).
    pub coefficient: Real,
    /// Tangential stiffness of sticking, N/m of elastic slip; `None`: the pair's normal
    /// penalty (the elastic slip at `μ f_N` is then μ times the penetration).
    pub stick_stiffness: Option<Real>,
    /// Pairs with their own values (`[[contact.pairs]]`), overriding the ones above.
    pub pairs: Vec<FrictionPair>,
}

/// `[[contact.pairs]]`: friction between two named bodies or obstacles.
#[derive(Clone, Debug, PartialEq)]
pub struct FrictionPair {
    /// The two names (bodies or obstacles; the same name twice: a body against itself).
    pub between: [String; 2],
    /// Coulomb coefficient μ (`None`: the `[contact]` value).
    pub coefficient: Option<Real>,
    /// Stick stiffness, N/m (`None`: the `[contact]` value or rule).
    pub stick_stiffness: Option<Real>,
}

impl FrictionSettings {
    /// Whether any pair has friction.
    pub fn any(&self) -> bool {
        self.coefficient > 0.0
            || self
                .pairs
                .iter()
                .any(|p| p.coefficient.is_some_and(|m| m > 0.0))
    }

    /// The coefficient and stick stiffness (`None`: the rule) between the surfaces named `a`
    /// and `b`.
    pub fn law(&self, a: &str, b: &str) -> (Real, Option<Real>) {
        let pair = self.pairs.iter().find(|p| {
            (p.between[0] == a && p.between[1] == b) || (p.between[0] == b && p.between[1] == a)
        });
        match pair {
            Some(p) => (
                p.coefficient.unwrap_or(self.coefficient),
                p.stick_stiffness.or(self.stick_stiffness),
            ),
            None => (self.coefficient, self.stick_stiffness),
        }
    }
}

/// Whether a contact sticks or slips.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SlipState {
    /// The tangential force is below `μ f_N`: no slip beyond the elastic one.
    Stick,
    /// The tangential force is `μ f_N` (frictionless contacts slip always).
    #[default]
    Slip,
}

impl SlipState {
    /// `"stick"` or `"slip"`, as written in the results.
    pub fn name(self) -> &'static str {
        match self {
            SlipState::Stick => "stick",
            SlipState::Slip => "slip",
        }
    }
}

/// The tangential answer of one contact to a trial relative motion (see the module).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tangential {
    /// Tangential force on the pressing side, N.
    pub force: Vector3<Real>,
    /// Stick or slip.
    pub state: SlipState,
    /// The symmetric part of `−∂f_T/∂Δg`, N/m.
    pub stiffness: Matrix3<Real>,
    /// The unsymmetric part of slip, `a bᵀ` as `(a, b)` (N/m, unit): `μ k_n t nᵀ`.
    pub rank_one: Option<(Vector3<Real>, Vector3<Real>)>,
    /// Slip this increment would add, m (zero while sticking).
    pub slip: Vector3<Real>,
    /// The stick stiffness `k_t` the mapping was made with, N/m (the tangent of sticking is
    /// `k_t P`).
    pub stick_stiffness: Real,
}

/// The return mapping of one contact: friction coefficient `mu`, stick stiffness `kt` (N/m),
/// normal penalty `kn` (N/m) and normal force `fn_` (N, ≥ 0 pressing), unit normal `n`, the
/// committed tangential force `old` (N) and the relative motion `dg` since then (m).
pub fn return_mapping(
    mu: Real,
    kt: Real,
    kn: Real,
    fn_: Real,
    n: &Vector3<Real>,
    old: &Vector3<Real>,
    dg: &Vector3<Real>,
) -> Tangential {
    let p = Matrix3::identity() - n * n.transpose();
    // The committed force turned into the current tangent plane, its size kept.
    let projected = p * old;
    let turned = if projected.norm() > 0.0 {
        projected * (old.norm() / projected.norm())
    } else {
        projected
    };
    let trial = turned - p * dg * kt;
    let limit = mu * fn_.max(0.0);
    let size = trial.norm();
    if size <= limit {
        return Tangential {
            force: trial,
            state: SlipState::Stick,
            stiffness: p * kt,
            rank_one: None,
            slip: Vector3::zeros(),
            stick_stiffness: kt,
        };
    }
    let t = trial / size;
    let pressing = fn_ > 0.0;
    Tangential {
        force: t * limit,
        state: SlipState::Slip,
        stiffness: (p - t * t.transpose()) * (limit * kt / size),
        rank_one: pressing.then(|| (t * (mu * kn), *n)),
        slip: -t * ((size - limit) / kt),
        stick_stiffness: kt,
    }
}

/// Which side a contact's friction history belongs to: a node of a body against an obstacle
/// or another body (whichever patch or segment of it), or an obstacle's sharp point against a
/// body. The history follows a node from patch to patch of the same body.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum FrictionKey {
    /// Node `node` of body `body` against obstacle `obstacle`.
    Obstacle {
        /// The body, scene index.
        body: usize,
        /// The node, 0-based.
        node: usize,
        /// The obstacle, scene index.
        obstacle: usize,
    },
    /// Node `node` of body `body` against body `other`.
    Body {
        /// The pressing body, scene index.
        body: usize,
        /// The node, 0-based.
        node: usize,
        /// The body pressed, scene index.
        other: usize,
    },
    /// Sharp point `point` of obstacle `obstacle` against body `body`.
    Sharp {
        /// The body pressed, scene index.
        body: usize,
        /// The point, in the obstacle's sharp points.
        point: usize,
        /// The obstacle, scene index.
        obstacle: usize,
    },
}

/// What a contact's history holds at the last converged state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Committed {
    /// Tangential force on the pressing side, N.
    pub force: Vector3<Real>,
    /// Slip accumulated, m.
    pub slip: Vector3<Real>,
}

/// The friction of a scene's contacts: the law of each pair and the history committed at the
/// last converged state (the displacements and obstacle offsets there, and each contact's
/// tangential force and slip).
#[derive(Clone, Debug, Default)]
pub struct FrictionHistory {
    /// Per contact (see [`FrictionKey`]), at the last converged state.
    pub committed: HashMap<FrictionKey, Committed>,
    /// Displacement per body DOF of each body at the last converged state, m.
    pub u: Vec<Vec<Real>>,
    /// Obstacle offsets at the last converged state, m.
    pub offsets: Vec<Vector3<Real>>,
    /// Coefficient and stick stiffness (`None`: the normal penalty) per pair: `bodies[b][o]`
    /// for body `b` against obstacle `o`, then body `o − obstacles` for bodies.
    pub laws: Vec<Vec<(Real, Option<Real>)>>,
    /// Obstacles in the scene (where the bodies start in a row of `laws`).
    pub obstacles: usize,
    /// Contacts held sticking whatever their tangential force (μ taken as infinite while they
    /// press): only inside a Newton solve, on a copy of the history, to keep contacts whose
    /// slip reversed between iterates from flipping back and forth. Such a solve ends only
    /// when every held contact is within μ f_N, where the return mapping sticks anyway.
    pub held: HashSet<FrictionKey>,
}

impl FrictionHistory {
    /// The history of a start at rest: no tangential force, the given laws.
    pub fn new(
        laws: Vec<Vec<(Real, Option<Real>)>>,
        obstacles: usize,
        dofs: &[usize],
        offsets: Vec<Vector3<Real>>,
    ) -> Self {
        FrictionHistory {
            committed: HashMap::new(),
            u: dofs.iter().map(|&n| vec![0.0; n]).collect(),
            offsets,
            laws,
            obstacles,
            held: HashSet::new(),
        }
    }

    /// The law of the contact `key`: coefficient and stick stiffness (`None`: the penalty).
    pub fn law(&self, key: &FrictionKey) -> (Real, Option<Real>) {
        let (b, col) = match *key {
            FrictionKey::Obstacle { body, obstacle, .. } => (body, obstacle),
            FrictionKey::Sharp { body, obstacle, .. } => (body, obstacle),
            FrictionKey::Body { body, other, .. } => (body, self.obstacles + other),
        };
        self.laws
            .get(b)
            .and_then(|row| row.get(col))
            .copied()
            .unwrap_or((0.0, None))
    }

    /// Back to a start at rest.
    pub fn clear(&mut self) {
        self.committed.clear();
        self.u.iter_mut().flatten().for_each(|v| *v = 0.0);
        self.offsets.iter_mut().for_each(|o| *o = Vector3::zeros());
        self.held.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const N: Vector3<Real> = Vector3::new(0.0, 1.0, 0.0);

    #[test]
    fn sticks_with_the_elastic_force_below_the_limit_and_slips_at_mu_n_above() {
        // μ 0.5, k_t 1e6 N/m, f_N 100 N: the limit is 50 N, reached at 50 µm of elastic slip.
        let stick = return_mapping(
            0.5,
            1e6,
            1e7,
            100.0,
            &N,
            &Vector3::zeros(),
            &Vector3::new(20e-6, 3e-6, 0.0),
        );
        assert_eq!(stick.state, SlipState::Stick);
        // The normal part of the motion makes no tangential force.
        assert!((stick.force - Vector3::new(-20.0, 0.0, 0.0)).norm() < 1e-12);
        assert!(stick.rank_one.is_none() && stick.slip == Vector3::zeros());
        let slip = return_mapping(
            0.5,
            1e6,
            1e7,
            100.0,
            &N,
            &Vector3::zeros(),
            &Vector3::new(80e-6, 0.0, 0.0),
        );
        assert_eq!(slip.state, SlipState::Slip);
        assert!((slip.force - Vector3::new(-50.0, 0.0, 0.0)).norm() < 1e-12);
        // 80 µm moved, 50 µm of them elastic: 30 µm of slip along the motion.
        assert!((slip.slip - Vector3::new(30e-6, 0.0, 0.0)).norm() < 1e-18);
        let (a, b) = slip.rank_one.unwrap();
        assert!((a - Vector3::new(-0.5 * 1e7, 0.0, 0.0)).norm() < 1e-6 && b == N);
    }

    #[test]
    fn the_tangent_is_the_derivative_of_the_force_by_finite_differences() {
        let n = Vector3::new(0.0, 0.6, 0.8);
        let old = Vector3::new(3.0, 0.0, 0.0);
        let (mu, kt, kn, depth) = (0.4, 2e6, 5e6, 1e-5);
        // f(Δg) with the normal force following the motion: f_N = k_n (depth − n·Δg).
        let force = |dg: &Vector3<Real>| {
            let fn_ = kn * (depth - n.dot(dg));
            return_mapping(mu, kt, kn, fn_, &n, &old, dg)
        };
        for dg in [
            Vector3::new(1e-6, 0.0, 0.0),   // stick
            Vector3::new(4e-5, 1e-5, 0.0),  // slip
            Vector3::new(-3e-5, 0.0, 2e-6), // slip the other way
        ] {
            let at = force(&dg);
            let mut k = at.stiffness;
            if let Some((a, b)) = at.rank_one {
                k += a * b.transpose();
            }
            let h = 1e-11;
            for j in 0..3 {
                let mut e = Vector3::zeros();
                e[j] = h;
                let numeric = -(force(&(dg + e)).force - force(&(dg - e)).force) / (2.0 * h);
                let scale = k.norm();
                assert!(
                    (numeric - k.column(j)).norm() <= 1e-5 * scale,
                    "{:?}: column {j}: {numeric} against {}",
                    at.state,
                    k.column(j)
                );
            }
        }
    }

    #[test]
    fn frictionless_slips_with_no_force() {
        let t = return_mapping(
            0.0,
            1e6,
            1e6,
            10.0,
            &N,
            &Vector3::zeros(),
            &Vector3::new(1e-3, 0.0, 0.0),
        );
        assert_eq!(t.state, SlipState::Slip);
        assert_eq!(t.force, Vector3::zeros());
    }

    #[test]
    fn a_pair_overrides_the_coefficient_either_way_round() {
        let settings = FrictionSettings {
            coefficient: 0.3,
            stick_stiffness: Some(1e8),
            pairs: vec![FrictionPair {
                between: ["block".into(), "floor".into()],
                coefficient: Some(0.5),
                stick_stiffness: None,
            }],
        };
        assert_eq!(settings.law("floor", "block"), (0.5, Some(1e8)));
        assert_eq!(settings.law("block", "wall"), (0.3, Some(1e8)));
        assert!(settings.any());
        assert!(!FrictionSettings::default().any());
    }
}
