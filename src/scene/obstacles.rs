//! Building the scene's rigid obstacles and contact settings from `[[obstacles]]` and
//! `[contact]`.

use crate::contact::{
    mesh_collider, orient_outward, sharp_sample_estimate, ContactSettings, Obstacle, ObstacleShape,
    MAX_SHARP_SAMPLES, SAMPLE_SPACING,
};
use crate::linkage::{Body, Dimension, Schedule};
use crate::scene::bounds::{check_length, check_lengths, check_rotation};
use crate::scene::mesh_file::read_mesh;
use crate::scene::selector::vector;
use crate::scene::spec::{ContactSpec, ObstacleSpec};
use crate::Real;
use nalgebra::Vector3;
use std::path::Path;

/// The obstacle described by `spec` in a scene of `dimension` with `steps` steps, and what
/// building it changed that the user may want to know (mesh faces turned outward). Errors say
/// what is wrong and what to do (the caller adds the file and line).
pub(crate) fn obstacle_from(
    spec: &ObstacleSpec,
    dimension: Dimension,
    steps: Option<usize>,
    bodies: &[Body],
    folder: &Path,
) -> Result<(Obstacle, Option<String>), String> {
    let mut found = None;
    let name = &spec.name;
    let fail = |m: String| format!("obstacle '{name}': {m}");
    if name.trim().is_empty() {
        return Err(
            "[[obstacles]] `name` is empty: give the obstacle a name (results name it in `with`)"
                .to_string(),
        );
    }
    check_keys_of_shape(spec).map_err(fail)?;
    if bodies.iter().any(|b| &b.name == name) {
        return Err(fail(
            "a body has the same name: obstacles and bodies need distinct names (results name them in `with`)".to_string(),
        ));
    }
    let point = |v: &Option<Vec<Real>>, key: &str| -> Result<Vector3<Real>, String> {
        match v {
            Some(v) => vector(v, dimension, key)
                .and_then(|p| check_lengths(&p, key))
                .map_err(fail),
            None => Err(fail(format!("a {} needs `{key}`", spec.shape))),
        }
    };
    let positive = |v: Option<Real>, key: &str| -> Result<Real, String> {
        match v {
            Some(x) if x.is_finite() && x > 0.0 => check_length(x, key).map_err(fail),
            Some(x) => Err(fail(format!("`{key}` = {x}: give a length > 0 (m)"))),
            None => Err(fail(format!("a {} needs `{key}` (m)", spec.shape))),
        }
    };
    let rotation = || -> Result<Vector3<Real>, String> {
        let degrees = match (&spec.rotation, dimension) {
            (None, _) => return Ok(Vector3::zeros()),
            (Some(r), Dimension::Two) if r.len() == 1 => Vector3::new(0.0, 0.0, r[0]),
            (Some(r), Dimension::Three) if r.len() == 3 => Vector3::new(r[0], r[1], r[2]),
            (Some(r), _) => {
                return Err(fail(format!(
                    "`rotation` has {} components: give one angle about z in 2D, a rotation vector [x, y, z] in 3D (degrees)",
                    r.len()
                )))
            }
        };
        check_rotation(&degrees, "rotation").map_err(fail)?;
        Ok(degrees.map(|x| x.to_radians()))
    };
    let shape = match spec.shape.as_str() {
        "half_space" => {
            let normal = point(&spec.normal, "normal")?;
            if normal.norm() == 0.0 {
                return Err(fail("`normal` must not be the zero vector".to_string()));
            }
            ObstacleShape::HalfSpace {
                point: point(&spec.point, "point")?,
                normal: normal.normalize(),
            }
        }
        "cuboid" => {
            let h = point(&spec.half_extents, "half_extents")?;
            let d = dimension.dofs_per_node();
            if h.as_slice()[..d].iter().any(|x| *x <= 0.0) {
                return Err(fail("`half_extents` must all be > 0 (m)".to_string()));
            }
            // A 2D scene's cuboid is a rectangle: give it a depth that covers the plane.
            let half_extents = if d == 2 {
                Vector3::new(h.x, h.y, h.x.max(h.y))
            } else {
                h
            };
            ObstacleShape::Cuboid {
                center: point(&spec.center, "center")?,
                half_extents,
                rotation: rotation()?,
            }
        }
        "ball" => ObstacleShape::Ball {
            center: point(&spec.center, "center")?,
            radius: positive(spec.radius, "radius")?,
        },
        "cylinder" => ObstacleShape::Cylinder {
            center: point(&spec.center, "center")?,
            radius: positive(spec.radius, "radius")?,
            half_height: positive(spec.half_height, "half_height")?,
            rotation: rotation()?,
        },
        "capsule" => ObstacleShape::Capsule {
            center: point(&spec.center, "center")?,
            radius: positive(spec.radius, "radius")?,
            half_height: positive(spec.half_height, "half_height")?,
            rotation: rotation()?,
        },
        "mesh" => {
            if dimension != Dimension::Three {
                return Err(fail(
                    "a mesh obstacle needs 3D bodies: in 2D use half_space, cuboid, ball, cylinder or capsule".to_string(),
                ));
            }
            let Some(file) = &spec.file else {
                return Err(fail(
                    "a mesh needs `file`: an OBJ or STL file (m), relative to the scene file"
                        .to_string(),
                ));
            };
            let path = folder.join(file);
            // Named with the `file` key, so that the scene line given is that key's.
            let (vertices, triangles) =
                read_mesh(&path).map_err(|e| fail(format!("`file`: {e}")))?;
            // Turned outward as a whole (faces that disagree with their neighbours turned too),
            // as body patches are: contact pushes nodes out along the faces' normals.
            let oriented = orient_outward(&vertices, &triangles).map_err(|p| {
                fail(format!(
                    "`file`: {}: {p} (a mesh obstacle is a solid, not a two-sided sheet: its mesh must be closed)",
                    path.display()
                ))
            })?;
            found = turned_faces(name, &path, &oriented.turned, triangles.len());
            let triangles = oriented.triangles;
            let _checked = mesh_collider(&vertices, &triangles).map_err(&fail)?;
            ObstacleShape::Mesh {
                vertices,
                triangles,
            }
        }
        other => {
            return Err(fail(format!(
                "shape = {other:?}: use \"half_space\", \"cuboid\", \"ball\", \"cylinder\", \"capsule\" or \"mesh\""
            )))
        }
    };
    let travel = match &spec.travel {
        Some(t) => vector(t, dimension, "travel")
            .and_then(|t| check_lengths(&t, "travel"))
            .map_err(fail)?,
        None => Vector3::zeros(),
    };
    let schedule = match &spec.schedule {
        None => Schedule::Linear,
        Some(f) if steps.is_some_and(|steps| f.len() != steps) => {
            return Err(fail(format!(
                "`schedule` has {} factors but the scene has {} steps: give one factor per step",
                f.len(),
                steps.unwrap_or(0)
            )))
        }
        Some(f) if f.is_empty() => {
            return Err(fail(
                "`schedule` is empty: give at least one factor (they stand at equally spaced times over [dynamics] duration)".to_string(),
            ))
        }
        Some(f) if f.iter().any(|x| !x.is_finite()) => {
            return Err(fail("`schedule` has a non-finite factor".to_string()))
        }
        Some(f) => {
            // The offset of a step is the travel times its factor: that too must stay a length.
            let most = f.iter().fold(0.0, |m: Real, x| m.max(x.abs()));
            check_length(travel.amax() * most, "travel").map_err(|e| {
                fail(format!(
                    "{e} (the travel times the largest `schedule` factor, {most})"
                ))
            })?;
            Schedule::Factors(f.clone())
        }
    };
    // Contact samples a 3D obstacle's sharp edges at half the bodies' shortest member: one far
    // larger than the bodies would need more points than memory holds.
    let shortest = bodies
        .iter()
        .flat_map(|b| (0..b.members.len()).map(|m| b.member_length(m)))
        .fold(Real::INFINITY, Real::min);
    if dimension == Dimension::Three && shortest.is_finite() && shortest > 0.0 {
        let samples = sharp_sample_estimate(&shape, shortest);
        if samples.is_nan() || samples > MAX_SHARP_SAMPLES {
            let key = match spec.shape.as_str() {
                "mesh" => "file",
                "cylinder" => "radius",
                _ => "half_extents",
            };
            return Err(fail(format!(
                "`{key}` makes its sharp edges {:.3e} m long in all, {samples:.3e} times the spacing contact samples them at ({:.3e} m, {SAMPLE_SPACING} of the bodies' shortest member): more than the {MAX_SHARP_SAMPLES:e} points allowed; give the obstacle sizes of the scene's scale (an endless floor is a half_space)",
                samples * SAMPLE_SPACING * shortest,
                SAMPLE_SPACING * shortest,
            )));
        }
    }
    Ok((
        Obstacle {
            name: name.clone(),
            shape,
            travel,
            schedule,
        },
        found,
    ))
}

