//! From a scene file to a checked [`World`]: every problem is reported with the file and line.

use crate::contact::Obstacle;
use crate::linkage::generators;
use crate::linkage::homogenize::{continuum_volume, fit_continuum_modulus};
use crate::linkage::prepare::PrepareReport;
use crate::linkage::{
    Behaviour, Body, Dimension, Failure, Geometry, Interrupt, Kinematics, Material, Member,
    NewtonSettings, NodalLoad, PathMethod, Scatter, Schedule, Softening, SolverChoice,
    SolverSettings, Support,
};
use crate::scene::bounds::{check_lengths, MAX_LENGTH};
use crate::scene::contact_pairs::friction_settings;
use crate::scene::dynamics_settings::{dynamics_from, initial_velocity, BodyStart, VelocitySource};
use crate::scene::import::{read_model, NodeGroup};
use crate::scene::inline_files::InlineFiles;
use crate::scene::obstacles::{contact_settings, obstacle_from};
use crate::scene::paper_files::{self, PaperFileError};
use crate::scene::plot_settings::NamedSupport;
use crate::scene::prepared_body::prepared_geometry;
use crate::scene::pressures::add_pressure;
use crate::scene::selector::{far_nearest_warning, select_nodes_in, vector};
use crate::scene::spec::{BodySpec, MaterialSpec, SceneSpec};
use crate::scene::{OutputSettings, PictureSettings, PlotSettings, ResultFormat, World};
use std::path::{Path, PathBuf};
use toml::Spanned;

/// Why a scene cannot be built. Every variant names the file; most name the line.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The scene file cannot be read.
    #[error("{path}: cannot read the scene file: {source}")]
    Read {
        /// Scene file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// TOML syntax, an unknown key or a wrong type (the message has line and column).
    #[error("{path}: {message}")]
    Parse {
        /// Scene file.
        path: PathBuf,
        /// toml's message.
        message: String,
    },
    /// A value that is the right type but cannot be used.
    #[error("{path}:{line}: {message}")]
    At {
        /// Scene file.
        path: PathBuf,
        /// 1-based line of the entry.
        line: usize,
        /// What is wrong and what to do.
        message: String,
    },
    /// A problem in one of the paper's files a body reads, with the scene line naming the file.
    #[error("{}:{line}: body '{body}': {source}", .path.display())]
    PaperFile {
        /// Scene file.
        path: PathBuf,
        /// 1-based line of the key that names the file (`nodes`, `links`, `patches`).
        line: usize,
        /// The body reading it.
        body: String,
        /// The problem in the file.
        source: PaperFileError,
    },
}

/// The 1-based line of the key a `message` is about, within the table whose span starts at
/// byte `start` of `text` (its header line, or the top of the file): the key named earliest
/// in the message (as `` `key` ``, `key =` or `[table.key]`), else the table's first line.
fn key_line(text: &str, start: usize, message: &str) -> usize {
    let start = start.min(text.len());
    let first = text[..start].matches('\n').count() + 1;
    let mut keys: Vec<(String, usize)> = Vec::new();
    for (k, raw) in text[start..].lines().enumerate() {
        let line = raw.trim_start();
        if line.starts_with('[') {
            if k == 0 {
                continue;
            }
            break;
        }
        if let Some((key, _)) = line.split_once('=') {
            let key = key.trim().trim_matches('"').to_string();
            if !key.is_empty() && !key.starts_with('#') {
                keys.push((key, first + k));
            }
        }
    }
    keys.iter()
        .filter_map(|(key, line)| {
            [
                format!("`{key}`"),
                format!("`{key}."),
                format!("{key} ="),
                format!(".{key}]"),
            ]
            .iter()
            .filter_map(|p| message.find(p.as_str()))
            .min()
            .map(|at| (at, *line))
        })
        .min()
        .map_or(first, |(_, line)| line)
}

/// The keys of a body's table that a validation error of the body is about, most likely
/// first, as [`key_line`] reads them (those the body does not have are passed over; with none
/// the error points at the body's header).
fn body_error_keys(e: &crate::linkage::BodyError) -> &'static str {
    use crate::linkage::BodyError as E;
    match e {
        E::Material { .. } | E::MaterialOutOfRange { .. } => "`material` `links`",
        E::NonFiniteNode { .. } | E::NodeOffPlane { .. } => {
            "`nodes` `offset` `mesh` `outline` `model`"
        }
        E::NodeOutOfRange { .. }
        | E::SelfMember { .. }
        | E::ZeroLength { .. }
        | E::TooLarge { .. }
        | E::DuplicateMember { .. } => "`links` `nodes` `mesh` `outline` `model`",
        E::BadPatch { .. } => "`patches`",
        E::LooseNode { .. } => "`links` `nodes` `mesh` `model`",
        _ => "",
    }
}

/// Byte offset of the `[output]` header in `text` (0 without one).
fn output_start(text: &str) -> usize {
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        if line.trim_start().starts_with("[output]") {
            return offset;
        }
        offset += line.len();
    }
    0
}

