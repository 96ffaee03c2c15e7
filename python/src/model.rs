//! `Material` and `Body`: a scene's materials and bodies built in Python, as the tables of a
//! scene file (every key of `[[materials]]` and `[[bodies]]` as a keyword argument) and, for
//! a body from arrays, the texts of its paper files (`<body>.nodes`, `<body>.links`).

use crate::convert::{kwargs_into, to_toml};
use linkage::linkage::Dimension;
use linkage::scene::paper_files::{links_text, nodes_text};
use nalgebra::Vector3;
use numpy::{AllowTypeChange, PyArrayLike2, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use toml::{Table, Value};

/// A material: `[[materials]]` of a scene file.
#[pyclass(module = "linkage", frozen)]
#[derive(Clone)]
pub struct Material {
    /// The `[[materials]]` table.
    pub table: Table,
}

impl Material {
    /// Its name.
    pub fn name(&self) -> &str {
        self.table
            .get("name")
            .and_then(Value::as_str)
            .unwrap_or_default()
    }
}

#[pymethods]
impl Material {
    /// A material named `name` with Young's modulus `youngs_modulus` (Pa) and cross-section
    /// `area` (m²) of its members, or instead of `area` `continuum_modulus` (Pa: the modulus a
    /// 3D body of this material has as a solid, its area chosen to give it); every other
    /// `[[materials]]` key as a keyword (`strength`, `tensile_strength`,
    /// `compressive_strength` in Pa, `behaviour`, `density` in kg/m³, `failure`, `scatter`,
    /// `softening`: see docs/SCENES.md).
    #[new]
    #[pyo3(signature = (name, youngs_modulus, area = None, continuum_modulus = None, **keys))]
    fn new(
        name: String,
        youngs_modulus: f64,
        area: Option<f64>,
        continuum_modulus: Option<f64>,
        keys: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let mut table = Table::new();
        table.insert("name".into(), Value::String(name));
        table.insert("youngs_modulus".into(), Value::Float(youngs_modulus));
        if let Some(a) = area {
            table.insert("area".into(), Value::Float(a));
        }
        if let Some(e) = continuum_modulus {
            table.insert("continuum_modulus".into(), Value::Float(e));
        }
        kwargs_into(&mut table, keys, "Material")?;
        Ok(Material { table })
    }

    /// The material's name.
    #[getter(name)]
    fn py_name(&self) -> String {
        self.name().to_string()
    }

    /// The `[[materials]]` table as a dict.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        crate::convert::table_to_dict(py, &self.table)
    }

    fn __repr__(&self) -> String {
        format!("Material({})", Value::Table(self.table.clone()))
    }
}

/// A material given as a `Material` or by the name of one.
pub enum MaterialRef {
    /// A material object, added to the scene's materials.
    Given(Material),
    /// The name of a material the scene defines.
    Named(String),
}

impl MaterialRef {
    fn extract(obj: &Bound<'_, PyAny>, key: &str) -> PyResult<Self> {
        if let Ok(m) = obj.cast::<Material>() {
            return Ok(MaterialRef::Given(m.get().clone()));
        }
        obj.extract::<String>()
            .map(MaterialRef::Named)
            .map_err(|_| {
                PyTypeError::new_err(format!(
                    "{key}: give a linkage.Material or the name of one, not {}",
                    obj.get_type()
                        .name()
                        .map(|n| n.to_string())
                        .unwrap_or_default()
                ))
            })
    }

    /// The material's name.
    pub fn name(&self) -> &str {
        match self {
            MaterialRef::Given(m) => m.name(),
            MaterialRef::Named(n) => n,
        }
    }
}

/// A deformable body: `[[bodies]]` of a scene file, its geometry from arrays or a generator.
#[pyclass(module = "linkage")]
pub struct Body {
    /// The `[[bodies]]` table without its geometry files, supports, loads and pressures.
    pub table: Table,
    /// The nodes file's text, for a body from arrays.
    pub nodes_text: Option<String>,
    /// The links file's text, for a body from arrays.
    pub links_text: Option<String>,
    /// The patches file's text, when patches are given.
    pub patches_text: Option<String>,
    /// Materials the body uses that it was given as objects (its default first).
    pub materials: Vec<Material>,
    /// `[[bodies.supports]]`.
    pub supports: Vec<Value>,
    /// `[[bodies.loads]]`.
    pub loads: Vec<Value>,
    /// `[[bodies.pressures]]`.
    pub pressures: Vec<Value>,
}

