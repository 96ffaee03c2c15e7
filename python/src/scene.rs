//! `Scene`: a scene file's text (and, for bodies from arrays, the texts of their paper files),
//! built and checked into the library's `World` when it is made, run in memory or into a
//! results folder.

use crate::convert::{dict_to_table, kwargs_into, table_to_dict, to_toml};
use crate::errors::{scene_error, SceneError};
use crate::model::{Body, Material};
use crate::results::Results;
use crate::solve::run_world;
use linkage::scene::spec::SceneSpec;
use linkage::scene::{build_world_with, with_values, InlineFiles, World};
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use toml::{Table, Value};

/// A scene: what a scene file says, checked and ready to run.
#[pyclass(module = "linkage", frozen)]
pub struct Scene {
    /// The scene's TOML.
    text: String,
    /// The file it was read from, or would be written to: relative file names resolve against
    /// its folder, and messages name it.
    path: PathBuf,
    /// Paper files held in memory (bodies from arrays), by name relative to `path`'s folder.
    files: Vec<(String, String)>,
    /// The checked world.
    world: Arc<World>,
}

/// The held files keyed by the path the scene's keys resolve to.
fn inline_files(path: &Path, files: &[(String, String)]) -> InlineFiles {
    let folder = path.parent().unwrap_or(Path::new("."));
    let mut held = InlineFiles::default();
    for (name, text) in files {
        held.insert(folder.join(name), text.clone());
    }
    held
}

/// The current folder joined with `name` (a scene made in Python resolves relative files
/// against the current folder).
fn here(name: &str) -> PathBuf {
    std::env::current_dir()
        .unwrap_or_else(|_| PathBuf::from("."))
        .join(name)
}

impl Scene {
    /// Build and check `text` (read from `path`) with the held `files`, the GIL released.
    fn build(
        py: Python<'_>,
        text: String,
        path: PathBuf,
        files: Vec<(String, String)>,
    ) -> PyResult<Self> {
        let world = py.detach(|| build_world_with(&text, &path, &inline_files(&path, &files)));
        let world = world.map_err(|e| scene_error(&e))?;
        Ok(Scene {
            text,
            path,
            files,
            world: Arc::new(world),
        })
    }

    /// A table as scene text, with a SceneError naming `path` when TOML cannot hold it.
    fn text_of(table: &Table, path: &Path) -> PyResult<String> {
        toml::to_string(table).map_err(|e| {
            SceneError::new_err(format!(
                "{}: cannot write the scene as TOML: {e}",
                path.display()
            ))
        })
    }
}

#[pymethods]
impl Scene {
    /// A scene named `name` (the output folder) of `bodies` (`Body`) with `steps` load steps.
    /// The materials are those the bodies were given as objects, and `materials` (a list of
    /// `Material`) for bodies that name theirs. Every other top-level scene key as a keyword:
    /// `contact`, `obstacles`, `output`, `gravity`, `gravity_schedule` (dicts and lists as the
    /// TOML has them; see docs/SCENES.md). Relative file names resolve against the current
    /// folder. Raises SceneError when the scene cannot be built.
    #[new]
    #[pyo3(signature = (name, bodies, steps=1, materials=None, **keys))]
    fn new(
        py: Python<'_>,
        name: String,
        bodies: Vec<PyRef<'_, Body>>,
        steps: i64,
        materials: Option<Vec<PyRef<'_, Material>>>,
        keys: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let mut table = Table::new();
        table.insert("name".into(), Value::String(name.clone()));
        table.insert("steps".into(), Value::Integer(steps));
        let mut all: Vec<Material> = Vec::new();
        let given = materials.iter().flatten().map(|m| (**m).clone());
        for m in given.chain(bodies.iter().flat_map(|b| b.materials.clone())) {
            match all.iter().find(|o| o.name() == m.name()) {
                Some(o) if o.table != m.table => {
                    return Err(PyValueError::new_err(format!(
                    "two different materials are named '{}': {} and {}; give them different names",
                    m.name(),
                    Value::Table(o.table.clone()),
                    Value::Table(m.table.clone())
                )))
                }
                Some(_) => {}
                None => all.push(m),
            }
        }
        let mut files = Vec::new();
        let mut body_tables = Vec::new();
        for b in &bodies {
            let (t, f) = b.scene_table();
            body_tables.push(Value::Table(t));
            files.extend(f);
        }
        kwargs_into(&mut table, keys, "")?;
        for k in ["materials", "bodies"] {
            if keys.is_some_and(|kw| kw.contains(k).unwrap_or(false)) {
                return Err(PyValueError::new_err(format!(
                    "give `{k}` as the argument of that name"
                )));
            }
        }
        if !all.is_empty() {
            table.insert(
                "materials".into(),
                Value::Array(all.into_iter().map(|m| Value::Table(m.table)).collect()),
            );
        }
        table.insert("bodies".into(), Value::Array(body_tables));
        let path = here(&format!("{name}.toml"));
        let text = Scene::text_of(&table, &path)?;
        Scene::build(py, text, path, files)
    }