/// Read, parse and check a scene file.
pub fn load_scene(path: &Path) -> Result<World, SceneError> {
    let text = std::fs::read_to_string(path).map_err(|source| SceneError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    build_world(&text, path)
}

/// Parse and check scene `text` that was read from `path` (relative file names resolve
/// against its folder).
pub fn build_world(text: &str, path: &Path) -> Result<World, SceneError> {
    build_world_with(text, path, &InlineFiles::default())
}

/// [`build_world`], reading the paper's files (`nodes`, `links`, `patches`) held in `files`
/// instead of the disk where `files` has their path (the Python package's bodies from arrays).
pub fn build_world_with(text: &str, path: &Path, files: &InlineFiles) -> Result<World, SceneError> {
    build_world_from(text, path, files, Interrupt::default())
}

/// [`build_world`], stopped by `stop` (a run's interrupt: SIGINT, SIGTERM) while a body is
/// prepared from a mesh: then an error saying so. The world's solves do not read `stop`: give it
/// to them with [`World::set_interrupt`].
pub fn build_world_until(text: &str, path: &Path, stop: Interrupt) -> Result<World, SceneError> {
    build_world_from(text, path, &InlineFiles::default(), stop)
}

/// [`build_world_with`] and [`build_world_until`] in one.
fn build_world_from(
    text: &str,
    path: &Path,
    files: &InlineFiles,
    stop: Interrupt,
) -> Result<World, SceneError> {
    let started = std::time::Instant::now();
    let spec: SceneSpec = toml::from_str(text).map_err(|e| SceneError::Parse {
        path: path.to_path_buf(),
        message: crate::scene::toml_error::scene_toml_message(text, &e),
    })?;
    let at = |span: std::ops::Range<usize>, message: String| SceneError::At {
        path: path.to_path_buf(),
        line: key_line(text, span.start, &message),
        message,
    };
    let top = 0..0;
    let output_span = output_start(text)..output_start(text);
    if spec.name.is_empty()
        || spec.name.starts_with('.')
        || !spec
            .name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "_-.".contains(c))
    {
        return Err(at(
            top,
            format!(
                "name = {:?} names the output folder: use letters, digits, '_', '-' and '.' (not first)",
                spec.name
            ),
        ));
    }
    if spec.steps == 0 {
        return Err(at(
            top,
            "steps = 0: a scene needs at least 1 load step".to_string(),
        ));
    }
    let output = OutputSettings {
        every: match spec.output.every {
            Some(0) => {
                return Err(at(
                    output_span,
                    "[output] every = 0: give 1 or more".to_string(),
                ))
            }
            Some(k) => k,
            None => 1,
        },
        last_only: spec.output.last_only,
        format: ResultFormat::Json,
    };
    let format = match spec.output.format.as_deref() {
        None => None,
        Some(f) => Some(ResultFormat::parse(f).ok_or_else(|| {
            at(
                output_span.clone(),
                format!("[output] format = {f:?}: use \"json\" or \"npz\" (NumPy arrays, for large models)"),
            )
        })?),
    };
    let mut pictures =
        PictureSettings::from_spec(&spec.output).map_err(|e| at(output_span.clone(), e))?;
    if let Some(g) = &spec.gravity {
        pictures.up_against(g);
    }

    let mut materials = Vec::new();
    for m in &spec.materials {
        let material = material_from(m.get_ref()).map_err(|e| at(m.span(), e))?;
        if materials.iter().any(|o: &Material| o.name == material.name) {
            return Err(at(
                m.span(),
                format!("material '{}' is defined twice", material.name),
            ));
        }
        materials.push(material);
    }
    let density = densities(&spec).map_err(|(span, e)| at(span, e))?;
    let mut dynamics = match &spec.dynamics {
        Some(d) => Some(dynamics_from(d.get_ref()).map_err(|e| at(d.span(), e))?),
        None => None,
    };
    if let Some(d) = &spec.dynamics {
        let stiffness_damping = dynamics
            .as_ref()
            .is_some_and(|d| d.damping.stiffness != 0.0);
        if (!spec.obstacles.is_empty() || spec.contact.is_some()) && stiffness_damping {
            return Err(at(
                d.span(),
                "[dynamics] damping.stiffness with contact (obstacles or a [contact] table) is not supported: the contact solver takes mass-proportional damping only. Use damping.mass, or the integrator's numerical damping (integrator = \"generalized_alpha\", rho_inf < 1)".to_string(),
            ));
        }
    }
    if spec.bodies.is_empty() {
        return Err(at(
            top,
            "the scene has no [[bodies]]: add at least one".to_string(),
        ));
    }
    let folder = path.parent().unwrap_or(Path::new("."));
    let mut bodies: Vec<Body> = Vec::new();
    let mut prepared = std::collections::BTreeMap::new();
    let mut solids = std::collections::BTreeMap::new();
    let mut warnings = Vec::new();
    let mut found = Vec::new();
    let mut named_supports: Vec<NamedSupport> = Vec::new();
    for b in &spec.bodies {
        let mut notes = BodyNotes::default();
        let steps = match &dynamics {
            Some(_) => None,
            None => Some(spec.steps),
        };
        let mut body = build_body(
            b,
            &materials,
            (text, path, files, stop),
            steps,
            &at,
            &mut notes,
        )?;
        // The solid a prepared body models is the mesh given; any other body's, what its
        // patches enclose (or its bounding box).
        let volume = match (&notes.report, body.dimension) {
            (Some(r), Dimension::Three) => r.reference,
            _ => continuum_volume(&body),
        };
        let fitted = fit_continuum_modulus(&mut body, volume).map_err(|e| {
            let line = key_line(text, b.span().start, "`material`");
            SceneError::At {
                path: path.to_path_buf(),
                line,
                message: e.to_string(),
            }
        })?;
        if let Some(r) = notes.report.as_mut() {
            r.solid = fitted;
        }
        if let Some(f) = fitted {
            solids.insert(body.name.clone(), f);
        }
        if let Some(r) = notes.report {
            prepared.insert(body.name.clone(), r);
        }
        found.extend(notes.found);
        warnings.extend(notes.warnings);
        for mut s in notes.named_supports {
            if named_supports
                .iter()
                .any(|o: &NamedSupport| o.name == s.name)
            {
                return Err(at(
                    b.span(),
                    format!(
                        "support '{}' is named twice: support names must differ in the scene",
                        s.name
                    ),
                ));
            }
            s.body_index = bodies.len();
            named_supports.push(s);
        }
        // A model file's materials follow the scene's, with their densities.
        let density: Vec<Option<crate::Real>> =
            density.iter().copied().chain(notes.densities).collect();
        if bodies.iter().any(|o| o.name == body.name) {
            return Err(at(
                b.span(),
                format!(
                    "body '{}' is defined twice: body names must differ",
                    body.name
                ),
            ));
        }
        // Inertia (a dynamic scene) or contact (obstacles, a [contact] table) may hold a
        // body without supports.
        let valid = match dynamics {
            Some(_) => body.validate_moving(),
            None if !spec.obstacles.is_empty() || spec.contact.is_some() => {
                body.validate_touching()
            }
            None => body.validate(),
        };
        valid.map_err(|e| {
            let message = e.to_string();
            SceneError::At {
                path: path.to_path_buf(),
                // The key the problem is in, not the body's header line.
                line: key_line(
                    text,
                    b.span().start,
                    &format!("{} {message}", body_error_keys(&e)),
                ),
                message,
            }
        })?;
        add_self_weight(&mut body, &spec, &density, dynamics.is_some()).map_err(|e| at(0..0, e))?;
        if let Some(d) = dynamics.as_mut() {
            d.bodies.push(body_start(b, &body, &spec, &density, &at)?);
        }
        bodies.push(body);
    }
    let contact = contact_settings(spec.contact.as_ref().map(|c| c.get_ref()))
        .map_err(|e| at(spec.contact.as_ref().map_or(0..0, |c| c.span()), e))?;
    let mut obstacles: Vec<Obstacle> = Vec::new();
    for o in &spec.obstacles {
        let dimension = bodies[0].dimension;
        if bodies.iter().any(|b| b.dimension != dimension) {
            return Err(at(
                o.span(),
                "obstacles need all bodies of one dimension (all 2D or all 3D)".to_string(),
            ));
        }
        let (obstacle, note) = obstacle_from(
            o.get_ref(),
            dimension,
            dynamics.is_none().then_some(spec.steps),
            &bodies,
            folder,
        )
        .map_err(|e| at(o.span(), e))?;
        found.extend(note);
        if obstacles.iter().any(|p| p.name == obstacle.name) {
            return Err(at(
                o.span(),
                format!(
                    "obstacle '{}' is defined twice: names must differ",
                    obstacle.name
                ),
            ));
        }
        obstacles.push(obstacle);
    }
    let mut contact = contact;
    if let Some(c) = &spec.contact {
        let names: Vec<&str> = bodies
            .iter()
            .map(|b| b.name.as_str())
            .chain(obstacles.iter().map(|o| o.name.as_str()))
            .collect();
        contact.friction =
            friction_settings(c.get_ref(), &names, c.span()).map_err(|(span, e)| at(span, e))?;
    }
    let obstacle_names: Vec<&str> = obstacles.iter().map(|o| o.name.as_str()).collect();
    let plots = PlotSettings::from_spec(&spec.output, &bodies, &obstacle_names, &named_supports)
        .map_err(|e| at(output_span, e))?;
    let members = bodies.iter().map(|b| b.members.len()).sum();
    let output = OutputSettings {
        format: format.unwrap_or(ResultFormat::default_for(members)),
        ..output
    };
    Ok(World {
        obstacles,
        found,
        warnings,
        contact,
        contact_table: spec.contact.is_some(),
        name: spec.name,
        steps: dynamics.as_ref().map_or(spec.steps, |d| d.frames),
        dynamics,
        bodies,
        output,
        pictures,
        plots,
        source: path.to_path_buf(),
        scene_digest: crate::scene::scene_and_files_digest(text, folder),
        prepared,
        solids,
        build_seconds: started.elapsed().as_secs_f64(),
    })
}