/// Rows of a 2-column integer array (1-based numbers), checked to be ≥ 1: 0-based pairs.
fn numbered_rows<const K: usize>(
    array: &PyArrayLike2<'_, i64, AllowTypeChange>,
    key: &str,
    what: &str,
) -> PyResult<Vec<[usize; K]>> {
    let view = array.as_array();
    if view.ncols() != K {
        return Err(PyValueError::new_err(format!(
            "{key}: give an array of shape (n, {K}) of 1-based node numbers (one {what} per row); got shape {:?}",
            array.shape()
        )));
    }
    view.rows()
        .into_iter()
        .enumerate()
        .map(|(r, row)| {
            let mut out = [0; K];
            for (slot, &n) in out.iter_mut().zip(row.iter()) {
                if n < 1 {
                    return Err(PyValueError::new_err(format!(
                        "{key}: {what} {} names node {n}: node numbers are 1-based (row i of `nodes` is node i + 1)",
                        r + 1
                    )));
                }
                *slot = (n - 1) as usize;
            }
            Ok(out)
        })
        .collect()
}

/// A selector's nodes (1-based numbers) as a TOML list, if given.
fn node_list(nodes: Option<&Bound<'_, PyAny>>, key: &str) -> PyResult<Option<Value>> {
    nodes.map(|n| to_toml(n, key)).transpose()
}

/// A `[[bodies.supports]]`-like entry from a selector, its own keys and the keywords.
fn entry(
    nodes: Option<&Bound<'_, PyAny>>,
    own: Vec<(&str, Option<Value>)>,
    keys: Option<&Bound<'_, PyDict>>,
    key: &str,
) -> PyResult<Value> {
    let mut table = Table::new();
    if let Some(n) = node_list(nodes, &format!("{key} nodes"))? {
        table.insert("nodes".into(), n);
    }
    for (k, v) in own {
        if let Some(v) = v {
            table.insert(k.into(), v);
        }
    }
    kwargs_into(&mut table, keys, key)?;
    Ok(Value::Table(table))
}

#[pymethods]
impl Body {
    /// A body named `name`. From arrays: `nodes` of shape (n, 2) or (n, 3) (m; row i is node
    /// i + 1) and `members` of shape (m, 2) (1-based node numbers; row i is member i + 1),
    /// optionally `patches` (k, 3) for 3D surfaces. Or from a generator keyword (`disk`,
    /// `rectangle`, `cylindrical_shell`, `box_lattice`, `mesh`, `outline`: see
    /// docs/SCENES.md). `material`: a `Material` or the name of one in `Scene(materials=)`;
    /// `member_materials`: one per member (the links file's third column). Every other
    /// `[[bodies]]` key as a keyword (`kinematics`, `solver`, `newton`, `offset`, ...).
    #[new]
    #[pyo3(signature = (name, nodes=None, members=None, material=None, member_materials=None, patches=None, **keys))]
    fn new(
        name: String,
        nodes: Option<PyArrayLike2<'_, f64, AllowTypeChange>>,
        members: Option<PyArrayLike2<'_, i64, AllowTypeChange>>,
        material: Option<&Bound<'_, PyAny>>,
        member_materials: Option<&Bound<'_, PyAny>>,
        patches: Option<PyArrayLike2<'_, i64, AllowTypeChange>>,
        keys: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let mut table = Table::new();
        table.insert("name".into(), Value::String(name.clone()));
        let mut materials = Vec::new();
        if let Some(m) = material {
            let m = MaterialRef::extract(m, "material")?;
            table.insert("material".into(), Value::String(m.name().to_string()));
            if let MaterialRef::Given(m) = m {
                materials.push(m);
            }
        }
        kwargs_into(&mut table, keys, &format!("body '{name}'"))?;
        for k in [
            "nodes",
            "links",
            "patches",
            "supports",
            "loads",
            "pressures",
        ] {
            if table.contains_key(k) {
                return Err(PyValueError::new_err(format!(
                    "body '{name}': give `{k}` {}",
                    match k {
                        "nodes" | "patches" => "as an array (the keyword of that name)",
                        "links" => "as the `members` array",
                        _ => "with body.support(), body.load() or body.pressure()",
                    }
                )));
            }
        }
        let (nodes_text, links_text, patches_text) = match (nodes, members) {
            (None, None) => {
                if member_materials.is_some() || patches.is_some() {
                    return Err(PyValueError::new_err(format!(
                        "body '{name}': member_materials and patches go with `nodes` and `members` arrays"
                    )));
                }
                (None, None, None)
            }
            (Some(nodes), Some(members)) => {
                let view = nodes.as_array();
                let dimension = match view.ncols() {
                    2 => Dimension::Two,
                    3 => Dimension::Three,
                    _ => {
                        return Err(PyValueError::new_err(format!(
                            "body '{name}': nodes: give an array of shape (n, 2) or (n, 3) of coordinates in m; got shape {:?}",
                            nodes.shape()
                        )))
                    }
                };
                let points: Vec<Vector3<f64>> = view
                    .rows()
                    .into_iter()
                    .map(|r| Vector3::new(r[0], r[1], if r.len() == 3 { r[2] } else { 0.0 }))
                    .collect();
                let pairs =
                    numbered_rows::<2>(&members, &format!("body '{name}': members"), "member")?;
                let names = match member_materials {
                    None => None,
                    Some(list) => {
                        let mut names = Vec::with_capacity(pairs.len());
                        for (k, item) in list.try_iter()?.enumerate() {
                            let m = MaterialRef::extract(
                                &item?,
                                &format!("body '{name}': member_materials[{k}]"),
                            )?;
                            names.push(m.name().to_string());
                            if let MaterialRef::Given(m) = m {
                                if !materials.iter().any(|o: &Material| o.name() == m.name()) {
                                    materials.push(m);
                                }
                            }
                        }
                        Some(names)
                    }
                };
                let invalid =
                    |e: std::io::Error| PyValueError::new_err(format!("body '{name}': {e}"));
                let nodes_text = nodes_text(dimension, &points).map_err(invalid)?;
                let links_text = links_text(&pairs, names.as_deref()).map_err(invalid)?;
                let patches_text = match patches {
                    None => None,
                    Some(p) => {
                        let triples =
                            numbered_rows::<3>(&p, &format!("body '{name}': patches"), "patch")?;
                        Some(
                            triples
                                .iter()
                                .map(|[a, b, c]| format!("{} {} {}\n", a + 1, b + 1, c + 1))
                                .collect(),
                        )
                    }
                };
                (Some(nodes_text), Some(links_text), patches_text)
            }
            _ => {
                return Err(PyValueError::new_err(format!(
                    "body '{name}': give both `nodes` and `members` arrays (or a generator keyword)"
                )))
            }
        };
        Ok(Body {
            table,
            nodes_text,
            links_text,
            patches_text,
            materials,
            supports: Vec::new(),
            loads: Vec::new(),
            pressures: Vec::new(),
        })
    }

