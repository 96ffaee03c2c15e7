//! One body: its nodes, members, patches, materials, supports and loads, and their checks.

use crate::linkage::{
    check_members, Geometry, Kinematics, Material, NewtonSettings, PathMethod, SolverSettings,
};
use crate::Real;
use nalgebra::Vector3;

/// Whether a body lives in the plane z = 0 (two DOFs per node) or in space (three).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Dimension {
    /// Plane body: nodes at z = 0, DOFs x and y.
    #[default]
    Two,
    /// Space body: DOFs x, y and z.
    Three,
}

impl Dimension {
    /// Degrees of freedom per node: 2 or 3.
    pub fn dofs_per_node(self) -> usize {
        match self {
            Dimension::Two => 2,
            Dimension::Three => 3,
        }
    }
}

/// An axial member: two node indices (0-based) and the index of its material in `Body::materials`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Member {
    /// End nodes, 0-based.
    pub nodes: [usize; 2],
    /// Index into `Body::materials`.
    pub material: usize,
}

/// How a load or a prescribed displacement grows over the load steps.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Schedule {
    /// `step / steps`: zero at step 0, full value at the last step.
    #[default]
    Linear,
    /// An explicit factor per step 1..=steps (`factors[k - 1]` at step k); zero at step 0.
    Factors(Vec<Real>),
}

impl Schedule {
    /// The factor applied at `step` of `steps` (step 0 is the undeformed state).
    pub fn factor(&self, step: usize, steps: usize) -> Real {
        if step == 0 {
            return 0.0;
        }
        match self {
            Schedule::Linear => step as Real / steps.max(1) as Real,
            Schedule::Factors(f) => f.get(step - 1).copied().unwrap_or(0.0),
        }
    }
}

/// A support: some directions of one node held, optionally at a prescribed displacement.
#[derive(Clone, Debug, PartialEq)]
pub struct Support {
    /// Supported node, 0-based.
    pub node: usize,
    /// Which of x, y, z are held (z is ignored in 2D).
    pub fixed: [bool; 3],
    /// Prescribed displacement of the held directions at full schedule, m (free directions: 0).
    pub displacement: Vector3<Real>,
    /// How the prescribed displacement grows over the steps.
    pub schedule: Schedule,
}

impl Support {
    /// A support that holds `fixed` directions of `node` in place.
    pub fn fixed(node: usize, fixed: [bool; 3]) -> Self {
        Support {
            node,
            fixed,
            displacement: Vector3::zeros(),
            schedule: Schedule::Linear,
        }
    }
}

/// A force applied at a node, N, at full schedule.
#[derive(Clone, Debug, PartialEq)]
pub struct NodalLoad {
    /// Loaded node, 0-based.
    pub node: usize,
    /// Force at full schedule, N (z is zero in 2D).
    pub force: Vector3<Real>,
    /// How the force grows over the steps.
    pub schedule: Schedule,
}

/// One deformable body: a linkage of nodes and members with its supports and loads.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Body {
    /// Name, unique in a scene; names the body in results and messages.
    pub name: String,
    /// 2D or 3D.
    pub dimension: Dimension,
    /// Undeformed node positions, m (z = 0 in 2D).
    pub nodes: Vec<Vector3<Real>>,
    /// Axial members.
    pub members: Vec<Member>,
    /// Outward-facing triangular surface patches, node indices (3D).
    pub patches: Vec<[usize; 3]>,
    /// Materials referred to by the members.
    pub materials: Vec<Material>,
    /// Per member its Young's modulus as a fraction of its material's, in [0, 1]: below 1 for
    /// a member softened by a tooth, 0 for a broken one (fracture keeps the materials as the
    /// scene wrote them). Empty: 1 for every member.
    pub member_factors: Vec<Real>,
    /// Supports; a node may appear in several (their fixed directions combine).
    pub supports: Vec<Support>,
    /// Applied nodal forces.
    pub loads: Vec<NodalLoad>,
    /// Pressures that follow the deformation (large kinematics only, solved by Newton); a
    /// pressure on a body under small displacements is given as `loads` instead
    /// ([`crate::linkage::pressure_loads_on`]).
    pub pressures: Vec<crate::linkage::Pressure>,
    /// Small (the paper's) or large displacements.
    pub kinematics: Kinematics,
    /// How a nonlinear body (large kinematics, or tension- or compression-only members) is solved.
    pub newton: NewtonSettings,
    /// Which linear solver `K_ff` gets, and the iterative solver's stopping rule.
    pub solver: SolverSettings,
}