/// Each material's density (kg/m³), checked: finite and not negative.
fn densities(
    spec: &SceneSpec,
) -> Result<Vec<Option<crate::Real>>, (std::ops::Range<usize>, String)> {
    spec.materials
        .iter()
        .map(|m| match m.get_ref().density {
            Some(rho) if !(rho.is_finite() && rho >= 0.0) => Err((
                m.span(),
                format!(
                    "material '{}': density = {rho} kg/m³: give a finite density of 0 or more",
                    m.get_ref().name
                ),
            )),
            d => Ok(d),
        })
        .collect()
}

/// The scene's `gravity` on `body`'s members of a material with a density, as nodal loads
/// on `gravity_schedule` (default: linear, full weight at the last step).
fn add_self_weight(
    body: &mut Body,
    spec: &SceneSpec,
    density: &[Option<crate::Real>],
    dynamic: bool,
) -> Result<(), String> {
    let Some(g) = &spec.gravity else {
        if spec.gravity_schedule.is_some() {
            return Err(
                "gravity_schedule is given without gravity: add gravity = [...] (m/s²)".to_string(),
            );
        }
        return Ok(());
    };
    let g =
        vector(g, body.dimension, "gravity").map_err(|e| format!("body '{}': {e}", body.name))?;
    if g.iter().any(|v| !v.is_finite()) {
        return Err(format!("gravity = {g:?}: give finite numbers in m/s²"));
    }
    let schedule = match &spec.gravity_schedule {
        None if dynamic => Schedule::Factors(vec![1.0]),
        Some(f) if dynamic && f.is_empty() => {
            return Err("gravity_schedule is empty: give at least one factor (factors stand at equally spaced times over [dynamics] duration)".to_string())
        }
        Some(f) if dynamic && f.iter().all(|v| v.is_finite()) => Schedule::Factors(f.clone()),
        None => Schedule::Linear,
        Some(f) if f.len() != spec.steps => {
            return Err(format!(
            "gravity_schedule has {} factors but the scene has {} steps: give one factor per step",
            f.len(),
            spec.steps
        ))
        }
        Some(f) if f.iter().any(|v| !v.is_finite()) => {
            return Err(format!("gravity_schedule = {f:?}: give finite factors"))
        }
        Some(f) => Schedule::Factors(f.clone()),
    };
    let loads = crate::linkage::self_weight_loads(body, density, g, &schedule);
    body.loads.extend(loads);
    Ok(())
}

