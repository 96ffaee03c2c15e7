//! What one run needs, built and checked from a scene file: bodies, obstacles, contact and output settings.

use crate::contact::{ContactSettings, Obstacle};
use crate::linkage::{Body, Interrupt, Schedule};
use crate::scene::{PictureSettings, PlotSettings, ResultFormat};
use crate::Real;
use std::path::PathBuf;

/// Which stored steps are written to `steps/NNNN.json` (or `.npz`), and in which format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OutputSettings {
    /// Write every k-th step (≥ 1).
    pub every: usize,
    /// Write only step 0 and the last step.
    pub last_only: bool,
    /// JSON or NumPy `.npz` step and model files (`[output] format`).
    pub format: ResultFormat,
}

impl Default for OutputSettings {
    fn default() -> Self {
        OutputSettings {
            every: 1,
            last_only: false,
            format: ResultFormat::Json,
        }
    }
}

impl OutputSettings {
    /// Whether `step` of `steps` is written: step 0 and the last always are.
    pub fn writes(&self, step: usize, steps: usize) -> bool {
        step == 0 || step == steps || (!self.last_only && step.is_multiple_of(self.every))
    }
}

/// Everything one run needs, built and checked from a scene file: plain data.
#[derive(Clone, Debug, PartialEq)]
pub struct World {
    /// Scene name: the output folder.
    pub name: String,
    /// Number of load steps; in a dynamic scene the stored frames after t = 0.
    pub steps: usize,
    /// `[dynamics]`: the scene is solved in time (`None`: quasi-static load steps).
    pub dynamics: Option<crate::scene::dynamics_settings::DynamicsSettings>,
    /// The deformable bodies.
    pub bodies: Vec<Body>,
    /// Rigid obstacles (`[[obstacles]]`).
    pub obstacles: Vec<Obstacle>,
    /// What building the world changed that a user may want to know (mesh faces turned
    /// outward), as `linkage check` says it.
    pub found: Vec<String>,
    /// What the scene asks that a user may not have meant, known before solving (a `nearest`
    /// node far from its point, a load partly on held directions), each with the scene file
    /// and line: `linkage check` prints them, `linkage run` puts them in step 0's warnings.
    pub warnings: Vec<String>,
    /// Contact settings (`[contact]`).
    pub contact: ContactSettings,
    /// Whether the scene has a `[contact]` table (contact between its bodies is looked for).
    pub contact_table: bool,
    /// Which steps to write.
    pub output: OutputSettings,
    /// Pictures and VTK files to write.
    pub pictures: PictureSettings,
    /// What the plots drawn with the pictures show (`[output] plot_node`).
    pub plots: PlotSettings,
    /// The scene file it came from.
    pub source: PathBuf,
    /// [`crate::scene::scene_digest`] of the text it was built from (a sweep's variant: its
    /// generated text), written to `summary.json`.
    pub scene_digest: String,
    /// The quality report of each body prepared from a mesh or an outline, by body name.
    pub prepared: std::collections::BTreeMap<String, crate::linkage::prepare::PrepareReport>,
    /// The elasticity as a solid of each body whose material gives `continuum_modulus`, by body
    /// name: its uniaxial tests with the area chosen ([`crate::linkage::homogenize`]).
    pub solids: std::collections::BTreeMap<String, crate::linkage::homogenize::EffectiveElasticity>,
    /// Wall time of building it: parsing the scene, reading its files, generating or
    /// preparing its bodies, s (`phases.reading` of `summary.json`).
    pub build_seconds: crate::Real,
}

impl World {
    /// Make every solve of this world stop between iterations once `interrupt` is raised: it
    /// goes into each body's [`crate::linkage::NewtonSettings`], where the body solvers, the
    /// contact loops and fracture's events read it (and the driver and the drawing, through
    /// [`World::interrupt`]).
    pub fn set_interrupt(&mut self, interrupt: Interrupt) {
        for body in &mut self.bodies {
            body.newton.interrupt = interrupt;
        }
    }

    /// The interrupt the world's solves read (see [`World::set_interrupt`]; never raised by
    /// default).
    pub fn interrupt(&self) -> Interrupt {
        self.bodies
            .first()
            .map(|b| b.newton.interrupt)
            .unwrap_or_default()
    }

    /// Whether the scene is solved with contact: it has obstacles or a `[contact]` table. All
    /// its bodies are then solved together, step by step ([`crate::contact::ContactSolver`]).
    pub fn has_contact(&self) -> bool {
        !self.obstacles.is_empty() || self.contact_table
    }

    /// The load factor reported for `step`: the common schedule's factor when every load,
    /// pressure and prescribed displacement of the scene follows one schedule ([`common_schedule`]), else
    /// `step / steps` (the step fraction).
    pub fn load_factor(&self, step: usize) -> Real {
        common_schedule(&self.bodies)
            .unwrap_or(&Schedule::Linear)
            .factor(step, self.steps)
    }

    /// The model's size in one line, as `linkage check` prints it: bodies, nodes, members,
    /// patches, DOFs and load steps.
    pub fn describe(&self) -> String {
        self.size_line(None)
    }

    /// The model's size in one line as `linkage run` prints it: [`World::describe`] with the
    /// free DOFs (the summary's `free_dofs`, summed over the bodies) after the DOFs, as in
    /// "1224 DOFs (1152 free)".
    pub fn describe_solved(&self, free_dofs: usize) -> String {
        self.size_line(Some(free_dofs))
    }

    fn size_line(&self, free_dofs: Option<usize>) -> String {
        let nodes: usize = self.bodies.iter().map(|b| b.nodes.len()).sum();
        let members: usize = self.bodies.iter().map(|b| b.members.len()).sum();
        let patches: usize = self.bodies.iter().map(|b| b.patches.len()).sum();
        let dofs: usize = self.bodies.iter().map(|b| b.dof_count()).sum();
        let free = free_dofs
            .map(|f| format!(" ({f} free)"))
            .unwrap_or_default();
        format!(
            "{} bod{}, {nodes} nodes, {members} members, {patches} patches, {dofs} DOFs{free}, {} step{}",
            self.bodies.len(),
            if self.bodies.len() == 1 { "y" } else { "ies" },
            self.steps,
            if self.steps == 1 { "" } else { "s" }
        )
    }
}

/// The one schedule every load, pressure and prescribed displacement of `bodies` follows;
/// `None` when they follow different ones or there is none: the results' load factor is then
/// the step fraction (`step / steps`, or `t / duration` in time), which pictures and plots call
/// so.
pub fn common_schedule(bodies: &[Body]) -> Option<&Schedule> {
    let mut schedules = bodies.iter().flat_map(|b| {
        b.loads
            .iter()
            .map(|l| &l.schedule)
            .chain(b.pressures.iter().map(|p| &p.schedule))
            .chain(
                b.supports
                    .iter()
                    .filter(|s| s.displacement.norm() > 0.0)
                    .map(|s| &s.schedule),
            )
    });
    let first = schedules.next()?;
    schedules.all(|s| s == first).then_some(first)
}