/// Why a body cannot be solved as given. Numbers in messages are 1-based.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum BodyError {
    /// A material with a bad value.
    #[error("body '{body}': material '{material}': {problem}")]
    Material {
        /// Body name.
        body: String,
        /// Material name.
        material: String,
        /// What is wrong and what to do.
        problem: String,
    },
    /// A node coordinate that is NaN or infinite.
    #[error("body '{body}': node {node} has a non-finite coordinate {value}: give finite numbers in metres")]
    NonFiniteNode {
        /// Body name.
        body: String,
        /// The node, 1-based.
        node: usize,
        /// The coordinate given, m.
        value: Real,
    },
    /// A 2D body with a node off the plane z = 0.
    #[error("body '{body}': node {node} has z = {z} but the body is 2D: 2D nodes lie in the plane z = 0")]
    NodeOffPlane {
        /// Body name.
        body: String,
        /// The node, 1-based.
        node: usize,
        /// Its z coordinate, m.
        z: Real,
    },
    /// A member whose node number does not exist.
    #[error("body '{body}': member {member} names node {node}, but the body has {count} nodes (numbers start at 1)")]
    NodeOutOfRange {
        /// Body name.
        body: String,
        /// The member, 1-based.
        member: usize,
        /// The node, 1-based.
        node: usize,
        /// Nodes the body has.
        count: usize,
    },
    /// A member joining a node to itself.
    #[error("body '{body}': member {member} joins node {node} to itself: a member needs two different nodes")]
    SelfMember {
        /// Body name.
        body: String,
        /// The member, 1-based.
        member: usize,
        /// The node, 1-based.
        node: usize,
    },
    /// A member whose nodes coincide.
    #[error("body '{body}': member {member} joins nodes {a} and {b}, which are at the same place (length {length:e} m): move one node or merge them")]
    ZeroLength {
        /// Body name.
        body: String,
        /// The member, 1-based.
        member: usize,
        /// First node, 1-based.
        a: usize,
        /// Second node, 1-based.
        b: usize,
        /// Distance between them, m.
        length: Real,
    },
    /// Coordinates too large to square: lengths overflow.
    #[error("body '{body}': member {member} joins nodes {a} and {b}, but the coordinates are too large to square (lengths overflow past 1e308): give coordinates in metres, below about 1e150")]
    TooLarge {
        /// Body name.
        body: String,
        /// The member, 1-based.
        member: usize,
        /// First node, 1-based.
        a: usize,
        /// Second node, 1-based.
        b: usize,
    },
    /// Two members joining the same pair of nodes.
    #[error("body '{body}': member {member} joins nodes {a} and {b}, as member {first} already does: remove one (to stiffen a link, use a material with a larger area)")]
    DuplicateMember {
        /// Body name.
        body: String,
        /// The member, 1-based.
        member: usize,
        /// The member that joins them first, 1-based.
        first: usize,
        /// First node, 1-based.
        a: usize,
        /// Second node, 1-based.
        b: usize,
    },
    /// A member whose material index does not exist.
    #[error("body '{body}': member {member} refers to material #{material}, which does not exist")]
    MaterialOutOfRange {
        /// Body name.
        body: String,
        /// The member, 1-based.
        member: usize,
        /// The material's number, 1-based.
        material: usize,
    },
    /// A patch that names a missing node or repeats a node.
    #[error("body '{body}': patch {patch} ({nodes:?}) {problem}")]
    BadPatch {
        /// Body name.
        body: String,
        /// The patch, 1-based.
        patch: usize,
        /// Its nodes as given.
        nodes: [usize; 3],
        /// What is wrong and what to do.
        problem: String,
    },
    /// A node that no member touches: it could move freely.
    #[error("body '{body}': node {node} belongs to no member, so nothing holds it: join it with members or remove it")]
    LooseNode {
        /// Body name.
        body: String,
        /// The node, 1-based.
        node: usize,
    },
    /// A body with no supports at all.
    #[error("body '{body}' has no supports, so it can move as a rigid body: add [[bodies.supports]] that hold it")]
    NoSupports {
        /// Body name.
        body: String,
    },
    /// A support or load on a node that does not exist.
    #[error("body '{body}': {what} names node {node}, but the body has {count} nodes")]
    TargetOutOfRange {
        /// Body name.
        body: String,
        /// What names it (a support, a load, a key).
        what: String,
        /// The node, 1-based.
        node: usize,
        /// Nodes the body has.
        count: usize,
    },
    /// A non-finite load, displacement or schedule, or a z component in 2D.
    #[error("body '{body}': {what}: {problem}")]
    BadValue {
        /// Body name.
        body: String,
        /// What names it (a support, a load, a key).
        what: String,
        /// What is wrong and what to do.
        problem: String,
    },
}

