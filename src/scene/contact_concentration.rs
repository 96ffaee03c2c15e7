//! The warning of a contact carried by one node: a ball obstacle pressing a mesh body through a
//! single node puts its whole force there, and the local result (the stresses around that
//! node, the indentation) is the mesh's, not the body's.

use crate::contact::NodeContact;
use crate::linkage::Body;
use crate::Real;
use nalgebra::Vector3;

/// One node carrying more than this share of a pair's normal force is warned about (50 %).
pub const CONCENTRATED_SHARE: Real = 0.5;

/// A neighbour of the pressing node (a member joins them) could share the contact when it
/// lies within this slope of the contact's tangent plane: its distance from that plane at most
/// this fraction of its distance from the node (0.5: within 30°). A neighbour along a beam
/// pressed end-on lies on the normal (slope 1) and cannot.
pub const NEIGHBOUR_SLOPE: Real = 0.5;

/// The warnings of `step` (the run's last, at full load) for `body`'s contacts (`contacts`, 1 per node and what it touches)
/// at its deformed `positions` (m): per pair (what the body touches) whose largest node
/// carries more than [`CONCENTRATED_SHARE`] of the pair's normal force while a neighbour of
/// that node lies within [`NEIGHBOUR_SLOPE`] of the contact's tangent plane (so several
/// contacts were possible: a finer mesh would spread the force). Pairs in `warned` (body
/// name, other name) are skipped, and the pairs warned are added to it: once per run.
pub fn concentrated_contact_warnings(
    body: &Body,
    step: usize,
    positions: &[Vector3<Real>],
    contacts: &[NodeContact],
    warned: &mut Vec<(String, String)>,
) -> Vec<String> {
    let mut pairs: Vec<&str> = contacts.iter().map(|c| c.with.as_str()).collect();
    pairs.sort_unstable();
    pairs.dedup();
    let mut out = Vec::new();
    for with in pairs {
        let key = (body.name.clone(), with.to_string());
        if warned.contains(&key) {
            continue;
        }
        let of_pair = || contacts.iter().filter(|c| c.with == with);
        let total: Real = of_pair().map(|c| c.normal_force).sum();
        let Some(top) = of_pair().max_by(|a, b| a.normal_force.total_cmp(&b.normal_force)) else {
            continue;
        };
        let most = total > 0.0 && top.normal_force > CONCENTRATED_SHARE * total;
        if !most {
            continue;
        }
        let Some(&at) = positions.get(top.node) else {
            continue;
        };
        let n = top.normal;
        let flat = body
            .members
            .iter()
            .filter_map(|m| match m.nodes {
                [a, b] if a == top.node => Some(b),
                [a, b] if b == top.node => Some(a),
                _ => None,
            })
            .filter_map(|j| positions.get(j))
            .any(|&p| {
                let r = p - at;
                r.norm() > 0.0 && n.dot(&r).abs() <= NEIGHBOUR_SLOPE * r.norm()
            });
        if !flat {
            continue;
        }
        warned.push(key);
        out.push(format!(
            "step {step}: body '{}': node {} carries {:.0} % of the contact force with '{with}' ({:.4e} of {:.4e} N), though its neighbours lie on the contact's tangent plane and could share it: the contact is resolved by one node, so the result near it (stresses, indentation) depends on the mesh; refine the body's mesh there (warned once per pair)",
            body.name,
            top.node + 1,
            100.0 * top.normal_force / total,
            top.normal_force,
            total,
        ));
    }
    out
}
