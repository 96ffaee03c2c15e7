//! The result files of a run (`summary.json`, `steps/NNNN.json`): see the README's output section.

use crate::linkage::{Body, StepState};
use crate::Real;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// A force at a node, as written: 1-based node, one component per dimension, N.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NodeForce {
    /// 1-based node number.
    pub node: usize,
    /// Force, N.
    pub force: Vec<Real>,
}

/// A node pressing on another body or an obstacle (filled by contact; empty without).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ContactForce {
    /// 1-based node number.
    pub node: usize,
    /// Name of the body or obstacle touched.
    pub with: String,
    /// Penetration depth, m.
    pub depth: Real,
    /// Force the node receives, N: `normal_force · normal + tangential_force`.
    pub force: Vec<Real>,
    /// Unit normal of the contact, from the surface towards the node.
    #[serde(default)]
    pub normal: Vec<Real>,
    /// Normal force the node receives, N (≥ 0).
    #[serde(default)]
    pub normal_force: Real,
    /// Tangential (friction) force the node receives, N.
    #[serde(default)]
    pub tangential_force: Vec<Real>,
    /// `"stick"` or `"slip"` (frictionless contacts slip).
    #[serde(default)]
    pub state: String,
    /// Slip of the node over what it touches, accumulated while the contact lasts, m.
    #[serde(default)]
    pub slip: Vec<Real>,
}

/// One body at one step, as written in `steps/NNNN.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BodyResult {
    /// Body name.
    pub name: String,
    /// Displacement per node, m.
    pub displacements: Vec<Vec<Real>>,
    /// Deformed position per node, m.
    pub positions: Vec<Vec<Real>>,
    /// Axial force per member, N, tension positive.
    pub axial_forces: Vec<Real>,
    /// Strain per member (change of length over length), tension positive.
    pub strains: Vec<Real>,
    /// Stress per member, Pa, tension positive.
    pub stresses: Vec<Real>,
    /// 1-based numbers of the members beyond their strength.
    pub overloaded: Vec<usize>,
    /// Force each supported node receives from its supports, N.
    pub reactions: Vec<NodeForce>,
    /// Applied force per loaded node at this step, N.
    pub loads: Vec<NodeForce>,
    /// Contact forces per node.
    pub contacts: Vec<ContactForce>,
    /// `broken`, `breaks` and `fallen`: a body with breaking members only.
    #[serde(flatten, default, skip_serializing_if = "Option::is_none")]
    pub fracture: Option<BodyFracture>,
    /// Velocity per node, m/s (a dynamic scene; absent otherwise).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub velocities: Vec<Vec<Real>>,
}

/// One break as written: the member and the load factor at which it broke.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BreakRecord {
    /// 1-based member number.
    pub member: usize,
    /// The load factor (or prescribed-displacement factor) at which it reached its strength:
    /// below the previous break's in a snap-back.
    pub load_factor: Real,
    /// For a softening member that did not break: the tooth it passed (1-based, below its
    /// material's `softening.teeth`); absent for a break.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tooth: Option<usize>,
    /// The time at which it broke, s (a dynamic scene; absent otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time: Option<Real>,
}

/// The fracture fields of a body at one step.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BodyFracture {
    /// 1-based members broken so far, in the order they broke.
    pub broken: Vec<usize>,
    /// The breaks of this step, and the teeth softening members passed (with `tooth`), in
    /// order.
    pub breaks: Vec<BreakRecord>,
    /// 1-based nodes of pieces that fell off in this step (left without support and removed
    /// from the solve; absent when none).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub fallen: Vec<usize>,
    /// The body collapsed in this step: the state written is the one it collapsed in (the
    /// displacements at its last break, every member broken so far shown broken; no
    /// equilibrium), the run's last step. Absent otherwise.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub collapse: bool,
}

/// A break as the summary lists it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SummaryBreak {
    /// The step in which it happened.
    pub step: usize,
    /// Body name.
    pub body: String,
    /// 1-based member number.
    pub member: usize,
    /// Load factor at which it broke.
    pub load_factor: Real,
    /// For a softening member that did not break: the tooth it passed (1-based); absent for a
    /// break.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tooth: Option<usize>,
    /// The time at which it broke, s (a dynamic scene; absent otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time: Option<Real>,
}

/// The collapse of a structure: a break left its supported part a mechanism.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Collapse {
    /// The step in which it collapsed: written as the run's last step, flagged, when the state
    /// it collapsed in is known (a body solved on its own with linear kinematics, or any body
    /// in a scene with contact); not written otherwise (it has no equilibrium).
    pub step: usize,
    /// Body name.
    pub body: String,
    /// Load factor of the last break.
    pub load_factor: Real,
    /// 1-based number of the member whose break made it a mechanism.
    pub member: usize,
}

/// The total contact force one body receives from one obstacle or other body at a step.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PairForce {
    /// The body.
    pub body: String,
    /// The obstacle or body it touches.
    pub with: String,
    /// Sum of the contact forces on the body's nodes from it, N (one component per dimension).
    pub force: Vec<Real>,
}