impl Body {
    /// An empty body.
    pub fn new(name: &str, dimension: Dimension) -> Self {
        Body {
            name: name.to_string(),
            dimension,
            ..Default::default()
        }
    }

    /// A body from a geometry whose members all use `material`.
    pub fn from_geometry(name: &str, geometry: Geometry, material: Material) -> Self {
        Body {
            name: name.to_string(),
            dimension: geometry.dimension,
            nodes: geometry.nodes,
            members: geometry
                .members
                .into_iter()
                .map(|nodes| Member { nodes, material: 0 })
                .collect(),
            patches: geometry.patches,
            materials: vec![material],
            ..Default::default()
        }
    }

    /// Member `m`'s Young's modulus as a fraction of its material's (see
    /// [`Body::member_factors`]).
    pub fn modulus_factor(&self, m: usize) -> Real {
        self.member_factors.get(m).copied().unwrap_or(1.0)
    }

    /// Member `m`'s Young's modulus, Pa: its material's times its factor.
    pub fn member_modulus(&self, m: usize) -> Real {
        self.materials[self.members[m].material].youngs_modulus * self.modulus_factor(m)
    }

    /// Number of degrees of freedom: nodes × (2 or 3).
    pub fn dof_count(&self) -> usize {
        self.nodes.len() * self.dimension.dofs_per_node()
    }

    /// Undeformed length of member `m`, m.
    pub fn member_length(&self, m: usize) -> Real {
        let [a, b] = self.members[m].nodes;
        (self.nodes[b] - self.nodes[a]).norm()
    }

    /// The diagonal of the bounding box of the nodes, m: the model's length scale.
    pub fn size(&self) -> Real {
        bounding_diagonal(&self.nodes)
    }

    /// Check everything that can be checked before solving; the first problem found is returned.
    pub fn validate(&self) -> Result<(), BodyError> {
        self.validate_held(true)
    }

    /// [`Body::validate`] for a body in time: inertia holds it, so it needs no supports.
    pub fn validate_moving(&self) -> Result<(), BodyError> {
        self.validate_held(false)
    }

    /// [`Body::validate`] for a body in a scene with contact: its contacts may hold it, so it
    /// needs no supports (where nothing holds it, the contact solver names the free motions).
    pub fn validate_touching(&self) -> Result<(), BodyError> {
        self.validate_held(false)
    }

