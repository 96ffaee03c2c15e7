//! Choosing nodes of a body by number or by geometry.

use crate::linkage::{Body, Dimension};
use crate::scene::import::{find_group, NodeGroup};
use crate::scene::spec::SelectorSpec;
use crate::Real;
use nalgebra::Vector3;

/// The nodes (0-based) a selector picks, or why it cannot pick any. Messages are for users:
/// they say what was asked and what to change.
pub fn select_nodes(spec: &SelectorSpec, body: &Body) -> Result<Vec<usize>, String> {
    select_nodes_in(spec, body, &[])
}

/// [`select_nodes`] for a body read from a model file, whose named node `groups` the key
/// `group` chooses from (exact name, else the one name that differs only in case).
pub fn select_nodes_in(
    spec: &SelectorSpec,
    body: &Body,
    groups: &[NodeGroup],
) -> Result<Vec<usize>, String> {
    let given = [
        spec.group.is_some(),
        spec.nodes.is_some(),
        spec.nearest.is_some(),
        spec.inside.is_some(),
        spec.on_line.is_some(),
        spec.on_plane.is_some(),
    ]
    .iter()
    .filter(|g| **g)
    .count();
    if given != 1 {
        return Err(format!(
            "give exactly one of `nodes`, `nearest`, `inside`, `on_line`, `on_plane`, `group` to choose the nodes ({given} given)"
        ));
    }
    if let Some(name) = &spec.group {
        return group_nodes(name, body, groups);
    }
    let tolerance = match spec.tolerance {
        Some(t) if t.is_finite() && t >= 0.0 => t,
        Some(t) => {
            return Err(format!(
                "tolerance = {t} must be a finite non-negative number of metres"
            ))
        }
        None => 1e-6 * body.size(),
    };
    let count = body.nodes.len();
    if let Some(list) = &spec.nodes {
        if list.is_empty() {
            return Err("`nodes` is empty: list at least one node number".to_string());
        }
        if let Some((k, n)) = list
            .iter()
            .enumerate()
            .find(|(k, n)| list[..*k].contains(n))
        {
            let first = list.iter().position(|m| m == n).unwrap_or(0);
            return Err(format!(
                "`nodes` lists node {n} twice (entries {} and {}): a repeated node would get the load or support twice; list each node once",
                first + 1,
                k + 1
            ));
        }
        return list
            .iter()
            .map(|&n| {
                if n >= 1 && (n as usize) <= count {
                    Ok(n as usize - 1)
                } else {
                    Err(format!(
                        "`nodes` names node {n}, which does not exist: body '{}' has nodes 1 to {count}",
                        body.name
                    ))
                }
            })
            .collect();
    }
    let point = |v: &[Real], key: &str| vector(v, body.dimension, key);
    let key = if spec.nearest.is_some() {
        "nearest"
    } else if spec.inside.is_some() {
        "inside"
    } else if spec.on_line.is_some() {
        "on_line"
    } else {
        "on_plane"
    };
    let picked: Vec<usize> = if let Some(p) = &spec.nearest {
        let p = point(p, "nearest")?;
        let best = (0..count).min_by(|&a, &b| {
            (body.nodes[a] - p)
                .norm_squared()
                .total_cmp(&(body.nodes[b] - p).norm_squared())
        });
        best.into_iter().collect()
    } else if let Some(b) = &spec.inside {
        let lo = point(&b.min, "inside.min")?;
        let hi = point(&b.max, "inside.max")?;
        if (0..3).any(|k| lo[k] > hi[k]) {
            return Err("inside.min must not exceed inside.max in any direction".to_string());
        }
        (0..count)
            .filter(|&i| {
                let q = body.nodes[i];
                (0..3).all(|k| q[k] >= lo[k] - tolerance && q[k] <= hi[k] + tolerance)
            })
            .collect()
    } else if let Some(l) = &spec.on_line {
        let p = point(&l.point, "on_line.point")?;
        let d = unit(
            point(&l.direction, "on_line.direction")?,
            "on_line.direction",
        )?;
        (0..count)
            .filter(|&i| {
                let r = body.nodes[i] - p;
                (r - d * d.dot(&r)).norm() <= tolerance
            })
            .collect()
    } else if let Some(pl) = &spec.on_plane {
        let p = point(&pl.point, "on_plane.point")?;
        let n = unit(point(&pl.normal, "on_plane.normal")?, "on_plane.normal")?;
        (0..count)
            .filter(|&i| n.dot(&(body.nodes[i] - p)).abs() <= tolerance)
            .collect()
    } else {
        Vec::new()
    };
    if picked.is_empty() {
        return Err(format!(
            "the selector `{key}` matches no node of body '{}' (tolerance {tolerance:e} m): check its coordinates against the body, which spans {}",
            body.name,
            extent(body)
        ));
    }
    Ok(picked)
}

