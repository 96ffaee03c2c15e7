//! Results in Python: a run's steps, each body's numbers as numpy arrays. Array row i is node
//! i + 1 (or member i + 1) of the scene's 1-based numbering.

use crate::errors::results_error;
use linkage::scene::{BodyResult, NodeForce, RunResults, StepResult, Summary};
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyList;
use std::path::PathBuf;
use std::sync::Arc;

/// A run's results: the stored steps (step 0 is the undeformed state) and the summary.
#[pyclass(module = "linkage", frozen)]
pub struct Results {
    /// The stored steps, ascending.
    steps: Arc<Vec<StepResult>>,
    /// `summary.json` of the run (None for a folder without one).
    summary: Option<Summary>,
    /// The folder read or written, if any.
    folder: Option<PathBuf>,
}

impl Results {
    /// Results of a run in memory or read back.
    pub fn new(steps: Vec<StepResult>, summary: Option<Summary>, folder: Option<PathBuf>) -> Self {
        Results {
            steps: Arc::new(steps),
            summary,
            folder,
        }
    }

    /// Read the results folder `dir` (JSON or NPZ) and its `summary.json`.
    pub fn read(dir: PathBuf) -> PyResult<Self> {
        let run: RunResults = RunResults::read(&dir).map_err(|e| results_error(&e))?;
        let summary = std::fs::read(dir.join("summary.json"))
            .ok()
            .and_then(|bytes| serde_json::from_slice::<Summary>(&bytes).ok());
        Ok(Results::new(run.steps, summary, Some(dir)))
    }
}

/// `value` as Python objects through JSON (dicts, lists, numbers, strings).
fn json_to_py<'py>(py: Python<'py>, value: &impl serde::Serialize) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value)
        .map_err(|e| PyValueError::new_err(format!("cannot convert to Python: {e}")))?;
    py.import("json")?.call_method1("loads", (text,))
}

#[pymethods]
impl Results {
    /// Read a results folder written by `linkage run` or `Scene.run(out=)`: `DIR/<scene name>`
    /// (JSON or NPZ step files). Raises `ResultsError` when it is not one.
    #[staticmethod]
    fn load(py: Python<'_>, dir: PathBuf) -> PyResult<Self> {
        py.detach(|| Results::read(dir))
    }

    /// The stored steps, ascending (step 0: the undeformed state).
    #[getter]
    fn steps(&self) -> Vec<Step> {
        (0..self.steps.len())
            .map(|k| Step {
                steps: self.steps.clone(),
                index: k,
            })
            .collect()
    }

    /// `summary.json` as a dict (per step its load factor, iterations, residual, warnings;
    /// breaks, failure), or None.
    #[getter]
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.summary.as_ref().map(|s| json_to_py(py, s)).transpose()
    }

    /// Why the run stopped early (the steps before it are here), or None.
    #[getter]
    fn failure(&self) -> Option<String> {
        self.summary.as_ref().and_then(|s| s.failure.clone())
    }

    /// The results folder read or written, or None for a run in memory.
    #[getter]
    fn folder(&self) -> Option<PathBuf> {
        self.folder.clone()
    }

    /// Step number `step` (not its position in `steps`: a run writing every k-th step stores
    /// fewer). Raises ValueError when it was not stored.
    fn step(&self, step: usize) -> PyResult<Step> {
        let index = self
            .steps
            .iter()
            .position(|s| s.step == step)
            .ok_or_else(|| {
                PyValueError::new_err(format!(
                    "step {step} is not stored: the stored steps are {:?}",
                    self.steps.iter().map(|s| s.step).collect::<Vec<_>>()
                ))
            })?;
        Ok(Step {
            steps: self.steps.clone(),
            index,
        })
    }

    fn __len__(&self) -> usize {
        self.steps.len()
    }

    /// Equal when the stored steps are equal, number for number (wall times and the folder
    /// are not compared).
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<Results>()
            .is_ok_and(|o| *o.get().steps == *self.steps)
    }

    fn __repr__(&self) -> String {
        format!(
            "Results({} stored step{}{})",
            self.steps.len(),
            if self.steps.len() == 1 { "" } else { "s" },
            self.folder
                .as_ref()
                .map(|f| format!(" in {}", f.display()))
                .unwrap_or_default()
        )
    }
}