/// One stored step: `steps/NNNN.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StepResult {
    /// Step number (0: undeformed).
    pub step: usize,
    /// Load factor of the step.
    pub load_factor: Real,
    /// Time of the stored state, s (a dynamic scene; absent otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time: Option<Real>,
    /// Every body of the scene, in scene order.
    pub bodies: Vec<BodyResult>,
}

/// The energies of a dynamic scene at one stored state, all bodies, J.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StepEnergy {
    /// Time of the state, s.
    pub time: Real,
    /// `½ vᵀ M v`, J.
    pub kinetic_energy: Real,
    /// Strain energy of the members, J.
    pub strain_energy: Real,
    /// Penalty energy `Σ ½ k d²` of the contacts, J (0 without contact).
    #[serde(default)]
    pub contact_energy: Real,
    /// Work of the applied forces (gravity included), of the moving supports and of the moving
    /// obstacles since t = 0, J.
    pub external_work: Real,
    /// Energy dissipated since t = 0 (Rayleigh damping, friction's `μ f_N |slip|`), J.
    pub dissipated: Real,
    /// The balance `kinetic + strain + contact − external_work + dissipated`, J: constant for an
    /// integrator that conserves energy; its drift is the integrator's numerical dissipation.
    pub total_energy: Real,
    /// Time steps taken since the previous stored state.
    pub time_steps: usize,
    /// The smallest time step taken since the previous stored state, s.
    pub smallest_time_step: Real,
    /// Per body, in scene order, its momenta.
    pub momenta: Vec<BodyMomentum>,
}

/// The momenta of one body at one stored state.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BodyMomentum {
    /// Body name.
    pub body: String,
    /// `Σ m v`, kg·m/s, one component per dimension.
    pub momentum: Vec<Real>,
    /// `Σ m x × v` about the origin, kg·m²/s (2D: the z component alone).
    pub angular_momentum: Vec<Real>,
}

/// One line of `summary.json`'s `steps`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StepSummary {
    /// Step number.
    pub step: usize,
    /// Load factor.
    pub load_factor: Real,
    /// Equilibrium iterations (a linear step is one; Newton iterations otherwise, largest over
    /// the bodies).
    pub iterations: usize,
    /// Halvings of the load increment Newton needed (all bodies; 0 for a linear step).
    pub cuts: usize,
    /// Relative residual after each Newton iteration of the step's last increment, for the
    /// body that needed the most iterations (absent for linear steps).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub residuals: Vec<Real>,
    /// Negative pivots of the tangent stiffness at the step's solution, summed over the
    /// bodies: 0 for a stable equilibrium (and for every linear step), k > 0 when the
    /// equilibrium is unstable in k directions (past a limit point, on a falling branch).
    pub negative_pivots: usize,
    /// Nonlinear bodies whose tangent conjugate gradients solved, which count no pivots: their
    /// stability is unknown, and `negative_pivots` counts the others only (absent when none).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub pivots_unknown: usize,
    /// Contact iterations (0 without contact).
    pub contact_iterations: usize,
    /// Contacts that stick (friction holds them; absent without contact).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub sticking: usize,
    /// Contacts that slip (at μ times their normal force; frictionless contacts slip).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub slipping: usize,
    /// Conjugate-gradient iterations of the step's solves, all bodies (0 with the direct
    /// solver; a linear body solves all its load patterns before step 1 and counts them there).
    #[serde(default)]
    pub linear_iterations: usize,
    /// Relative out-of-balance force, largest over the bodies.
    pub residual: Real,
    /// Largest node displacement, m.
    pub max_displacement: Real,
    /// Overloaded members, all bodies.
    pub overloaded: usize,
    /// Largest penetration, m (0 without contact).
    pub max_penetration: Real,
    /// Wall time of the step, s (step 1 includes assembly and factorization).
    pub seconds: Real,
    /// Total contact force per pair: what each body receives from each obstacle or body it
    /// touches (absent without contact).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub contact_forces: Vec<PairForce>,
    /// What the user should know about the step: penetration above the tolerance, a contact
    /// set that did not settle (absent when there is nothing to say).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// Members broken so far, all bodies (absent without breaking members).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub broken: Option<usize>,
    /// The member stress of largest magnitude, Pa, signed (absent without members).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_stress: Option<Real>,
    /// The largest |σ| over its member's strength in that sense, over the members whose
    /// material has one (absent when none has).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stress_ratio: Option<Real>,
    /// `time`, the energies and the momenta of a dynamic scene (absent otherwise).
    #[serde(flatten, default, skip_serializing_if = "Option::is_none")]
    pub dynamics: Option<StepEnergy>,
    /// This line is the state a structure collapsed in (see [`BodyFracture::collapse`]): at
    /// the load factor of its last break, the run's last step. Absent otherwise.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub collapse: bool,
}