    /// The checks of [`Body::validate`]; supports are required when `needs_supports`.
    fn validate_held(&self, needs_supports: bool) -> Result<(), BodyError> {
        let body = || self.name.clone();
        for m in &self.materials {
            if let Some(problem) = m.problem() {
                return Err(BodyError::Material {
                    body: body(),
                    material: m.name.clone(),
                    problem,
                });
            }
        }
        for (i, p) in self.nodes.iter().enumerate() {
            if let Some(v) = p.iter().find(|v| !v.is_finite()) {
                return Err(BodyError::NonFiniteNode {
                    body: body(),
                    node: i + 1,
                    value: *v,
                });
            }
            if self.dimension == Dimension::Two && p.z != 0.0 {
                return Err(BodyError::NodeOffPlane {
                    body: body(),
                    node: i + 1,
                    z: p.z,
                });
            }
        }
        check_members(&self.nodes, self.members.iter().map(|m| m.nodes))
            .map_err(|p| p.into_body_error(self))?;
        for (i, m) in self.members.iter().enumerate() {
            if m.material >= self.materials.len() {
                return Err(BodyError::MaterialOutOfRange {
                    body: body(),
                    member: i + 1,
                    material: m.material + 1,
                });
            }
        }
        for (i, m) in self.members.iter().enumerate() {
            let (material, length) = (&self.materials[m.material], self.member_length(i));
            let k = material.youngs_modulus * material.area / length;
            if !(k.is_finite() && k > 0.0) {
                return Err(BodyError::Material {
                    body: body(),
                    material: material.name.clone(),
                    problem: format!("member {} (nodes {} and {}, length {length:e} m) has the axial stiffness E A / L = {k:e} N/m, which is out of range: check the units of E, A and the coordinates", i + 1, m.nodes[0] + 1, m.nodes[1] + 1),
                });
            }
        }
        for (i, t) in self.patches.iter().enumerate() {
            let problem = if t.iter().any(|&n| n >= self.nodes.len()) {
                Some(format!(
                    "names a node beyond the {} nodes",
                    self.nodes.len()
                ))
            } else if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                Some("repeats a node: a patch needs three different nodes".to_string())
            } else {
                None
            };
            if let Some(problem) = problem {
                return Err(BodyError::BadPatch {
                    body: body(),
                    patch: i + 1,
                    nodes: t.map(|n| n + 1),
                    problem,
                });
            }
        }
        let mut touched = vec![false; self.nodes.len()];
        for m in &self.members {
            touched[m.nodes[0]] = true;
            touched[m.nodes[1]] = true;
        }
        if let Some(n) = touched.iter().position(|t| !t) {
            return Err(BodyError::LooseNode {
                body: body(),
                node: n + 1,
            });
        }
        if needs_supports && self.supports.iter().all(|s| !s.fixed.iter().any(|f| *f)) {
            return Err(BodyError::NoSupports { body: body() });
        }
        for (i, s) in self.supports.iter().enumerate() {
            let what = format!("support {} (node {})", i + 1, s.node + 1);
            self.check_target(&what, s.node)?;
            self.check_vector(&what, "displacement", &s.displacement)?;
            for d in 0..3 {
                if !s.fixed[d] && s.displacement[d] != 0.0 {
                    return Err(BodyError::BadValue {
                        body: body(),
                        what,
                        problem: format!(
                            "a displacement is prescribed in direction {} which the support does not fix: add it to `fix`",
                            ["x", "y", "z"][d]
                        ),
                    });
                }
            }
            self.check_schedule(&what, &s.schedule)?;
        }
        for (i, l) in self.loads.iter().enumerate() {
            let what = format!("load {} (node {})", i + 1, l.node + 1);
            self.check_target(&what, l.node)?;
            self.check_vector(&what, "force", &l.force)?;
            self.check_schedule(&what, &l.schedule)?;
        }
        self.check_pressures()?;
        self.check_newton()
    }

    /// Following pressures: on a body under large displacements along a schedule path, on
    /// faces of its dimension whose nodes exist and are joined by members (the load
    /// stiffness goes into the members' places of the tangent).
    fn check_pressures(&self) -> Result<(), BodyError> {
        use crate::linkage::PressureFaces;
        if self.pressures.is_empty() {
            return Ok(());
        }
        let bad = |what: String, problem: String| BodyError::BadValue {
            body: self.name.clone(),
            what,
            problem,
        };
        let mut pairs: Vec<(usize, usize)> = self
            .members
            .iter()
            .map(|m| (m.nodes[0].min(m.nodes[1]), m.nodes[0].max(m.nodes[1])))
            .collect();
        pairs.sort_unstable();
        for (k, p) in self.pressures.iter().enumerate() {
            let what = format!("pressure {}", k + 1);
            if self.kinematics != Kinematics::Large {
                return Err(bad(what, "a pressure that follows the deformation needs kinematics = \"large\"; on a linear body give it as nodal loads on the undeformed faces (pressure_loads_on)".to_string()));
            }
            if self.newton.path != PathMethod::Schedules {
                return Err(bad(what, "a pressure that follows the deformation is applied by its schedule, not along an arc length: use path = \"schedules\" or nodal loads".to_string()));
            }
            if !p.pressure.is_finite() {
                return Err(bad(what, format!("pressure {} is not finite", p.pressure)));
            }
            let fits = matches!(
                (&p.faces, self.dimension),
                (PressureFaces::Patches(_), Dimension::Three)
                    | (PressureFaces::Segments(_), Dimension::Two)
            );
            if !fits {
                return Err(bad(
                    what,
                    "a 3D body takes pressure on patches, a 2D body on boundary segments"
                        .to_string(),
                ));
            }
            self.check_schedule(&what, &p.schedule)?;
            for face in p.faces.nodes() {
                for &n in face {
                    self.check_target(&what, n)?;
                }
                for (i, &a) in face.iter().enumerate() {
                    let b = face[(i + 1) % face.len()];
                    if pairs.binary_search(&(a.min(b), a.max(b))).is_err() {
                        return Err(bad(what, format!("nodes {} and {} of a loaded face are not joined by a member: a following pressure needs every edge of its faces to be a member (its load stiffness acts between their nodes)", a + 1, b + 1)));
                    }
                }
            }
        }
        Ok(())
    }

    /// Whether this body needs the Newton solve: large kinematics, a path method other than the
    /// schedules, or members that act in tension or compression only.
    pub fn is_nonlinear(&self) -> bool {
        self.kinematics == Kinematics::Large
            || self.newton.path != PathMethod::Schedules
            || self
                .members
                .iter()
                .any(|m| self.materials[m.material].behaviour != crate::linkage::Behaviour::Elastic)
    }

    fn check_newton(&self) -> Result<(), BodyError> {
        let n = &self.newton;
        let bad = |problem: String| BodyError::BadValue {
            body: self.name.clone(),
            what: "[bodies.newton]".to_string(),
            problem,
        };
        let positive = |v: Real| v.is_finite() && v > 0.0;
        if !positive(n.tolerance) || n.tolerance >= 1.0 {
            return Err(bad(format!(
                "tolerance = {} must be between 0 and 1 (e.g. 1e-8)",
                n.tolerance
            )));
        }
        if !positive(n.displacement_tolerance) || n.displacement_tolerance >= 1.0 {
            return Err(bad(format!(
                "displacement_tolerance = {} must be between 0 and 1 (e.g. 1e-6)",
                n.displacement_tolerance
            )));
        }
        if n.max_iterations == 0 {
            return Err(bad("max_iterations must be at least 1".to_string()));
        }
        if let PathMethod::ArcLength { length } = n.path {
            if !positive(length) {
                return Err(BodyError::BadValue {
                    body: self.name.clone(),
                    what: "[bodies.path]".to_string(),
                    problem: format!("arc_length = {length} must be a finite positive length in m"),
                });
            }
            if self
                .supports
                .iter()
                .any(|s| s.displacement != Vector3::zeros())
            {
                return Err(BodyError::BadValue {
                    body: self.name.clone(),
                    what: "[bodies.path]".to_string(),
                    problem: "the arc-length method scales the loads only: prescribed support displacements are not allowed (use method = \"schedules\" for displacement control)".to_string(),
                });
            }
        }
        Ok(())
    }

    fn check_target(&self, what: &str, node: usize) -> Result<(), BodyError> {
        if node >= self.nodes.len() {
            return Err(BodyError::TargetOutOfRange {
                body: self.name.clone(),
                what: what.to_string(),
                node: node + 1,
                count: self.nodes.len(),
            });
        }
        Ok(())
    }

    fn check_vector(&self, what: &str, key: &str, v: &Vector3<Real>) -> Result<(), BodyError> {
        let problem = if v.iter().any(|c| !c.is_finite()) {
            Some(format!("{key} {:?} is not finite", v.as_slice()))
        } else if self.dimension == Dimension::Two && v.z != 0.0 {
            Some(format!("{key} has a z component in a 2D body"))
        } else {
            None
        };
        match problem {
            Some(problem) => Err(BodyError::BadValue {
                body: self.name.clone(),
                what: what.to_string(),
                problem,
            }),
            None => Ok(()),
        }
    }

    fn check_schedule(&self, what: &str, s: &Schedule) -> Result<(), BodyError> {
        if let Schedule::Factors(f) = s {
            if let Some(v) = f.iter().find(|v| !v.is_finite()) {
                return Err(BodyError::BadValue {
                    body: self.name.clone(),
                    what: what.to_string(),
                    problem: format!("schedule factor {v} is not finite"),
                });
            }
        }
        Ok(())
    }
}