/// A `nearest` node farther than this fraction of the body's size (its bounding diagonal) from
/// the point given is warned about: the point was probably mistyped (`[12, 300]` for `[12, 3]`).
pub const FAR_NEAREST: Real = 0.1;

/// The warning of a `nearest` selector whose picked node (0-based `picked`, as
/// [`select_nodes`] chose it) lies farther than [`FAR_NEAREST`] of the body's size from the
/// point given: the point, the node and the distance (`None` for other selectors, a point near
/// its node, or a point that cannot be read).
pub fn far_nearest_warning(spec: &SelectorSpec, body: &Body, picked: &[usize]) -> Option<String> {
    let given = spec.nearest.as_ref()?;
    let point = vector(given, body.dimension, "nearest").ok()?;
    let node = *picked.first()?;
    let at = body.nodes.get(node)?;
    let distance = (at - point).norm();
    let size = body.size();
    if distance.is_nan() || distance <= FAR_NEAREST * size {
        return None;
    }
    let d = body.dimension.dofs_per_node();
    Some(format!(
        "`nearest` = {given:?} picks node {} at {:?} m, {distance:.4} m away from the point: more than a tenth of the body's size ({size:.4} m, its bounding diagonal); no node is near that point: check its coordinates against the body, which spans {}",
        node + 1,
        &at.as_slice()[..d],
        extent(body)
    ))
}

/// The nodes of the group `name` among `groups` (a model file's).
fn group_nodes(name: &str, body: &Body, groups: &[NodeGroup]) -> Result<Vec<usize>, String> {
    if groups.is_empty() {
        return Err(format!(
            "`group` = {name:?}: body '{}' has no named groups; groups come from its `model` file (gmsh physical groups, INP *NSET and *ELSET)",
            body.name
        ));
    }
    let group = find_group(groups, name);
    let names = groups
        .iter()
        .map(|g| format!("{:?}", g.name))
        .collect::<Vec<_>>()
        .join(", ");
    match group {
        None => Err(format!(
            "`group` = {name:?} is not a group of body '{}': its model file has {names}",
            body.name
        )),
        Some(g) if g.nodes.is_empty() => Err(format!(
            "`group` = {name:?} holds no node of body '{}' (its elements are not part of the body)",
            body.name
        )),
        Some(g) => Ok(g.nodes.clone()),
    }
}

/// A point or direction with one component per dimension of the body, as a 3-vector.
pub fn vector(v: &[Real], dimension: Dimension, key: &str) -> Result<Vector3<Real>, String> {
    let d = dimension.dofs_per_node();
    if v.len() != d {
        return Err(format!(
            "`{key}` has {} components but the body is {}D: give {d}",
            v.len(),
            d
        ));
    }
    if let Some(x) = v.iter().find(|x| !x.is_finite()) {
        return Err(format!("`{key}` has the non-finite component {x}"));
    }
    let mut out = Vector3::zeros();
    out.as_mut_slice()[..d].copy_from_slice(v);
    Ok(out)
}

fn unit(v: Vector3<Real>, key: &str) -> Result<Vector3<Real>, String> {
    let n = v.norm();
    if n > 0.0 {
        Ok(v / n)
    } else {
        Err(format!("`{key}` must not be the zero vector"))
    }
}

fn extent(body: &Body) -> String {
    let mut lo = Vector3::repeat(Real::INFINITY);
    let mut hi = Vector3::repeat(Real::NEG_INFINITY);
    for p in &body.nodes {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let d = body.dimension.dofs_per_node();
    format!("{:?} to {:?} m", &lo.as_slice()[..d], &hi.as_slice()[..d])
}