    /// Read the scene file `path` (with its paper, mesh and outline files) and check it.
    /// `values` sets dotted keys as one variant of a `[sweep]` would
    /// (`{"materials.rubber.youngs_modulus": 2e7}`; tables in lists by `name` or 1-based
    /// position); the file's own `[sweep]` is dropped then (without `values`, its values
    /// outside the sweep are run). Raises SceneError with the file and line.
    #[staticmethod]
    #[pyo3(signature = (path, values=None))]
    fn load(py: Python<'_>, path: PathBuf, values: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let text = std::fs::read_to_string(&path).map_err(|source| {
            scene_error(&linkage::scene::SceneError::Read {
                path: path.clone(),
                source,
            })
        })?;
        let text = match values {
            None => text,
            Some(v) => {
                let mut set = Vec::new();
                for (k, value) in v.iter() {
                    let key: String = k.extract()?;
                    set.push((key.clone(), to_toml(&value, &key)?));
                }
                with_values(&text, &path, &set)
                    .map_err(|e| scene_error(&e))?
                    .text
            }
        };
        Scene::build(py, text, path, Vec::new())
    }

    /// A scene from a dict with the scene file's keys (as `to_dict` gives, or `tomllib`
    /// reads). `path` is where it would be: relative file names resolve against its folder
    /// (default: the current folder). Raises SceneError as for a file.
    #[staticmethod]
    #[pyo3(signature = (scene, path=None))]
    fn from_dict(
        py: Python<'_>,
        scene: &Bound<'_, PyDict>,
        path: Option<PathBuf>,
    ) -> PyResult<Self> {
        let table = dict_to_table(scene, "")?;
        let name = table.get("name").and_then(Value::as_str).unwrap_or("scene");
        let path = path.unwrap_or_else(|| here(&format!("{name}.toml")));
        let text = Scene::text_of(&table, &path)?;
        Scene::build(py, text, path, Vec::new())
    }

    /// The scene as a dict of the scene file's keys, through the same types the file is read
    /// with (absent keys left out). Bodies from arrays name their files (`<body>.nodes`,
    /// `<body>.links`), held in memory until `to_toml` writes them.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let spec: SceneSpec = toml::from_str(&self.text)
            .map_err(|e| SceneError::new_err(format!("{}: {e}", self.path.display())))?;
        let value = Value::try_from(&spec)
            .map_err(|e| PyValueError::new_err(format!("cannot convert the scene: {e}")))?;
        match value {
            Value::Table(t) => table_to_dict(py, &t),
            _ => Err(PyValueError::new_err("the scene is not a table")),
        }
    }

    /// Write the scene file `path` that `linkage run` runs, and beside it the paper files of
    /// bodies from arrays (`<body>.nodes`, `<body>.links`, `<body>.patches`). Other file names
    /// are written as given: relative ones resolve against the new file's folder.
    fn to_toml(&self, path: PathBuf) -> PyResult<()> {
        let folder = path.parent().unwrap_or(Path::new("."));
        let fail = |p: &Path, e: std::io::Error| {
            PyOSError::new_err(format!("{}: cannot write: {e}", p.display()))
        };
        if !folder.as_os_str().is_empty() {
            std::fs::create_dir_all(folder).map_err(|e| fail(folder, e))?;
        }
        for (name, text) in &self.files {
            let file = folder.join(name);
            std::fs::write(&file, text).map_err(|e| fail(&file, e))?;
        }
        std::fs::write(&path, &self.text).map_err(|e| fail(&path, e))
    }

    /// Solve every load step. Without `out` the results stay in memory (nothing is written);
    /// with `out` they are written to `out/<name>/` as `linkage run --out out` does (pictures
    /// and VTK files when the scene's `[output]` asks) and read back. `progress(done, total)`
    /// is called on this thread as steps are solved. The GIL is released while it solves;
    /// Ctrl-C raises KeyboardInterrupt within 50 ms (the solve stops after its current step).
    /// Raises RunError when a step cannot be solved (`err.results`: the steps before it).
    #[pyo3(signature = (out=None, progress=None))]
    fn run(
        &self,
        py: Python<'_>,
        out: Option<PathBuf>,
        progress: Option<Py<PyAny>>,
    ) -> PyResult<Results> {
        run_world(py, self.world.clone(), out, progress)
    }

    /// The scene's name (its output folder).
    #[getter]
    fn name(&self) -> String {
        self.world.name.clone()
    }

    /// Its number of load steps.
    #[getter]
    fn steps(&self) -> usize {
        self.world.steps
    }

    /// The scene file it was read from (or would be written to).
    #[getter]
    fn path(&self) -> PathBuf {
        self.path.clone()
    }

    /// The scene's TOML text.
    #[getter]
    fn text(&self) -> String {
        self.text.clone()
    }

    /// The body names, in scene order.
    #[getter]
    fn bodies(&self) -> Vec<String> {
        self.world.bodies.iter().map(|b| b.name.clone()).collect()
    }

    /// The model's size in one line, as `linkage check` prints it.
    fn describe(&self) -> String {
        self.world.describe()
    }

    fn __repr__(&self) -> String {
        format!("Scene('{}': {})", self.world.name, self.world.describe())
    }
}

/// `linkage.run(path, out)`: the scene file run as `linkage run path --out out` runs it.
pub fn run_file(
    py: Python<'_>,
    path: PathBuf,
    out: PathBuf,
    progress: Option<Py<PyAny>>,
) -> PyResult<Results> {
    let scene = Scene::load(py, path.clone(), None)?;
    let variants = linkage::scene::expand_sweep(&scene.text, &path).map_err(|e| scene_error(&e))?;
    if variants.iter().any(|v| !v.values.is_empty()) {
        return Err(SceneError::new_err(format!(
            "{}: the scene has a [sweep] of {} variants: run one with linkage.Scene.load(path, values={{...}}).run(out=...), or all of them with `linkage run`",
            path.display(),
            variants.len()
        )));
    }
    scene.run(py, Some(out), progress)
}
