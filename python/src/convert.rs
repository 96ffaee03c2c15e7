//! Python values to TOML values and back: a scene dict is a TOML table, so every scene key
//! the files have is reachable from Python with its own name.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use toml::{Table, Value};

/// `obj` as a TOML value: bool, int, float, str, a list, tuple or numpy array (as a list), a
/// dict with string keys (as a table); numpy scalars by their Python value. `key` names the
/// place in errors.
pub fn to_toml(obj: &Bound<'_, PyAny>, key: &str) -> PyResult<Value> {
    if obj.is_instance_of::<PyBool>() {
        return Ok(Value::Boolean(obj.extract()?));
    }
    if obj.is_instance_of::<PyInt>() {
        return obj.extract::<i64>().map(Value::Integer).map_err(|_| {
            PyValueError::new_err(format!("{key}: the integer {obj} does not fit in 64 bits"))
        });
    }
    if obj.is_instance_of::<PyFloat>() {
        return Ok(Value::Float(obj.extract()?));
    }
    if obj.is_instance_of::<PyString>() {
        return Ok(Value::String(obj.extract()?));
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        return dict_to_table(d, key).map(Value::Table);
    }
    if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() {
        let mut out = Vec::new();
        for (i, item) in obj.try_iter()?.enumerate() {
            out.push(to_toml(&item?, &format!("{key}[{i}]"))?);
        }
        return Ok(Value::Array(out));
    }
    // numpy arrays and scalars: through their Python values.
    if obj.hasattr("tolist")? {
        let plain = obj.call_method0("tolist")?;
        if !plain.is(obj) {
            return to_toml(&plain, key);
        }
    }
    if obj.hasattr("__index__")? {
        return Ok(Value::Integer(obj.call_method0("__index__")?.extract()?));
    }
    if obj.hasattr("__float__")? {
        return Ok(Value::Float(obj.call_method0("__float__")?.extract()?));
    }
    Err(PyValueError::new_err(format!(
        "{key}: {} cannot be a scene value: give a bool, int, float, str, list, numpy array or dict",
        obj.get_type().name()?
    )))
}

/// A dict with string keys as a TOML table (`key` names it in errors).
pub fn dict_to_table(d: &Bound<'_, PyDict>, key: &str) -> PyResult<Table> {
    let mut table = Table::new();
    for (k, v) in d.iter() {
        let name: String = k
            .extract()
            .map_err(|_| PyValueError::new_err(format!("{key}: the key {k} is not a string")))?;
        if v.is_none() {
            continue;
        }
        let place = if key.is_empty() {
            name.clone()
        } else {
            format!("{key}.{name}")
        };
        let value = to_toml(&v, &place)?;
        table.insert(name, value);
    }
    Ok(table)
}

/// A TOML value as plain Python objects (tables as dicts, arrays as lists).
pub fn from_toml<'py>(py: Python<'py>, value: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match value {
        Value::String(s) => s.into_pyobject(py)?.into_any(),
        Value::Integer(i) => i.into_pyobject(py)?.into_any(),
        Value::Float(f) => f.into_pyobject(py)?.into_any(),
        Value::Boolean(b) => b.into_pyobject(py)?.to_owned().into_any(),
        Value::Datetime(d) => d.to_string().into_pyobject(py)?.into_any(),
        Value::Array(a) => {
            let list = PyList::empty(py);
            for v in a {
                list.append(from_toml(py, v)?)?;
            }
            list.into_any()
        }
        Value::Table(t) => table_to_dict(py, t)?.into_any(),
    })
}

/// A TOML table as a dict.
pub fn table_to_dict<'py>(py: Python<'py>, table: &Table) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (k, v) in table {
        d.set_item(k, from_toml(py, v)?)?;
    }
    Ok(d)
}

/// Keyword arguments as table entries (None values left out).
pub fn kwargs_into(
    table: &mut Table,
    kwargs: Option<&Bound<'_, PyDict>>,
    key: &str,
) -> PyResult<()> {
    if let Some(kw) = kwargs {
        for (k, v) in dict_to_table(kw, key)? {
            table.insert(k, v);
        }
    }
    Ok(())
}