fn material_from(m: &MaterialSpec) -> Result<Material, String> {
    if m.name.trim().is_empty() {
        return Err(
            "[[materials]] `name` is empty: give the material a name (bodies and links files use it)"
                .to_string(),
        );
    }
    // Strengths are checked under the key the user wrote.
    for (key, value) in [
        ("strength", m.strength),
        ("tensile_strength", m.tensile_strength),
        ("compressive_strength", m.compressive_strength),
    ] {
        if let Some(v) = value {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!(
                    "material '{}': {key} = {v} must be a finite positive number of Pa",
                    m.name
                ));
            }
        }
    }
    let area = match (m.area, m.continuum_modulus) {
        (Some(a), None) => a,
        (None, Some(e)) if e.is_finite() && e > 0.0 => 1.0,
        (None, Some(e)) => {
            return Err(format!(
                "material '{}': continuum_modulus = {e} must be a finite positive number of Pa",
                m.name
            ))
        }
        (Some(_), Some(_)) => {
            return Err(format!(
                "material '{}': give either `area` (m², the members' cross-section) or `continuum_modulus` (Pa, the modulus the body should have as a solid: the area is then chosen per body), not both",
                m.name
            ))
        }
        (None, None) => {
            return Err(format!(
                "material '{}': give `area` (m², the members' cross-section) or `continuum_modulus` (Pa, the modulus a 3D body of this material should have as a solid)",
                m.name
            ))
        }
    };
    let material = Material {
        name: m.name.clone(),
        youngs_modulus: m.youngs_modulus,
        area,
        continuum_modulus: m.continuum_modulus,
        tensile_strength: m.tensile_strength.or(m.strength),
        compressive_strength: m.compressive_strength.or(m.strength),
        behaviour: match m.behaviour.as_deref() {
            None | Some("elastic") => Behaviour::Elastic,
            Some("tension_only") => Behaviour::TensionOnly,
            Some("compression_only") => Behaviour::CompressionOnly,
            Some(other) => {
                return Err(format!(
                    "material '{}': behaviour = {other:?}: use \"elastic\", \"tension_only\" (a cable) or \"compression_only\" (a strut)",
                    m.name
                ))
            }
        },
        scatter: m.scatter.as_ref().map(|s| Scatter {
            weibull_modulus: s.weibull_modulus,
            seed: s.seed,
        }),
        softening: m.softening.as_ref().map(|s| Softening {
            fracture_energy: s.fracture_energy,
            teeth: s.teeth,
        }),
        failure: match m.failure.as_deref() {
            None | Some("mark") => Failure::Mark,
            Some("break") => Failure::Break,
            Some(other) => {
                return Err(format!(
                    "material '{}': failure = {other:?}: use \"mark\" (overloaded members are only marked) or \"break\" (they break)",
                    m.name
                ))
            }
        },
    };
    if material.scatter.is_some() && material.failure != Failure::Break {
        return Err(format!(
            "material '{}': scatter is for breaking members: add failure = \"break\" or remove scatter",
            m.name
        ));
    }
    if material.softening.is_some() && material.failure != Failure::Break {
        return Err(format!(
            "material '{}': softening is for breaking members: add failure = \"break\" or remove softening",
            m.name
        ));
    }
    if material.softening.is_some() && material.tensile_strength.is_none() {
        return Err(format!(
            "material '{}': softening softens members in tension: give strength or tensile_strength in Pa",
            m.name
        ));
    }
    if material.failure == Failure::Break
        && material.tensile_strength.is_none()
        && material.compressive_strength.is_none()
    {
        return Err(format!(
            "material '{}': failure = \"break\" needs a strength: give strength (or tensile_strength, compressive_strength) in Pa",
            m.name
        ));
    }
    match material.problem() {
        Some(p) => Err(format!("material '{}': {p}", m.name)),
        None => Ok(material),
    }
}

/// `[bodies.newton]` and `[bodies.path]` over the defaults.
fn newton_settings(spec: &BodySpec) -> Result<NewtonSettings, String> {
    let mut settings = NewtonSettings::default();
    if let Some(n) = &spec.newton {
        settings.tolerance = n.tolerance.unwrap_or(settings.tolerance);
        settings.displacement_tolerance = n
            .displacement_tolerance
            .unwrap_or(settings.displacement_tolerance);
        settings.max_iterations = n.max_iterations.unwrap_or(settings.max_iterations);
        settings.max_cuts = n.max_cuts.unwrap_or(settings.max_cuts);
    }
    if let Some(p) = &spec.path {
        settings.path = match (p.method.as_str(), p.arc_length) {
            ("schedules", None) => PathMethod::Schedules,
            ("arc_length", Some(length)) => PathMethod::ArcLength { length },
            ("arc_length", None) => {
                return Err("[bodies.path] method = \"arc_length\" needs `arc_length` (m): the length of one step along the path".to_string())
            }
            ("schedules", Some(_)) => {
                return Err("[bodies.path] `arc_length` goes with method = \"arc_length\"".to_string())
            }
            (other, _) => {
                return Err(format!(
                    "[bodies.path] method = {other:?}: use \"schedules\" (load and displacement control) or \"arc_length\""
                ))
            }
        };
    }
    Ok(settings)
}

/// Which generator keys a body gives, in the order `disk`, `rectangle`, `cylindrical_shell`,
/// `box_lattice`, `mesh`, `outline`.
fn generated_by(spec: &BodySpec) -> [bool; 6] {
    [
        spec.disk.is_some(),
        spec.rectangle.is_some(),
        spec.cylindrical_shell.is_some(),
        spec.box_lattice.is_some(),
        spec.mesh.is_some(),
        spec.outline.is_some(),
    ]
}