/// What `linkage check` says of a mesh whose faces were turned (1-based `turned` of `count`):
/// all of them (the mesh faced inward) or some (they disagreed with their neighbours).
fn turned_faces(name: &str, path: &Path, turned: &[usize], count: usize) -> Option<String> {
    if turned.is_empty() {
        return None;
    }
    let file = path.display();
    if turned.len() == count {
        return Some(format!(
            "obstacle '{name}': all {count} faces of {file} faced inward (clockwise seen from outside): turned outward as a whole"
        ));
    }
    let listed: Vec<String> = turned.iter().take(20).map(|f| f.to_string()).collect();
    Some(format!(
        "obstacle '{name}': {} of the {count} faces of {file} disagreed with their neighbours or faced inward and were turned outward: face{} {}{}",
        turned.len(),
        if turned.len() == 1 { "" } else { "s" },
        listed.join(", "),
        if turned.len() > 20 { ", ..." } else { "" }
    ))
}

/// The shape keys each obstacle shape takes (`travel` and `schedule` go with every shape).
const SHAPE_KEYS: [(&str, &[&str]); 6] = [
    ("half_space", &["point", "normal"]),
    ("cuboid", &["center", "half_extents", "rotation"]),
    ("ball", &["center", "radius"]),
    ("cylinder", &["center", "radius", "half_height", "rotation"]),
    ("capsule", &["center", "radius", "half_height", "rotation"]),
    ("mesh", &["file"]),
];

