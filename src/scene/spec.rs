//! The scene file as written (TOML), before any checking beyond types: see `docs/SCENES.md`.
//! The types also serialize (the Python package's `Scene.to_dict`), leaving out absent keys.

use crate::Real;
use serde::{Deserialize, Serialize};
use toml::Spanned;

/// A whole scene file. Unknown keys are errors.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// Names the output folder `DIR/<name>/`.
    pub name: String,
    /// Number of load steps (≥ 1); loads reach full value at the last one.
    #[serde(default = "one")]
    pub steps: usize,
    /// Materials the bodies refer to by name.
    #[serde(default)]
    pub materials: Vec<Spanned<MaterialSpec>>,
    /// The deformable bodies.
    #[serde(default)]
    pub bodies: Vec<Spanned<BodySpec>>,
    /// Which steps to write.
    #[serde(default)]
    pub output: OutputSpec,
    /// Contact settings.
    pub contact: Option<Spanned<ContactSpec>>,
    /// Rigid obstacles.
    #[serde(default)]
    pub obstacles: Vec<Spanned<ObstacleSpec>>,
    /// `[sweep]`: expanded into variants before a batch reads them (`crate::scene::sweep`);
    /// a scene read on its own builds with the values written outside it.
    #[serde(default)]
    pub sweep: Option<toml::Value>,
    /// Acceleration of gravity, m/s² (one component per dimension): the self-weight of
    /// members whose material has a `density`, lumped to their end nodes.
    pub gravity: Option<Vec<Real>>,
    /// Factor of `gravity` per step 1..=steps (default: linear ramp, full weight at the last
    /// step), as a load's `schedule`.
    pub gravity_schedule: Option<Vec<Real>>,
    /// `[dynamics]`: the scene is solved in time, with inertia (see `docs/SCENES.md`).
    pub dynamics: Option<Spanned<DynamicsSpec>>,
}

/// `[dynamics]`: time integration settings.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct DynamicsSpec {
    /// Simulated time, s (> 0).
    pub duration: Real,
    /// The largest time step, s (> 0); halved where Newton needs it, regrown after.
    pub time_step: Real,
    /// Stored states after t = 0, evenly spaced in time (default: every time step).
    pub frames: Option<usize>,
    /// `"energy_momentum"` (default), `"newmark"`, `"generalized_alpha"` or `"backward_euler"`.
    pub integrator: Option<String>,
    /// Newmark β (default ¼), > 0.
    pub beta: Option<Real>,
    /// Newmark γ (default ½), ≥ ½.
    pub gamma: Option<Real>,
    /// Generalized-α spectral radius at infinite frequency ρ∞ (default 0.8), in [0, 1].
    pub rho_inf: Option<Real>,
    /// Rayleigh damping `{ mass = α (1/s), stiffness = β (s) }`.
    pub damping: Option<DampingSpec>,
}

/// `damping = { mass, stiffness }` of `[dynamics]`.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct DampingSpec {
    /// α, 1/s (≥ 0).
    pub mass: Option<Real>,
    /// β, s (≥ 0).
    pub stiffness: Option<Real>,
}

/// `[[bodies.velocities]]`: the initial velocity of selected nodes (a dynamic scene).
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct VelocitySpec {
    /// 1-based node numbers.
    pub nodes: Option<Vec<i64>>,
    /// See [`SelectorSpec`].
    pub nearest: Option<Vec<Real>>,
    /// See [`SelectorSpec`].
    pub inside: Option<BoxSpec>,
    /// See [`SelectorSpec`].
    pub on_line: Option<LineSpec>,
    /// See [`SelectorSpec`].
    pub on_plane: Option<PlaneSpec>,
    /// See [`SelectorSpec`].
    pub tolerance: Option<Real>,
    /// Initial velocity of each selected node, m/s, one component per direction.
    pub velocity: Vec<Real>,
}