/// One stored step: its load factor and every body's numbers.
#[pyclass(module = "linkage", frozen)]
#[derive(Clone)]
pub struct Step {
    steps: Arc<Vec<StepResult>>,
    index: usize,
}

impl Step {
    fn result(&self) -> &StepResult {
        &self.steps[self.index]
    }
}

#[pymethods]
impl Step {
    /// The step number (0: undeformed).
    #[getter]
    fn number(&self) -> usize {
        self.result().step
    }

    /// The load factor of the step (loads and prescribed displacements reach 1 at the last).
    #[getter]
    fn load_factor(&self) -> f64 {
        self.result().load_factor
    }

    /// Time of the step, s, in a dynamic scene; None in a quasi-static one.
    #[getter]
    fn time(&self) -> Option<f64> {
        self.result().time
    }

    /// The names of the bodies, in scene order.
    #[getter]
    fn names(&self) -> Vec<String> {
        self.result()
            .bodies
            .iter()
            .map(|b| b.name.clone())
            .collect()
    }

    /// Every body's results, in scene order.
    #[getter]
    fn bodies(&self) -> Vec<Body> {
        (0..self.result().bodies.len())
            .map(|b| Body {
                step: self.clone(),
                body: b,
            })
            .collect()
    }

    /// The results of the body named `name`; raises ValueError naming the bodies when there
    /// is none.
    fn body(&self, name: &str) -> PyResult<Body> {
        let bodies = &self.result().bodies;
        let body = bodies.iter().position(|b| b.name == name).ok_or_else(|| {
            PyValueError::new_err(format!(
                "no body named '{name}' in the step: the bodies are {}",
                bodies
                    .iter()
                    .map(|b| format!("'{}'", b.name))
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })?;
        Ok(Body {
            step: self.clone(),
            body,
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "Step({}, load_factor={}, bodies={:?})",
            self.result().step,
            self.result().load_factor,
            self.names()
        )
    }
}

/// One body at one step. Node arrays have one row per node (row i is node i + 1) and one
/// column per dimension (2 or 3); member arrays have one entry per member (entry i is member
/// i + 1).
#[pyclass(module = "linkage", frozen, name = "BodyResult")]
pub struct Body {
    step: Step,
    body: usize,
}

impl Body {
    fn result(&self) -> &BodyResult {
        &self.step.result().bodies[self.body]
    }

    /// Columns of the node arrays: the dimension of the body.
    fn dimension(&self) -> usize {
        self.result().displacements.first().map_or(2, Vec::len)
    }

    /// Rows of vectors as an (n, d) array.
    fn rows<'py>(&self, py: Python<'py>, rows: &[Vec<f64>]) -> Bound<'py, PyArray2<f64>> {
        let d = self.dimension();
        let flat: Vec<f64> = rows.iter().flat_map(|r| r.iter().copied()).collect();
        Array2::from_shape_vec((rows.len(), d), flat)
            .unwrap_or_else(|_| Array2::zeros((rows.len(), d)))
            .into_pyarray(py)
    }

    /// Forces at some nodes as an (n, d) array over all nodes (zero rows elsewhere).
    fn per_node<'py>(
        &self,
        py: Python<'py>,
        forces: impl Iterator<Item = (usize, &'py [f64])>,
    ) -> Bound<'py, PyArray2<f64>> {
        let (n, d) = (self.result().displacements.len(), self.dimension());
        let mut out = Array2::<f64>::zeros((n, d));
        for (node, force) in forces {
            if (1..=n).contains(&node) {
                for (k, f) in force.iter().take(d).enumerate() {
                    out[[node - 1, k]] += f;
                }
            }
        }
        out.into_pyarray(py)
    }

