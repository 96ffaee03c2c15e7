//! Marks drawn over the bodies: supports, applied forces and contact forces.

use crate::render::colour_scale::{CONTACT_ORANGE, FORCE_BLUE, SLIP_MAGENTA, STICK_GREEN};
use crate::render::deformed_body::{vec3, DeformedBody};
use crate::render::extent::arrow_ends;
use crate::render::{Primitive, RunExtent};
use nalgebra::Vector3;

/// Supports (a teal mark across each held direction, on the outside of the body), applied
/// forces (blue arrows) and contact forces (orange arrows) on one length scale for the whole
/// run
/// and their tangential (friction) part (green where the contact sticks, magenta where it
/// slips) of one body. `depth_test`: hide those behind surfaces (3D).
pub fn markers(body: &DeformedBody, extent: &RunExtent, depth_test: bool) -> Vec<Primitive> {
    let mut out = Vec::new();
    for s in &body.model.supports {
        let at = body.at(s.node);
        let outward = body
            .undeformed
            .get(s.node.wrapping_sub(1))
            .map(|p| p - body.centre)
            .unwrap_or_default();
        if depth_test && s.fix.len() == 3 {
            out.push(Primitive::Clamp { at, depth_test });
            continue;
        }
        for d in &s.fix {
            let axis = match d.as_str() {
                "x" => Vector3::x(),
                "y" => Vector3::y(),
                _ => Vector3::z(),
            };
            // The mark lies outside: on the side the node faces from the body's centre.
            let direction = if axis.dot(&outward) > 0.0 {
                -axis
            } else {
                axis
            };
            out.push(Primitive::Support {
                at,
                direction,
                depth_test,
            });
        }
    }
    // Many loaded nodes (a load shared by a face or a ring): thinner arrows.
    let width = if body.result.loads.len() > 6 {
        1.8
    } else {
        3.0
    };
    let forces = body
        .result
        .loads
        .iter()
        .map(|l| (l.node, &l.force, extent.force_scale, FORCE_BLUE, width))
        .chain(
            body.result
                .contacts
                .iter()
                .map(|c| (c.node, &c.force, extent.force_scale, CONTACT_ORANGE, 2.0)),
        )
        .chain(body.result.contacts.iter().map(|c| {
            let colour = if c.state == "stick" {
                STICK_GREEN
            } else {
                SLIP_MAGENTA
            };
            (c.node, &c.tangential_force, extent.force_scale, colour, 2.0)
        }));
    for (node, f, scale, colour, width) in forces {
        if f.iter().all(|x| *x == 0.0) {
            continue;
        }
        let (tail, tip) = arrow_ends(body.at(node), vec3(f), scale, body.centre);
        out.push(Primitive::Arrow {
            tail,
            tip,
            colour,
            width,
            depth_test,
        });
    }
    out
}