/// Size of one body, as reported in `summary.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BodySize {
    /// Body name.
    pub name: String,
    /// 2 or 3.
    pub dimension: usize,
    /// Nodes.
    pub nodes: usize,
    /// Members.
    pub members: usize,
    /// Surface patches.
    pub patches: usize,
    /// Free DOFs (size of `K_ff`).
    pub free_dofs: usize,
    /// The linear solver used: "direct", "iterative", or "iterative, then direct" when
    /// conjugate gradients did not converge.
    #[serde(default)]
    pub solver: String,
}

/// Wall time of the run's phases, s, summed over bodies.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PhaseSeconds {
    /// Reading the scene and its files, building (generating, preparing) its bodies.
    #[serde(default)]
    pub reading: Real,
    /// Assembly of `K_ff`.
    pub assembly: Real,
    /// Ordering and symbolic factorization (linear iterative bodies: the matrix in full rows
    /// and the multigrid set-up).
    pub symbolic: Real,
    /// Numeric factorization.
    pub numeric: Real,
    /// Triangular solves (iterative bodies: conjugate gradients).
    pub solve: Real,
    /// Writing result files.
    pub writing: Real,
    /// Drawing pictures (PNG frames, GIF) of the stored steps.
    #[serde(default)]
    pub drawing: Real,
    /// Finding contacts (projecting nodes on obstacles and surfaces).
    #[serde(default)]
    pub contact_query: Real,
}

/// `summary.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// Scene name.
    pub scene: String,
    /// Per step, 0..=steps.
    pub steps: Vec<StepSummary>,
    /// Model sizes.
    pub bodies: Vec<BodySize>,
    /// Where the time went.
    pub phases: PhaseSeconds,
    /// Why the run stopped early (the steps listed were solved and written); absent when
    /// every step was solved.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub failure: Option<String>,
    /// Fingerprint of the scene text that ran (FNV-1a 64, hex): a batch run again skips a job
    /// only when it matches (absent in folders written before it).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub scene_digest: String,
    /// The quality report of each body prepared from a mesh or an outline, by body name;
    /// absent when no body was prepared.
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub prepared: std::collections::BTreeMap<String, crate::linkage::prepare::PrepareReport>,
    /// Every break of the run, and every tooth a softening member passed (with `tooth`), in
    /// order (absent when nothing broke).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub breaks: Vec<SummaryBreak>,
    /// The structure's collapse, when a break made it a mechanism: the run stopped there with
    /// the steps before it written (absent otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub collapse: Option<Collapse>,
}

/// Components of a vector for a body of dimension `d` (2 or 3).
fn components(v: &Vector3<Real>, d: usize) -> Vec<Real> {
    v.as_slice()[..d].to_vec()
}

impl BodyResult {
    /// The written form of `state` for `body`.
    pub fn new(body: &Body, state: &StepState) -> Self {
        let d = body.dimension.dofs_per_node();
        let node_forces = |list: &[(usize, Vector3<Real>)]| {
            list.iter()
                .map(|(n, f)| NodeForce {
                    node: n + 1,
                    force: components(f, d),
                })
                .collect()
        };
        BodyResult {
            name: body.name.clone(),
            displacements: state
                .displacements
                .iter()
                .map(|u| components(u, d))
                .collect(),
            positions: body
                .nodes
                .iter()
                .zip(&state.displacements)
                .map(|(p, u)| components(&(p + u), d))
                .collect(),
            axial_forces: state.axial_forces.clone(),
            strains: state.strains.clone(),
            stresses: state.stresses.clone(),
            overloaded: state.overloaded.iter().map(|m| m + 1).collect(),
            reactions: node_forces(&state.reactions),
            loads: node_forces(&state.loads),
            contacts: Vec::new(),
            fracture: None,
            velocities: Vec::new(),
        }
    }

    /// The first of its lists holding a NaN or an infinity (which JSON cannot hold), if any:
    /// `"displacements"`, `"positions"`, `"axial forces"`, `"strains"`, `"stresses"`,
    /// `"reactions"` or `"loads"`.
    pub fn non_finite(&self) -> Option<&'static str> {
        let finite = |v: &[Real]| v.iter().all(|x| x.is_finite());
        let nodes = |v: &[Vec<Real>]| v.iter().all(|x| finite(x));
        let forces = |v: &[NodeForce]| v.iter().all(|f| finite(&f.force));
        [
            ("displacements", nodes(&self.displacements)),
            ("positions", nodes(&self.positions)),
            ("axial forces", finite(&self.axial_forces)),
            ("strains", finite(&self.strains)),
            ("stresses", finite(&self.stresses)),
            ("reactions", forces(&self.reactions)),
            ("loads", forces(&self.loads)),
        ]
        .into_iter()
        .find_map(|(name, ok)| (!ok).then_some(name))
    }
}

/// Whether a count is zero (left out of the summary).
fn is_zero(n: &usize) -> bool {
    *n == 0
}