/// What is wrong with one member of a list, by 0-based member index (see [`check_members`]).
#[derive(Debug, Clone, PartialEq)]
pub enum MemberProblem {
    /// A node index past the end.
    NodeOutOfRange {
        /// The member, 0-based.
        member: usize,
        /// The node index it names, 0-based.
        node: usize,
    },
    /// Both ends the same node.
    SelfMember {
        /// The member, 0-based.
        member: usize,
        /// The node, 0-based.
        node: usize,
    },
    /// The two nodes coincide.
    ZeroLength {
        /// The member, 0-based.
        member: usize,
        /// Its length, m.
        length: Real,
    },
    /// Coordinates so large that squaring them overflows: no length can be computed.
    TooLarge {
        /// The member, 0-based (the first one checked, when the body's size overflows).
        member: usize,
    },
    /// The same pair as an earlier member.
    Duplicate {
        /// The member, 0-based.
        member: usize,
        /// The earlier member joining the same nodes, 0-based.
        first: usize,
    },
}

impl MemberProblem {
    /// The member (0-based) the problem is about.
    pub fn member(&self) -> usize {
        match *self {
            MemberProblem::NodeOutOfRange { member, .. }
            | MemberProblem::SelfMember { member, .. }
            | MemberProblem::ZeroLength { member, .. }
            | MemberProblem::TooLarge { member }
            | MemberProblem::Duplicate { member, .. } => member,
        }
    }

