//! A scene whose only body follows an arc-length path against fixed half-spaces: the body's
//! own Newton holds one [`Stop`] per half-space (its plane, its outward normal, the contact
//! penalty), so the path passes limit points with the obstacles in its residual and tangent.
//! Every other arc-length scene with contact is refused here with the physics reason.

use crate::contact::{
    default_penalty, self_contact_on, ContactError, NodeContact, ObstacleShape, SlipState,
};
use crate::linkage::body_state::node_vector;
use crate::linkage::{stop_forces, Body, PathMethod, Stop};
use crate::scene::run_error::RunError;
use crate::scene::World;
use crate::Real;
use nalgebra::Vector3;

/// The stops of `world`'s arc-length body: `Ok(None)` when no body of a scene with contact
/// follows an arc-length path (the contact solver's scene), `Ok(Some)` when the scene is one
/// body on an arc-length path and fixed frictionless half-spaces (one stop each, with the
/// penalty the contact solver would use: `[contact] penalty` or [`default_penalty`]), and the
/// error naming the body, the reason and the remedy for any other arc-length scene with
/// contact. Call it for scenes with contact only.
pub(crate) fn arc_length_stops(world: &World) -> Result<Option<Vec<Stop>>, RunError> {
    let Some(body) = world
        .bodies
        .iter()
        .find(|b| matches!(b.newton.path, PathMethod::ArcLength { .. }))
    else {
        return Ok(None);
    };
    let refuse = |reason: &str, remedy: &str| RunError::Contact {
        scene: world.source.clone(),
        source: ContactError::ArcLength {
            body: body.name.clone(),
            reason: reason.to_string(),
            remedy: remedy.to_string(),
        },
    };
    let schedules = "or follow the path by its schedules ([bodies.path] method = \"schedules\")";
    if world.bodies.len() > 1 {
        return Err(refuse(
            "the scene has other bodies: the arc length is one body's constraint; the contact solver advances by load control",
            &format!("solve the body alone against fixed half-spaces, {schedules}"),
        ));
    }
    if let Some(o) = world
        .obstacles
        .iter()
        .find(|o| o.travel != Vector3::zeros())
    {
        return Err(refuse(
            &format!("obstacle '{}' moves (travel): a moving obstacle sets the path's time, which the arc length sets itself", o.name),
            &format!("hold the obstacle still and load the body, {schedules}"),
        ));
    }
    if world.contact.friction.any() {
        return Err(refuse(
            "the scene has friction: friction's history needs increments in the load's time",
            &format!("make the contact frictionless ([contact] friction = 0), {schedules}"),
        ));
    }
    if self_contact_on(body, world.contact.self_contact) {
        return Err(refuse(
            "self-contact is on: the body's contact with itself is the contact solver's, which advances by load control",
            &format!("turn it off ([contact] self = false), {schedules}"),
        ));
    }
    let stiffness = world
        .contact
        .penalty
        .unwrap_or_else(|| default_penalty(body));
    world
        .obstacles
        .iter()
        .map(|o| match &o.shape {
            ObstacleShape::HalfSpace { point, normal } => Ok(Stop {
                name: o.name.clone(),
                point: *point,
                normal: *normal,
                stiffness,
            }),
            _ => Err(refuse(
                &format!("obstacle '{}' is not a half-space: only half-spaces are stops of an arc-length body so far", o.name),
                &format!("use half_space obstacles, {schedules}"),
            )),
        })
        .collect::<Result<Vec<_>, _>>()
        .map(Some)
}

/// What the stops do to `body` at displacement `u` (per body DOF, m), as a contact step
/// reports it: per pressed node its contact (frictionless: the normal force `k · depth` along
/// the stop's normal), and per stop pressed its total force on the body, N.
pub(crate) fn stop_contacts(
    body: &Body,
    stops: &[Stop],
    u: &[Real],
) -> (Vec<NodeContact>, Vec<(String, Vector3<Real>)>) {
    let d = body.dimension.dofs_per_node();
    let mut contacts = Vec::new();
    let mut totals = Vec::new();
    for (stop, (total, nodes)) in stops.iter().zip(stop_forces(body, stops, u)) {
        if nodes.is_empty() {
            continue;
        }
        for node in nodes {
            let x = body.nodes[node] + node_vector(u, d, node);
            let depth = stop.depth(&x);
            let normal_force = stop.stiffness * depth;
            contacts.push(NodeContact {
                node,
                with: stop.name.clone(),
                depth,
                force: stop.normal * normal_force,
                normal: stop.normal,
                normal_force,
                tangential_force: Vector3::zeros(),
                state: SlipState::Slip,
                slip: Vector3::zeros(),
                friction_dissipated: 0.0,
            });
        }
        totals.push((stop.name.clone(), total));
    }
    (contacts, totals)
}