/// The first node (0-based) with a coordinate beyond [`MAX_LENGTH`] (or not finite), and that
/// coordinate.
fn beyond_bound(nodes: &[nalgebra::Vector3<crate::Real>]) -> Option<(usize, crate::Real)> {
    nodes.iter().enumerate().find_map(|(n, p)| {
        p.iter()
            .find(|v| !v.is_finite() || v.abs() > MAX_LENGTH)
            .map(|v| (n, *v))
    })
}

/// What building one body tells besides the body.
#[derive(Default)]
struct BodyNotes {
    /// The quality report of a body prepared from a mesh or an outline.
    report: Option<PrepareReport>,
    /// Densities (kg/m³) of the materials a model file adds after the scene's, in order.
    densities: Vec<Option<crate::Real>>,
    /// What a model file held but the body does not use, for `linkage check`.
    found: Vec<String>,
    /// Slips found while building the body (a far `nearest` point, a load partly on held
    /// directions), for the run's warnings.
    warnings: Vec<String>,
    /// The supports with a `name` (for `[output] plot`).
    named_supports: Vec<NamedSupport>,
}

fn build_body(
    spanned: &Spanned<BodySpec>,
    materials: &[Material],
    (text, scene, files, stop): (&str, &Path, &InlineFiles, Interrupt),
    steps: Option<usize>,
    at: &dyn Fn(std::ops::Range<usize>, String) -> SceneError,
    notes: &mut BodyNotes,
) -> Result<Body, SceneError> {
    let folder = scene.parent().unwrap_or(Path::new("."));
    let spec = spanned.get_ref();
    let here = |message: String| at(spanned.span(), format!("body '{}': {message}", spec.name));
    if spec.name.trim().is_empty() {
        return Err(here(
            "`name` is empty: give the body a name (results and messages use it)".to_string(),
        ));
    }
    // A paper file the body reads: missing files are reported at the key naming them, problems
    // inside them with the scene line too.
    let paper_file = |key: &str, file: &str| -> Result<PathBuf, SceneError> {
        let full = folder.join(file);
        if files.get(&full).is_none() && !full.is_file() {
            return Err(here(format!(
                "`{key}` = {file:?}: there is no file {}: file names are relative to the folder of the scene file",
                full.display()
            )));
        }
        Ok(full)
    };
    let in_file = |key: &str| {
        let line = key_line(text, spanned.span().start, &format!("`{key}`"));
        move |source: PaperFileError| SceneError::PaperFile {
            path: scene.to_path_buf(),
            line,
            body: spec.name.clone(),
            source,
        }
    };
    let kinematics = match spec.kinematics.as_deref() {
        None | Some("linear") => Kinematics::Linear,
        Some("large") => Kinematics::Large,
        Some(other) => {
            return Err(here(format!(
                "kinematics = {other:?} is not available: use \"linear\" (the paper's model) or \"large\" (large displacements)"
            )))
        }
    };
    let newton = newton_settings(spec).map_err(here)?;
    let mut solver = SolverSettings {
        choice: match spec.solver.as_deref() {
            None | Some("auto") => SolverChoice::Auto,
            Some("direct") => SolverChoice::Direct,
            Some("iterative") => SolverChoice::Iterative,
            Some(other) => {
                return Err(here(format!(
                    "solver = {other:?} is not available: use \"direct\", \"iterative\" or \"auto\""
                )))
            }
        },
        ..Default::default()
    };
    if let Some(it) = &spec.iterative {
        if let Some(t) = it.tolerance {
            if !(t.is_finite() && t > 0.0 && t < 1.0) {
                return Err(here(format!(
                    "[bodies.iterative] tolerance = {t}: give a relative residual between 0 and 1, e.g. 1e-10"
                )));
            }
            solver.iterative.tolerance = t;
        }
        if let Some(m) = it.max_iterations {
            if m == 0 {
                return Err(here(
                    "[bodies.iterative] max_iterations = 0: give 1 or more".to_string(),
                ));
            }
            solver.iterative.max_iterations = m;
        }
        if let Some(w) = it.warm_start {
            solver.iterative.warm_start = w;
        }
    }
    if solver.choice == SolverChoice::Iterative && newton.path != PathMethod::Schedules {
        return Err(here(
            "solver = \"iterative\" cannot follow an arc-length path (it counts the tangent's negative pivots, which needs a factorization): use solver = \"direct\" or \"auto\"".to_string(),
        ));
    }
    if newton.path != PathMethod::Schedules {
        solver.choice = SolverChoice::Direct;
    }
    let material_index = |name: &str| materials.iter().position(|m| m.name == name);
    let default_material = match &spec.material {
        Some(name) => Some(material_index(name).ok_or_else(|| {
            here(format!(
                "material '{name}' is not defined: add a [[materials]] entry named '{name}'"
            ))
        })?),
        None if materials.len() == 1 => Some(0),
        None => None,
    };
    let need_default = || {
        here(if materials.is_empty() {
            "no material: add a [[materials]] entry and name it with `material =`".to_string()
        } else {
            "give `material = \"...\"`: the scene has several materials".to_string()
        })
    };

    let generated = generated_by(spec).iter().filter(|g| **g).count();
    let from_files = spec.nodes.is_some() || spec.links.is_some();
    if generated + usize::from(from_files) + usize::from(spec.model.is_some()) != 1 {
        return Err(here(
            "give the geometry either as files (`nodes` and `links`, optionally `patches`), as a `model` file (.msh, .inp) or as exactly one generator (`disk`, `rectangle`, `cylindrical_shell`, `box_lattice`, `mesh`, `outline`)".to_string(),
        ));
    }
    // Named node groups of a model file, for `group =` selectors.
    let mut groups: Vec<NodeGroup> = Vec::new();
    let mut body = Body::new(&spec.name, Dimension::Two);
    body.materials = materials.to_vec();
    body.kinematics = kinematics;
    body.newton = newton;
    body.solver = solver;
    if let Some(file) = &spec.model {
        if spec.patches.is_some() {
            return Err(here(
                "`patches` goes with `nodes` and `links` files, not with `model` (the model file gives the patches)".to_string(),
            ));
        }
        let full = paper_file("model", file)?;
        let model = read_model(&full).map_err(|e| here(format!("`model` = {file:?}: {e}")))?;
        if let Some((n, v)) = beyond_bound(&model.geometry.nodes) {
            return Err(here(format!(
                "`model` = {file:?}: node {} has the coordinate {v:e}, too large to square (lengths and contact forces would overflow): give coordinates in metres, within ±{MAX_LENGTH:e}",
                n + 1
            )));
        }
        // The model's own materials (INP sections), unless the scene names one for all.
        let first_own = body.materials.len();
        let own = spec.material.is_none() && !model.materials.is_empty();
        if own {
            for m in &model.materials {
                if materials.iter().any(|o| o.name == m.name) {
                    return Err(here(format!(
                        "`model` = {file:?} defines material '{}', as does a [[materials]] entry: rename one, or give `material = ...` to use a scene material for every member",
                        m.name
                    )));
                }
                let material = Material::new(&m.name, m.youngs_modulus, m.area);
                if let Some(p) = material.problem() {
                    return Err(here(format!(
                        "`model` = {file:?}: material '{}': {p}",
                        m.name
                    )));
                }
                body.materials.push(material);
                notes.densities.push(m.density);
            }
        }
        body.members.reserve_exact(model.geometry.members.len());
        for (k, &nodes) in model.geometry.members.iter().enumerate() {
            let material = match model.member_materials.get(k).copied().flatten() {
                Some(i) if own => first_own + i,
                _ => match default_material {
                    Some(m) => m,
                    None => {
                        return Err(match &model.unassigned {
                            Some(u) if own => here(format!("`model` = {file:?}: {u}")),
                            _ => need_default(),
                        })
                    }
                },
            };
            body.members.push(Member { nodes, material });
        }
        for s in &model.supports {
            body.supports.push(Support {
                node: s.node,
                fixed: s.fixed,
                displacement: s.displacement,
                schedule: Schedule::Linear,
            });
        }
        for &(node, force) in &model.loads {
            body.loads.push(NodalLoad {
                node,
                force,
                schedule: Schedule::Linear,
            });
        }
        notes.found.extend(
            model
                .warnings
                .iter()
                .map(|w| format!("body '{}': `model`: {w}", spec.name)),
        );
        body.dimension = model.geometry.dimension;
        body.nodes = model.geometry.nodes;
        body.patches = model.geometry.patches;
        groups = model.groups;
    } else if from_files {
        let (Some(nodes_file), Some(links_file)) = (&spec.nodes, &spec.links) else {
            return Err(here(
                "a body read from files needs both `nodes` and `links`".to_string(),
            ));
        };
        let nodes_path = paper_file("nodes", nodes_file)?;
        let links_path = paper_file("links", links_file)?;
        let (dimension, nodes) = match files.get(&nodes_path) {
            Some(held) => paper_files::parse_nodes(held, &nodes_path),
            None => paper_files::read_nodes(&nodes_path),
        }
        .map_err(in_file("nodes"))?;
        // Lengths square coordinate differences: past about 1e154 they overflow.
        if let Some((n, v)) = beyond_bound(&nodes) {
            return Err(here(format!(
                "`nodes` = {nodes_file:?}: node {} has the coordinate {v:e}, too large to square (lengths and contact forces would overflow): give coordinates in metres, within ±{MAX_LENGTH:e}",
                n + 1
            )));
        }
        let links = match files.get(&links_path) {
            Some(held) => paper_files::parse_links(held, &links_path, &nodes),
            None => paper_files::read_links(&links_path, &nodes),
        }
        .map_err(in_file("links"))?;
        body.members.reserve_exact(links.len());
        for link in &links {
            let material = match &link.material {
                Some(name) => material_index(name).ok_or_else(|| {
                    in_file("links")(PaperFileError::Line {
                        path: links_path.clone(),
                        line: link.line,
                        message: format!(
                            "material '{name}' is not defined in the scene: add a [[materials]] entry named '{name}'"
                        ),
                    })
                })?,
                None => default_material.ok_or_else(need_default)?,
            };
            body.members.push(Member {
                nodes: link.nodes,
                material,
            });
        }
        if let Some(patches_file) = &spec.patches {
            let patches_path = paper_file("patches", patches_file)?;
            body.patches = match files.get(&patches_path) {
                Some(held) => paper_files::parse_patches(held, &patches_path, nodes.len()),
                None => paper_files::read_patches(&patches_path, nodes.len()),
            }
            .map_err(in_file("patches"))?;
        }
        body.dimension = dimension;
        body.nodes = nodes;
    } else {
        if spec.patches.is_some() {
            return Err(here(
                "`patches` goes with `nodes` and `links` files, not with a generator".to_string(),
            ));
        }
        if let Some(why) = crate::scene::fits_machine::generator_refusal(spec) {
            return Err(here(why));
        }
        let prepared = prepared_geometry(spec, folder, stop).map_err(&here)?;
        let geometry: Geometry = if let Some(p) = prepared {
            notes.report = Some(p.report);
            Ok(p.geometry)
        } else if let Some(g) = &spec.disk {
            generators::disk(g.radius, g.rings, g.sectors)
        } else if let Some(g) = &spec.rectangle {
            generators::rectangle(g.width, g.height, g.cells[0], g.cells[1])
        } else if let Some(g) = &spec.cylindrical_shell {
            generators::cylindrical_shell(g.radius, g.length, g.rings, g.sectors)
        } else if let Some(g) = &spec.box_lattice {
            generators::box_lattice(g.size, g.cells)
        } else {
            unreachable!("exactly one generator was counted above")
        }
        .map_err(|e| here(e.to_string()))?;
        let material = default_material.ok_or_else(need_default)?;
        body.dimension = geometry.dimension;
        body.nodes = geometry.nodes;
        body.members = geometry
            .members
            .into_iter()
            .map(|nodes| Member { nodes, material })
            .collect();
        body.patches = geometry.patches;
    }
    if body.dimension == Dimension::Two && !body.patches.is_empty() {
        return Err(here(
            "patches are for 3D bodies; this body's nodes have 2 coordinates".to_string(),
        ));
    }
    let generator = crate::scene::toml_error::GENERATORS
        .iter()
        .copied()
        .zip(generated_by(spec))
        .find_map(|(key, g)| g.then_some(key));
    if let (Some(key), Some((n, v))) = (generator, beyond_bound(&body.nodes)) {
        return Err(here(format!(
            "`{key}` places node {} at the coordinate {v:e} m, too large to square (lengths and contact forces would overflow): give sizes in metres, within ±{MAX_LENGTH:e}",
            n + 1
        )));
    }
    if let Some(offset) = &spec.offset {
        let shift = vector(offset, body.dimension, "offset")
            .and_then(|v| check_lengths(&v, "offset"))
            .map_err(&here)?;
        body.nodes.iter_mut().for_each(|p| *p += shift);
        if let Some((n, v)) = beyond_bound(&body.nodes) {
            return Err(here(format!(
                "`offset` moves node {} to the coordinate {v:e} m, too large to square (lengths and contact forces would overflow): keep the body within ±{MAX_LENGTH:e} m",
                n + 1
            )));
        }
    }

    // In a dynamic scene (`steps` None) a schedule's factors stand at equally spaced times over
    // the duration; without one a load is full from t = 0 and a support displacement is covered
    // at constant speed.
    let dynamic_default =
        |load: bool| Schedule::Factors(if load { vec![1.0] } else { vec![0.0, 1.0] });
    let schedule_of = |s: &Option<Vec<f64>>, load: bool| -> Result<Schedule, String> {
        match (s, steps) {
            (None, None) => Ok(dynamic_default(load)),
            (None, Some(_)) => Ok(Schedule::Linear),
            (Some(f), None) if f.is_empty() => Err(
                "`schedule` is empty: give at least one factor (they stand at equally spaced times over [dynamics] duration)".to_string(),
            ),
            (Some(f), None) => Ok(Schedule::Factors(f.clone())),
            (Some(f), Some(steps)) if f.len() != steps => Err(format!(
                "`schedule` has {} factors but the scene has {steps} steps: give one factor per step",
                f.len()
            )),
            (Some(f), Some(_)) => Ok(Schedule::Factors(f.clone())),
        }
    };
    if steps.is_some() {
        let key = if spec.velocity.is_some() {
            Some("velocity")
        } else if spec.angular_velocity.is_some() {
            Some("angular_velocity")
        } else if !spec.velocities.is_empty() {
            Some("velocities")
        } else {
            None
        };
        if let Some(key) = key {
            return Err(here(format!(
                "`{key}` is an initial velocity, for a scene solved in time: add a [dynamics] table (duration, time_step) or remove it"
            )));
        }
    }
    let d = body.dimension.dofs_per_node();
    for s in &spec.supports {
        let sp = s.get_ref();
        let fail = |m: String| at(s.span(), format!("body '{}': support: {m}", spec.name));
        let nodes = select_nodes_in(&sp.selector(), &body, &groups).map_err(fail)?;
        notes.warnings.extend(
            far_nearest_warning(&sp.selector(), &body, &nodes).map(|w| fail(w).to_string()),
        );
        if sp.fix.is_empty() {
            return Err(fail(
                "`fix` is empty: list the held directions, e.g. fix = [\"x\", \"y\"]".to_string(),
            ));
        }
        let mut fixed = [false; 3];
        for dir in &sp.fix {
            let k = match dir.as_str() {
                "x" => 0,
                "y" => 1,
                "z" if d == 3 => 2,
                "z" => return Err(fail("`fix` names \"z\" but the body is 2D".to_string())),
                other => {
                    return Err(fail(format!(
                        "`fix` names {other:?}: use \"x\", \"y\" or \"z\""
                    )))
                }
            };
            fixed[k] = true;
        }
        let displacement = match &sp.displacement {
            Some(v) => vector(v, body.dimension, "displacement").map_err(fail)?,
            None => nalgebra::Vector3::zeros(),
        };
        if let Some(k) = (0..3).find(|&k| !fixed[k] && displacement[k] != 0.0) {
            return Err(fail(format!(
                "`displacement` is non-zero in direction {} which is not in `fix`",
                ["x", "y", "z"][k]
            )));
        }
        let schedule = schedule_of(&sp.schedule, false).map_err(fail)?;
        if let Some(name) = &sp.name {
            notes.named_supports.push(NamedSupport {
                name: name.clone(),
                body: spec.name.clone(),
                body_index: 0,
                nodes: nodes.clone(),
                displacement: [displacement.x, displacement.y, displacement.z],
            });
        }
        for node in nodes {
            body.supports.push(Support {
                node,
                fixed,
                displacement,
                schedule: schedule.clone(),
            });
        }
    }
    for l in &spec.loads {
        let lp = l.get_ref();
        let fail = |m: String| at(l.span(), format!("body '{}': load: {m}", spec.name));
        let nodes = select_nodes_in(&lp.selector(), &body, &groups).map_err(fail)?;
        notes.warnings.extend(
            far_nearest_warning(&lp.selector(), &body, &nodes).map(|w| fail(w).to_string()),
        );
        let force = match (&lp.force, &lp.total_force) {
            (Some(f), None) => vector(f, body.dimension, "force").map_err(fail)?,
            (None, Some(f)) => {
                vector(f, body.dimension, "total_force").map_err(fail)? / nodes.len() as f64
            }
            _ => {
                return Err(fail(
                    "give exactly one of `force` (per node) and `total_force` (shared), in N"
                        .to_string(),
                ))
            }
        };
        let key = if lp.force.is_some() {
            "force"
        } else {
            "total_force"
        };
        let total = force * nodes.len() as f64;
        if !(force.norm().is_finite() && total.norm().is_finite()) {
            return Err(fail(format!(
                "`{key}` overflows: its magnitude (over {} node{}) is too large to compute with; give forces in N below about 1e150",
                nodes.len(),
                if nodes.len() == 1 { "" } else { "s" }
            )));
        }
        // A load in a direction a support fixes goes straight into the reaction. Nodes the user
        // named must not be loaded so; a line, plane or box may take in a supported node with
        // the others, but not only such nodes.
        let held = |node: usize| {
            body.supports
                .iter()
                .filter(|s| s.node == node)
                .fold([false; 3], |acc, s| [0, 1, 2].map(|k| acc[k] || s.fixed[k]))
        };
        let absorbed = |node: usize| (0..d).find(|&k| held(node)[k] && force[k] != 0.0);
        let named = lp.nodes.is_some() || lp.nearest.is_some();
        let all_absorbed = nodes
            .iter()
            .all(|&n| (0..d).all(|k| force[k] == 0.0 || held(n)[k]));
        if let Some((node, k)) = nodes
            .iter()
            .find_map(|&n| absorbed(n).map(|k| (n, k)))
            .filter(|_| named || all_absorbed)
        {
            return Err(fail(format!(
                "`{key}` pushes node {} in {}, which a support fixes: that load goes straight into the reaction and moves nothing; remove the node from the load or the direction from the support's `fix`",
                node + 1,
                ["x", "y", "z"][k]
            )));
        }
        let lost: Vec<(usize, nalgebra::Vector3<crate::Real>)> = nodes
            .iter()
            .map(|&n| {
                let h = held(n);
                (
                    n,
                    force.map_with_location(|k, _, f| if h[k] { f } else { 0.0 }),
                )
            })
            .filter(|(_, f)| *f != nalgebra::Vector3::zeros())
            .collect();
        notes.warnings.extend(
            partly_held_warning(key, force, nodes.len(), &lost, d).map(|w| fail(w).to_string()),
        );
        let schedule = schedule_of(&lp.schedule, true).map_err(fail)?;
        for node in nodes {
            body.loads.push(NodalLoad {
                node,
                force,
                schedule: schedule.clone(),
            });
        }
    }
    for p in &spec.pressures {
        let fail = |m: String| at(p.span(), format!("body '{}': pressure: {m}", spec.name));
        let schedule = schedule_of(&p.get_ref().schedule, true).map_err(fail)?;
        add_pressure(&mut body, p.get_ref(), schedule, &groups).map_err(fail)?;
    }
    Ok(body)
}