/// `[contact]`: penalty and tolerances (see `docs/SCENES.md`).
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Penalty stiffness, N/m of penetration (default: 100 × the mean E A / L of the body).
    pub penalty: Option<Real>,
    /// Penetration warned about, m (default: 1% of the mean member length).
    pub tolerance: Option<Real>,
    /// Contact iterations per step (default 50).
    pub max_iterations: Option<usize>,
    /// Linear bodies factored once and condensed on their contact candidates (default true).
    pub condense: Option<bool>,
    /// Coulomb coefficient μ of every contact pair (default 0: frictionless).
    pub friction: Option<Real>,
    /// Tangential stiffness of sticking, N/m of elastic slip (default: the normal penalty).
    pub stick_stiffness: Option<Real>,
    /// Contact of every body with itself (`self = true`; default: bodies with breaking
    /// members only; `false`: none).
    #[serde(rename = "self")]
    pub self_contact: Option<bool>,
    /// Pairs with their own friction.
    #[serde(default)]
    pub pairs: Vec<Spanned<ContactPairSpec>>,
}

/// `[[contact.pairs]]`: friction between two named bodies or obstacles.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ContactPairSpec {
    /// The two names: bodies or obstacles.
    pub between: Vec<String>,
    /// Coulomb coefficient μ of the pair.
    pub friction: Option<Real>,
    /// Stick stiffness of the pair, N/m.
    pub stick_stiffness: Option<Real>,
}

/// `[[obstacles]]`: a rigid obstacle (see `docs/SCENES.md`).
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ObstacleSpec {
    /// Name, distinct from every body's and obstacle's name.
    pub name: String,
    /// `"half_space"`, `"cuboid"`, `"ball"`, `"cylinder"`, `"capsule"` or `"mesh"`.
    pub shape: String,
    /// A point on the boundary of a half-space, m.
    pub point: Option<Vec<Real>>,
    /// Outward normal of a half-space.
    pub normal: Option<Vec<Real>>,
    /// Centre of the other shapes, m.
    pub center: Option<Vec<Real>>,
    /// Half extents of a cuboid, m.
    pub half_extents: Option<Vec<Real>>,
    /// Radius of a ball, cylinder or capsule, m.
    pub radius: Option<Real>,
    /// Half length along the axis (local y) of a cylinder or capsule, m.
    pub half_height: Option<Real>,
    /// Rotation, degrees: about z in 2D (one number, `45.0` or `[45.0]`), a rotation vector
    /// (axis times angle) in 3D.
    #[serde(default, deserialize_with = "number_or_list")]
    pub rotation: Option<Vec<Real>>,
    /// Triangle mesh file of a `"mesh"` obstacle (OBJ, or ASCII or binary STL, m), relative to the scene.
    pub file: Option<String>,
    /// Translation reached at the last step, m.
    pub travel: Option<Vec<Real>>,
    /// Factor of the travel per step 1..=steps (default: linear ramp).
    pub schedule: Option<Vec<Real>>,
}

fn one() -> usize {
    1
}

/// A number or a list of numbers, as a list: `rotation = 45.0` is `[45.0]`.
fn number_or_list<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<Vec<Real>>, D::Error> {
    struct Visitor;
    impl<'de> serde::de::Visitor<'de> for Visitor {
        type Value = Vec<Real>;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("a number of degrees or a list of numbers")
        }
        fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Self::Value, E> {
            Ok(vec![v])
        }
        fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Self::Value, E> {
            Ok(vec![v as Real])
        }
        fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Self::Value, E> {
            Ok(vec![v as Real])
        }
        fn visit_seq<A: serde::de::SeqAccess<'de>>(
            self,
            mut seq: A,
        ) -> Result<Self::Value, A::Error> {
            let mut out = Vec::new();
            while let Some(x) = seq.next_element::<Real>()? {
                out.push(x);
            }
            Ok(out)
        }
    }
    d.deserialize_any(Visitor).map(Some)
}