    fn into_body_error(self, b: &Body) -> BodyError {
        let body = b.name.clone();
        let count = b.nodes.len();
        let ends = |m: usize| b.members[m].nodes.map(|n| n + 1);
        match self {
            MemberProblem::NodeOutOfRange { member, node } => BodyError::NodeOutOfRange {
                body,
                member: member + 1,
                node: node + 1,
                count,
            },
            MemberProblem::SelfMember { member, node } => BodyError::SelfMember {
                body,
                member: member + 1,
                node: node + 1,
            },
            MemberProblem::ZeroLength { member, length } => BodyError::ZeroLength {
                body,
                member: member + 1,
                a: ends(member)[0],
                b: ends(member)[1],
                length,
            },
            MemberProblem::TooLarge { member } => BodyError::TooLarge {
                body,
                member: member + 1,
                a: ends(member)[0],
                b: ends(member)[1],
            },
            MemberProblem::Duplicate { member, first } => BodyError::DuplicateMember {
                body,
                member: member + 1,
                first: first + 1,
                a: ends(member)[0],
                b: ends(member)[1],
            },
        }
    }
}

/// The diagonal of the bounding box of `points`, m (0 for none).
pub fn bounding_diagonal(points: &[Vector3<Real>]) -> Real {
    let mut lo = Vector3::repeat(Real::INFINITY);
    let mut hi = Vector3::repeat(Real::NEG_INFINITY);
    for p in points {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    if points.is_empty() {
        0.0
    } else {
        (hi - lo).norm()
    }
}

/// Prescribed displacement per body DOF, m (zero at free DOFs), with each support's schedule
/// weighted by `factor`. Supports are grouped by schedule as the linear solve groups them:
/// within one schedule a later support's value of a DOF replaces an earlier one's; different
/// schedules add up.
pub fn prescribed_displacements(body: &Body, factor: impl Fn(&Schedule) -> Real) -> Vec<Real> {
    let d = body.dimension.dofs_per_node();
    let mut patterns: Vec<(&Schedule, Vec<Real>)> = Vec::new();
    for s in &body.supports {
        if s.displacement == Vector3::zeros() {
            continue;
        }
        let p = match patterns.iter().position(|(sched, _)| *sched == &s.schedule) {
            Some(p) => p,
            None => {
                patterns.push((&s.schedule, vec![0.0; body.dof_count()]));
                patterns.len() - 1
            }
        };
        for k in 0..d {
            if s.fixed[k] {
                patterns[p].1[s.node * d + k] = s.displacement[k];
            }
        }
    }
    let mut u = vec![0.0; body.dof_count()];
    for (schedule, values) in patterns {
        let f = factor(schedule);
        for (a, b) in u.iter_mut().zip(values) {
            *a += f * b;
        }
    }
    u
}