/// The warning of a load of `force` per node (N) on `count` nodes, `lost` of which have it
/// partly on directions a support holds (per node, 0-based, the part held, N): that part goes
/// straight into the reactions. Names the nodes (the first 8), what they lose, the total
/// lost and what the free nodes carry; `None` when nothing is lost.
fn partly_held_warning(
    key: &str,
    force: nalgebra::Vector3<crate::Real>,
    count: usize,
    lost: &[(usize, nalgebra::Vector3<crate::Real>)],
    d: usize,
) -> Option<String> {
    if lost.is_empty() {
        return None;
    }
    let shown: Vec<String> = lost
        .iter()
        .take(8)
        .map(|(n, _)| (n + 1).to_string())
        .collect();
    let more = if lost.len() > 8 { ", …" } else { "" };
    let total_lost: nalgebra::Vector3<crate::Real> = lost.iter().map(|(_, f)| f).sum();
    let applied = force * count as crate::Real;
    let carried = applied - total_lost;
    let v = |f: nalgebra::Vector3<crate::Real>| format!("{:?}", &f.as_slice()[..d]);
    Some(format!(
        "`{key}` puts {} N on each of {count} nodes, and {} of them (node{} {}{more}) are held by a support in a direction it pushes: {} N of the {} N in all goes straight into the reactions and moves nothing; the free nodes carry {} N. Leave the held nodes out of the selector (a smaller box, line or plane) or, with `total_force`, give the force the free nodes should share",
        v(force),
        lost.len(),
        if lost.len() == 1 { "" } else { "s" },
        shown.join(", "),
        v(total_lost),
        v(applied),
        v(carried),
    ))
}

/// A dynamic scene's body: its lumped mass (a material without density is reported at its
/// `[[materials]]` entry) and initial velocity (reported at the key or entry that gives it).
fn body_start(
    spanned: &Spanned<BodySpec>,
    body: &Body,
    spec: &SceneSpec,
    density: &[Option<crate::Real>],
    at: &dyn Fn(std::ops::Range<usize>, String) -> SceneError,
) -> Result<BodyStart, SceneError> {
    let mass = crate::linkage::dynamics::lumped_mass(body, density).map_err(|e| {
        let span = match &e {
            crate::linkage::dynamics::MassError::NoDensity { material, .. } => spec
                .materials
                .iter()
                .find(|m| &m.get_ref().name == material)
                .map_or(spanned.span(), |m| m.span()),
            _ => spanned.span(),
        };
        at(span, format!("{e}; add `density` to the material"))
    })?;
    let velocity = initial_velocity(spanned.get_ref(), body, &mass).map_err(|(source, e)| {
        let span = match source {
            VelocitySource::Body => spanned.span(),
            VelocitySource::Entry(k) => spanned.get_ref().velocities[k].span(),
        };
        at(span, format!("body '{}': {e}", body.name))
    })?;
    Ok(BodyStart { mass, velocity })
}