/// `[[materials]]`: E, A and optional strengths.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Name referred to by bodies and links files.
    pub name: String,
    /// Young's modulus E, Pa.
    pub youngs_modulus: Real,
    /// Cross-section area A, m² (or `continuum_modulus`, not both).
    pub area: Option<Real>,
    /// Young's modulus the body should have as a solid, Pa: the members' area is chosen per
    /// body so that its uniaxial tests give it (instead of `area`; 3D bodies of this one
    /// material).
    pub continuum_modulus: Option<Real>,
    /// Strength in tension and compression, Pa.
    pub strength: Option<Real>,
    /// Strength in tension, Pa (overrides `strength`).
    pub tensile_strength: Option<Real>,
    /// Strength in compression as a positive number, Pa (overrides `strength`).
    pub compressive_strength: Option<Real>,
    /// `"elastic"` (default), `"tension_only"` (a cable) or `"compression_only"` (a strut).
    pub behaviour: Option<String>,
    /// Density ρ, kg/m³: members weigh ρ A L under the scene's `gravity` (none: weightless).
    pub density: Option<Real>,
    /// `"mark"` (default: members beyond their strength are only marked) or `"break"`.
    pub failure: Option<String>,
    /// `{ weibull_modulus, seed }`: each breaking member's strength drawn from a Weibull law.
    pub scatter: Option<ScatterSpec>,
    /// `{ fracture_energy, teeth }`: saw-tooth softening of breaking members.
    pub softening: Option<SofteningSpec>,
}

/// `softening = { fracture_energy = 100.0, teeth = 5 }` of a breaking material.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SofteningSpec {
    /// Fracture energy G_f, J/m² over the member's cross-section.
    pub fracture_energy: Real,
    /// Teeth of the saw-tooth, ≥ 1 (1: brittle).
    pub teeth: usize,
}

/// `scatter = { weibull_modulus = 12.0, seed = 7 }` of a breaking material.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ScatterSpec {
    /// Weibull modulus (shape), > 0.
    pub weibull_modulus: Real,
    /// Seed of the generator.
    pub seed: u64,
}

/// `[[bodies]]`: where the geometry comes from, its material, supports and loads.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// Unique name in the scene.
    pub name: String,
    /// Nodes file (paper format), relative to the scene file.
    pub nodes: Option<String>,
    /// Links file (paper format), relative to the scene file.
    pub links: Option<String>,
    /// Patches file (paper format), relative to the scene file.
    pub patches: Option<String>,
    /// Default material of the members.
    pub material: Option<String>,
    /// `"linear"` (the paper's model, default) or `"large"` (geometrically exact members).
    pub kinematics: Option<String>,
    /// Newton settings of a nonlinear body.
    pub newton: Option<NewtonSpec>,
    /// How the load path is followed (schedules or arc length).
    pub path: Option<PathSpec>,
    /// `"direct"`, `"iterative"` or `"auto"` (default).
    pub solver: Option<String>,
    /// Stopping rule of the iterative solver.
    pub iterative: Option<IterativeSpec>,
    /// Generated circular disk (paper Fig. 1).
    pub disk: Option<DiskSpec>,
    /// Generated 2D rectangular solid (paper Fig. 4–6).
    pub rectangle: Option<RectangleSpec>,
    /// Generated 3D cylindrical shell (paper Fig. 7).
    pub cylindrical_shell: Option<ShellSpec>,
    /// Generated 3D box lattice.
    pub box_lattice: Option<LatticeSpec>,
    /// A 3D body filled inside a closed triangle mesh (isosurface stuffing).
    pub mesh: Option<MeshSpec>,
    /// A 2D body triangulated inside an outline (constrained Delaunay, refined).
    pub outline: Option<OutlineSpec>,
    /// A model file read as the body, relative to the scene file: a gmsh mesh (`.msh`, MSH
    /// 4.1) or an Abaqus/CalculiX input file (`.inp`, with its materials, supports and loads).
    pub model: Option<String>,
    /// Translation of the body's nodes (from files or a generator), m: places bodies in a scene.
    pub offset: Option<Vec<Real>>,
    /// Supports.
    #[serde(default)]
    pub supports: Vec<Spanned<SupportSpec>>,
    /// Nodal loads.
    #[serde(default)]
    pub loads: Vec<Spanned<LoadSpec>>,
    /// Pressures on surface patches.
    #[serde(default)]
    pub pressures: Vec<Spanned<PressureSpec>>,
    /// Initial velocity of every node, m/s (a dynamic scene).
    pub velocity: Option<Vec<Real>>,
    /// Initial angular velocity about the body's centre of mass, rad/s: one number in 2D
    /// (about z), three in 3D (a dynamic scene).
    #[serde(default, deserialize_with = "number_or_list")]
    pub angular_velocity: Option<Vec<Real>>,
    /// Initial velocities of selected nodes, after `velocity` and `angular_velocity`.
    #[serde(default)]
    pub velocities: Vec<Spanned<VelocitySpec>>,
}