    fn node_forces<'py>(
        &'py self,
        py: Python<'py>,
        list: &'py [NodeForce],
    ) -> Bound<'py, PyArray2<f64>> {
        self.per_node(py, list.iter().map(|f| (f.node, f.force.as_slice())))
    }
}

fn numbers<'py>(py: Python<'py>, v: &[usize]) -> Bound<'py, PyArray1<i64>> {
    Array1::from_iter(v.iter().map(|&k| k as i64)).into_pyarray(py)
}

#[pymethods]
impl Body {
    /// The body's name.
    #[getter]
    fn name(&self) -> String {
        self.result().name.clone()
    }

    /// Displacement of each node, m: shape (nodes, d); row i is node i + 1.
    #[getter]
    fn displacements<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.rows(py, &self.result().displacements)
    }

    /// Deformed position of each node, m: shape (nodes, d); row i is node i + 1.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.rows(py, &self.result().positions)
    }

    /// Axial force of each member, N, tension positive: shape (members,); entry i is member i + 1.
    #[getter]
    fn axial_forces<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.result().axial_forces.clone().into_pyarray(py)
    }

    /// Strain of each member (change of length over length), tension positive: shape (members,).
    #[getter]
    fn strains<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.result().strains.clone().into_pyarray(py)
    }

    /// Stress of each member, Pa, tension positive: shape (members,); entry i is member i + 1.
    #[getter]
    fn stresses<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.result().stresses.clone().into_pyarray(py)
    }

    /// Force each node receives from its supports, N: shape (nodes, d), zero rows at nodes
    /// without a support; row i is node i + 1.
    #[getter]
    fn reactions<'py>(&'py self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.node_forces(py, &self.result().reactions)
    }

    /// The 1-based numbers of the supported nodes (the rows of `reactions` that can be non-zero).
    #[getter]
    fn supported_nodes<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        let nodes: Vec<usize> = self.result().reactions.iter().map(|f| f.node).collect();
        numbers(py, &nodes)
    }

    /// Applied force at each node at this step, N: shape (nodes, d); row i is node i + 1.
    #[getter]
    fn loads<'py>(&'py self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.node_forces(py, &self.result().loads)
    }

    /// Contact force each node receives (from obstacles and other bodies, normal plus
    /// friction), N: shape (nodes, d), zero rows at nodes not in contact; row i is node i + 1.
    /// `contact_list` has each contact's depth, normal, state and slip.
    #[getter]
    fn contacts<'py>(&'py self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let list = &self.result().contacts;
        self.per_node(py, list.iter().map(|c| (c.node, c.force.as_slice())))
    }

    /// Every contact as a dict: `node` (1-based), `with`, `depth` (m), `force`, `normal`,
    /// `normal_force`, `tangential_force` (N), `state` ("stick" or "slip"), `slip` (m).
    #[getter]
    fn contact_list<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.result().contacts)
    }

    /// 1-based numbers of the members beyond their strength.
    #[getter]
    fn overloaded<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        numbers(py, &self.result().overloaded)
    }

    /// 1-based numbers of the members broken so far, in the order they broke (empty without
    /// breaking members).
    #[getter]
    fn broken<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        let broken = self
            .result()
            .fracture
            .as_ref()
            .map(|f| f.broken.clone())
            .unwrap_or_default();
        numbers(py, &broken)
    }

    /// The breaks of this step as dicts (`member`, `load_factor`, and `tooth` for a softening
    /// member that passed a tooth).
    #[getter]
    fn breaks<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        match &self.result().fracture {
            Some(f) => json_to_py(py, &f.breaks),
            None => Ok(PyList::empty(py).into_any()),
        }
    }

    /// The body's step as the dict `steps/NNNN.json` holds for it.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, self.result())
    }

    fn __repr__(&self) -> String {
        let r = self.result();
        format!(
            "BodyResult('{}', {} nodes, {} members, step {})",
            r.name,
            r.displacements.len(),
            r.axial_forces.len(),
            self.step.result().step
        )
    }
}