    /// Hold the selected nodes in the directions `fix` (any of "x", "y", "z"): `nodes` are
    /// 1-based node numbers, or select with a keyword (`nearest`, `inside`, `on_line`,
    /// `on_plane`, `tolerance`); `displacement` (m) and `schedule` as in `[[bodies.supports]]`.
    #[pyo3(signature = (nodes=None, fix=None, **keys))]
    fn support(
        &mut self,
        nodes: Option<&Bound<'_, PyAny>>,
        fix: Option<Vec<String>>,
        keys: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<()> {
        let fix = fix.map(|f| Value::Array(f.into_iter().map(Value::String).collect()));
        let e = entry(nodes, vec![("fix", fix)], keys, "support")?;
        self.supports.push(e);
        Ok(())
    }

    /// Load the selected nodes: `force` per node (N, one component per dimension), or
    /// `total_force=` shared by them; `nodes` are 1-based node numbers or a selector keyword;
    /// `schedule` as in `[[bodies.loads]]`.
    #[pyo3(signature = (nodes=None, force=None, **keys))]
    fn load(
        &mut self,
        nodes: Option<&Bound<'_, PyAny>>,
        force: Option<&Bound<'_, PyAny>>,
        keys: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<()> {
        let force = force.map(|f| to_toml(f, "load force")).transpose()?;
        let e = entry(nodes, vec![("force", force)], keys, "load")?;
        self.loads.push(e);
        Ok(())
    }

    /// A pressure (Pa, positive into the body) on every patch whose three nodes the selector
    /// chooses, as `[[bodies.pressures]]`.
    #[pyo3(signature = (pressure, nodes=None, **keys))]
    fn pressure(
        &mut self,
        pressure: f64,
        nodes: Option<&Bound<'_, PyAny>>,
        keys: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<()> {
        let e = entry(
            nodes,
            vec![("pressure", Some(Value::Float(pressure)))],
            keys,
            "pressure",
        )?;
        self.pressures.push(e);
        Ok(())
    }

    /// The body's name.
    #[getter]
    fn name(&self) -> String {
        self.table
            .get("name")
            .and_then(Value::as_str)
            .unwrap_or_default()
            .to_string()
    }

    fn __repr__(&self) -> String {
        format!(
            "Body('{}', {} supports, {} loads)",
            self.name(),
            self.supports.len(),
            self.loads.len()
        )
    }
}

impl Body {
    /// The `[[bodies]]` table as the scene holds it, naming its files `<name>.nodes`,
    /// `<name>.links` (and `.patches`) when it is made from arrays, with the files' names and
    /// texts.
    pub fn scene_table(&self) -> (Table, Vec<(String, String)>) {
        let mut table = self.table.clone();
        let name = self.name();
        let mut files = Vec::new();
        for (key, text) in [
            ("nodes", &self.nodes_text),
            ("links", &self.links_text),
            ("patches", &self.patches_text),
        ] {
            if let Some(text) = text {
                let file = format!("{name}.{key}");
                table.insert(key.into(), Value::String(file.clone()));
                files.push((file, text.clone()));
            }
        }
        for (key, list) in [
            ("supports", &self.supports),
            ("loads", &self.loads),
            ("pressures", &self.pressures),
        ] {
            if !list.is_empty() {
                table.insert(key.into(), Value::Array(list.clone()));
            }
        }
        (table, files)
    }
}