/// `[bodies.newton]`: convergence settings of the Newton solve (see `docs/SCENES.md`).
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct NewtonSpec {
    /// Relative out-of-balance force at convergence (default 1e-8).
    pub tolerance: Option<Real>,
    /// Relative size of the last displacement correction at convergence (default 1e-6).
    pub displacement_tolerance: Option<Real>,
    /// Newton iterations per increment before it is halved (default 30).
    pub max_iterations: Option<usize>,
    /// Smallest increment `1/2^max_cuts` of a step (default 10).
    pub max_cuts: Option<usize>,
}

/// `[bodies.iterative]`: when conjugate gradients stop (see `docs/SCENES.md`).
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct IterativeSpec {
    /// Relative residual at which a solve stops (default 1e-10).
    pub tolerance: Option<Real>,
    /// Iterations per solve before falling back to the direct solver (default 500).
    pub max_iterations: Option<usize>,
    /// Start each solve from the last solution (default true).
    pub warm_start: Option<bool>,
}

/// `[bodies.path]`: `method = "schedules"` (default) or `"arc_length"` with `arc_length` (m).
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PathSpec {
    /// `"schedules"` or `"arc_length"`.
    pub method: String,
    /// Arc length per step, m (arc-length method).
    pub arc_length: Option<Real>,
}

/// `disk = { radius, rings, sectors }`.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct DiskSpec {
    /// Radius, m.
    pub radius: Real,
    /// Rings of nodes around the centre (default 1).
    #[serde(default = "one")]
    pub rings: usize,
    /// Nodes per ring (default 8).
    #[serde(default = "eight")]
    pub sectors: usize,
}

fn eight() -> usize {
    8
}

/// `rectangle = { width, height, cells = [nx, ny] }`.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RectangleSpec {
    /// Extent in x, m.
    pub width: Real,
    /// Extent in y, m.
    pub height: Real,
    /// Cells in x and y.
    pub cells: [usize; 2],
}

/// `cylindrical_shell = { radius, length, rings, sectors }`.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ShellSpec {
    /// Radius, m.
    pub radius: Real,
    /// Length along x, m.
    pub length: Real,
    /// Rings of nodes along the axis (≥ 2).
    pub rings: usize,
    /// Nodes per ring (≥ 3).
    pub sectors: usize,
}

/// `box_lattice = { size = [x, y, z], cells = [nx, ny, nz] }`.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LatticeSpec {
    /// Extent, m.
    pub size: [Real; 3],
    /// Cells per direction.
    pub cells: [usize; 3],
}

/// `mesh = { file, spacing }`: a closed OBJ or STL mesh (m) filled with members.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MeshSpec {
    /// The mesh file, relative to the scene file.
    pub file: String,
    /// Target member length, m.
    pub spacing: Real,
}

/// `outline = { file | points, spacing }`: a 2D polygon with holes (m).
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct OutlineSpec {
    /// A file of loops (one `x y` per line, a blank line between loops), relative to the scene.
    pub file: Option<String>,
    /// The outside loop's points, m (no holes).
    pub points: Option<Vec<[Real; 2]>>,
    /// Target member length, m.
    pub spacing: Real,
}