/// A shape key given to a shape that does not take it is an error, not ignored.
fn check_keys_of_shape(spec: &ObstacleSpec) -> Result<(), String> {
    let Some((_, takes)) = SHAPE_KEYS.iter().find(|(s, _)| *s == spec.shape) else {
        return Ok(()); // an unknown shape is reported with the shapes there are
    };
    let given = [
        ("point", spec.point.is_some()),
        ("normal", spec.normal.is_some()),
        ("center", spec.center.is_some()),
        ("half_extents", spec.half_extents.is_some()),
        ("radius", spec.radius.is_some()),
        ("half_height", spec.half_height.is_some()),
        ("rotation", spec.rotation.is_some()),
        ("file", spec.file.is_some()),
    ];
    match given.iter().find(|(key, g)| *g && !takes.contains(key)) {
        Some((key, _)) => Err(format!(
            "`{key}` does not apply to a {}, which takes {} (and `travel`, `schedule`): remove it or change `shape`",
            spec.shape,
            takes
                .iter()
                .map(|k| format!("`{k}`"))
                .collect::<Vec<_>>()
                .join(", ")
        )),
        None => Ok(()),
    }
}

/// The contact settings of `[contact]` (defaults without it).
pub(crate) fn contact_settings(spec: Option<&ContactSpec>) -> Result<ContactSettings, String> {
    let mut settings = ContactSettings::default();
    let Some(spec) = spec else {
        return Ok(settings);
    };
    for (key, value) in [("penalty", spec.penalty), ("tolerance", spec.tolerance)] {
        if let Some(v) = value {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("[contact] {key} = {v}: give a value > 0"));
            }
        }
    }
    settings.penalty = spec.penalty;
    settings.tolerance = spec.tolerance;
    if let Some(n) = spec.max_iterations {
        if n == 0 {
            return Err("[contact] max_iterations = 0: give 1 or more".to_string());
        }
        settings.max_iterations = n;
    }
    settings.condense = spec.condense.unwrap_or(settings.condense);
    settings.self_contact = spec.self_contact;
    Ok(settings)
}