/// Which nodes a support or load applies to: exactly one of the selector keys.
#[derive(Debug, Deserialize, Serialize, Default)]
#[serde(deny_unknown_fields)]
pub struct SelectorSpec {
    /// 1-based node numbers.
    pub nodes: Option<Vec<i64>>,
    /// The one node nearest this point, m.
    pub nearest: Option<Vec<Real>>,
    /// Every node inside this axis-aligned box (bounds included, widened by `tolerance`).
    pub inside: Option<BoxSpec>,
    /// Every node within `tolerance` of this line.
    pub on_line: Option<LineSpec>,
    /// Every node within `tolerance` of this plane.
    pub on_plane: Option<PlaneSpec>,
    /// Distance within which a node counts as on a line, plane or box, m (default 1e-6 of the body size).
    pub tolerance: Option<Real>,
    /// The nodes of a named group of the body's model file (a gmsh physical group, an INP
    /// `*NSET` or `*ELSET`).
    pub group: Option<String>,
}

/// `inside = { min = [..], max = [..] }`, m.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BoxSpec {
    /// Lower corner, m.
    pub min: Vec<Real>,
    /// Upper corner, m.
    pub max: Vec<Real>,
}

/// `on_line = { point = [..], direction = [..] }`.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LineSpec {
    /// A point of the line, m.
    pub point: Vec<Real>,
    /// Its direction (any length).
    pub direction: Vec<Real>,
}

/// `on_plane = { point = [..], normal = [..] }`.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PlaneSpec {
    /// A point of the plane, m.
    pub point: Vec<Real>,
    /// Its normal (any length).
    pub normal: Vec<Real>,
}

/// `[[bodies.supports]]`.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SupportSpec {
    /// A name for `[output] plot = { support = "NAME" }` (unique in the scene; optional).
    pub name: Option<String>,
    /// 1-based node numbers.
    pub nodes: Option<Vec<i64>>,
    /// See [`SelectorSpec`].
    pub nearest: Option<Vec<Real>>,
    /// See [`SelectorSpec`].
    pub inside: Option<BoxSpec>,
    /// See [`SelectorSpec`].
    pub on_line: Option<LineSpec>,
    /// See [`SelectorSpec`].
    pub on_plane: Option<PlaneSpec>,
    /// See [`SelectorSpec`].
    pub tolerance: Option<Real>,
    /// See [`SelectorSpec`].
    pub group: Option<String>,
    /// Held directions: any of "x", "y", "z".
    pub fix: Vec<String>,
    /// Prescribed displacement at full schedule, m, one component per direction of the body;
    /// only fixed directions may be non-zero.
    pub displacement: Option<Vec<Real>>,
    /// Factor per step 1..=steps (default: linear ramp).
    pub schedule: Option<Vec<Real>>,
}

/// `[[bodies.loads]]`.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LoadSpec {
    /// 1-based node numbers.
    pub nodes: Option<Vec<i64>>,
    /// See [`SelectorSpec`].
    pub nearest: Option<Vec<Real>>,
    /// See [`SelectorSpec`].
    pub inside: Option<BoxSpec>,
    /// See [`SelectorSpec`].
    pub on_line: Option<LineSpec>,
    /// See [`SelectorSpec`].
    pub on_plane: Option<PlaneSpec>,
    /// See [`SelectorSpec`].
    pub tolerance: Option<Real>,
    /// See [`SelectorSpec`].
    pub group: Option<String>,
    /// Force per selected node at full schedule, N.
    pub force: Option<Vec<Real>>,
    /// Total force shared equally by the selected nodes at full schedule, N.
    pub total_force: Option<Vec<Real>>,
    /// Factor per step 1..=steps (default: linear ramp).
    pub schedule: Option<Vec<Real>>,
}

/// `[[bodies.pressures]]`: a pressure on every patch whose three nodes the selector chooses.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PressureSpec {
    /// 1-based node numbers.
    pub nodes: Option<Vec<i64>>,
    /// See [`SelectorSpec`].
    pub nearest: Option<Vec<Real>>,
    /// See [`SelectorSpec`].
    pub inside: Option<BoxSpec>,
    /// See [`SelectorSpec`].
    pub on_line: Option<LineSpec>,
    /// See [`SelectorSpec`].
    pub on_plane: Option<PlaneSpec>,
    /// See [`SelectorSpec`].
    pub tolerance: Option<Real>,
    /// See [`SelectorSpec`].
    pub group: Option<String>,
    /// Pressure at full schedule, Pa (positive pushes into the body).
    pub pressure: Real,
    /// Factor per step 1..=steps (default: linear ramp).
    pub schedule: Option<Vec<Real>>,
}

/// `[output]`: which steps are written, pictures and VTK files.
#[derive(Debug, Deserialize, Serialize, Default)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Write every k-th step (step 0 and the last are always written); default 1.
    pub every: Option<usize>,
    /// Write only the last step (and step 0).
    #[serde(default)]
    pub last_only: bool,
    /// Step and model files: `"json"` or `"npz"` (default: JSON up to
    /// [`crate::scene::NPZ_ABOVE_MEMBERS`] members, `.npz` above).
    pub format: Option<String>,
    /// Pictures and VTK files: see [`crate::scene::PictureSettings`].
    pub png: Option<bool>,
    /// Animated GIF (default: as `png`).
    pub gif: Option<bool>,
    /// ParaView files.
    pub vtk: Option<bool>,
    /// glTF 2.0 animation, `anim.glb`.
    pub gltf: Option<bool>,
    /// How ParaView files store their arrays: `"binary"` (default) or `"ascii"`.
    pub vtk_format: Option<String>,
    /// Frame width, pixels.
    pub width: Option<u32>,
    /// Frame height, pixels.
    pub height: Option<u32>,
    /// Displacement magnification (default automatic).
    pub magnification: Option<Real>,
    /// Camera azimuth, degrees.
    pub azimuth: Option<Real>,
    /// Camera elevation, degrees.
    pub elevation: Option<Real>,
    /// What colours members and surfaces: "stress" (default), "max-stress" or "plain".
    pub colour: Option<String>,
    /// The axis pictures draw upwards: "x", "y" (default) or "z"; the scene's `gravity`,
    /// when given, decides instead (up is opposite it).
    pub up: Option<String>,
    /// The node (1-based) whose displacement the load–displacement plot shows (default: the
    /// largest displacement of any node); see [`crate::scene::PlotSettings`].
    pub plot_node: Option<usize>,
    /// The body of `plot_node` (default: the first body).
    pub plot_body: Option<String>,
    /// The obstacle whose push is the load: the load–displacement plot shows the force the
    /// bodies receive from it against its travel.
    pub plot_obstacle: Option<String>,
    /// The place whose force the load–displacement plot shows against its displacement: a
    /// named support, or nodes of a body.
    pub plot: Option<PlotSpec>,
}

/// `[output] plot = { support = "NAME" }` or `plot = { body = "NAME", nodes = [..] }`.
#[derive(Debug, Deserialize, Serialize, Default)]
#[serde(deny_unknown_fields)]
pub struct PlotSpec {
    /// A support's `name`.
    pub support: Option<String>,
    /// The body of `nodes` (default: the first body).
    pub body: Option<String>,
    /// 1-based node numbers of `body`.
    pub nodes: Option<Vec<i64>>,
}

macro_rules! selector_of {
    ($t:ty) => {
        impl $t {
            /// The selector keys of this entry.
            pub fn selector(&self) -> SelectorSpec {
                SelectorSpec {
                    nodes: self.nodes.clone(),
                    nearest: self.nearest.clone(),
                    inside: self.inside.clone(),
                    on_line: self.on_line.clone(),
                    on_plane: self.on_plane.clone(),
                    tolerance: self.tolerance,
                    ..SelectorSpec::default()
                }
            }
        }
    };
    // An entry that may also choose a model file's `group`.
    ($t:ty, group) => {
        impl $t {
            /// The selector keys of this entry.
            pub fn selector(&self) -> SelectorSpec {
                SelectorSpec {
                    nodes: self.nodes.clone(),
                    nearest: self.nearest.clone(),
                    inside: self.inside.clone(),
                    on_line: self.on_line.clone(),
                    on_plane: self.on_plane.clone(),
                    tolerance: self.tolerance,
                    group: self.group.clone(),
                }
            }
        }
    };
}
selector_of!(SupportSpec, group);
selector_of!(LoadSpec, group);
selector_of!(PressureSpec, group);
selector_of!(VelocitySpec);
