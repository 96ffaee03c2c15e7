//! Isosurface stuffing (Labelle & Shewchuk, SIGGRAPH 2007): a BCC lattice over the part, cut
//! points where lattice edges leave the surface, lattice vertices too near a cut point warped
//! onto it, and each lattice tetrahedron replaced by the stencil of its vertex signs.
//!
//! Quadrilaterals that the stencils make on lattice faces are split through their vertex of
//! smallest id, so neighbouring tetrahedra agree across every face and every prism has a
//! vertex on two of its diagonals (the split of Dompierre et al. 1999 needs no extra point).
//! The paper's thresholds α_long = 0.24999 and α_short = 0.41189 bound the dihedral angles
//! (10.7° to 164.8° in the paper, for its parity rule; the tests measure ours).

use super::bcc_lattice::{BccLattice, EdgeKind};
use super::closed_surface::{ClosedSurface, Side};
use super::tet_mesh::TetMesh;
use crate::linkage::Interrupt;
use crate::Real;
use nalgebra::Vector3;
use rayon::prelude::*;
use std::collections::HashMap;

/// Warping threshold of long lattice edges, as a fraction of their length (the paper's value).
pub const ALPHA_LONG: Real = 0.24999;
/// Warping threshold of short lattice edges, as a fraction of their length (the paper's value).
pub const ALPHA_SHORT: Real = 0.41189;

/// Where a lattice edge crosses the surface.
struct Cut {
    /// The inside end, the outside end (lattice ids).
    ends: [usize; 2],
    /// Parameter of the crossing from the inside end, in (0, 1).
    t: Real,
    /// The crossing, on the mesh, m.
    point: Vector3<Real>,
    /// Long or short edge.
    kind: EdgeKind,
    /// False once an end has been warped onto the surface.
    alive: bool,
}

/// Fill `surface` over `lattice` with tetrahedra: node ids below the lattice's vertex count
/// are (possibly warped) lattice vertices, the rest cut points. `None` once `stop` is raised:
/// the vertices left are then skipped and the work ends at the next phase.
pub(crate) fn stuff(
    surface: &ClosedSurface,
    lattice: &BccLattice,
    stop: Interrupt,
) -> Option<TetMesh> {
    let count = lattice.vertex_count();
    let (mut side, mut position): (Vec<Side>, Vec<Vector3<Real>>) = (0..count)
        .into_par_iter()
        .map(|id| {
            let p = lattice.position(id);
            if stop.is_raised() {
                return (Side::Outside, p);
            }
            let (s, nearest) = surface.side(&p);
            // A vertex on the surface is moved onto it exactly.
            (s, if s == Side::On { nearest } else { p })
        })
        .unzip();

    // Lattice edges whose ends are strictly on opposite sides, in the lattice's edge order.
    let mut crossing = Vec::new();
    lattice.for_each_edge(|a, b, kind| match (side[a], side[b]) {
        (Side::Inside, Side::Outside) => crossing.push(([a, b], kind)),
        (Side::Outside, Side::Inside) => crossing.push(([b, a], kind)),
        _ => {}
    });
    if stop.is_raised() {
        return None;
    }
    let mut cuts: Vec<Cut> = crossing
        .into_par_iter()
        .map(|(ends, kind)| {
            let (t, point) = surface.crossing(&position[ends[0]], &position[ends[1]]);
            Cut {
                ends,
                t,
                point,
                kind,
                alive: true,
            }
        })
        .collect();

    // The cuts on the edges of each vertex, vertex by vertex.
    let mut at_vertex: Vec<(usize, usize)> = cuts
        .iter()
        .enumerate()
        .flat_map(|(c, cut)| [(cut.ends[0], c), (cut.ends[1], c)])
        .collect();
    at_vertex.sort_unstable();
    // Warp, vertex by vertex in id order: a vertex nearer a cut on one of its edges than α
    // times that edge moves onto the nearest such cut, and the cuts of its edges vanish.
    let mut start = 0;
    while start < at_vertex.len() {
        let v = at_vertex[start].0;
        let end = start + at_vertex[start..].partition_point(|&(w, _)| w == v);
        let mut nearest: Option<(Real, usize)> = None;
        for &(_, c) in &at_vertex[start..end] {
            let cut = &cuts[c];
            if !cut.alive {
                continue;
            }
            let t = if cut.ends[0] == v { cut.t } else { 1.0 - cut.t };
            let alpha = match cut.kind {
                EdgeKind::Long => ALPHA_LONG,
                EdgeKind::Short => ALPHA_SHORT,
            };
            let distance = (cut.point - position[v]).norm();
            if t < alpha && nearest.is_none_or(|(d, _)| distance < d) {
                nearest = Some((distance, c));
            }
        }
        if let Some((_, c)) = nearest {
            position[v] = cuts[c].point;
            side[v] = Side::On;
            for &(_, c) in &at_vertex[start..end] {
                cuts[c].alive = false;
            }
        }
        start = end;
    }

    if stop.is_raised() {
        return None;
    }
    // Node ids: lattice vertices, then the cuts that survived.
    let mut cut_id: HashMap<(usize, usize), usize> = HashMap::new();
    for (c, cut) in cuts.iter().enumerate() {
        if cut.alive {
            let [a, b] = cut.ends;
            cut_id.insert((a.min(b), a.max(b)), count + c);
            position.push(cut.point);
        } else {
            position.push(Vector3::zeros());
        }
    }
    let cut = |a: usize, b: usize| cut_id[&(a.min(b), a.max(b))];

    let mut tets = Vec::new();
    lattice.for_each_tet(|t| {
        let (mut neg, mut zero, mut pos) = (Vec::new(), Vec::new(), Vec::new());
        for v in t {
            match side[v] {
                Side::Inside => neg.push(v),
                Side::On => zero.push(v),
                Side::Outside => pos.push(v),
            }
        }
        match (neg.len(), zero.len(), pos.len()) {
            (0, 4, 0) => {
                // On the surface all round: inside if its centre is.
                let centre = t.iter().map(|&v| position[v]).sum::<Vector3<Real>>() / 4.0;
                if surface.side(&centre).0 == Side::Inside {
                    tets.push(t);
                }
            }
            (0, _, _) => {}
            (_, _, 0) => tets.push(t),
            (1, 0, 3) => {
                let a = neg[0];
                tets.push([a, cut(a, pos[0]), cut(a, pos[1]), cut(a, pos[2])]);
            }
            (1, 1, 2) => {
                let a = neg[0];
                tets.push([a, zero[0], cut(a, pos[0]), cut(a, pos[1])]);
            }
            (1, 2, 1) => {
                let a = neg[0];
                tets.push([a, zero[0], zero[1], cut(a, pos[0])]);
            }
            (2, 1, 1) => {
                let (a, b, p) = (neg[0], neg[1], pos[0]);
                split_pyramid(zero[0], [a, b, cut(b, p), cut(a, p)], &mut tets);
            }
            (2, 0, 2) => {
                let (a, b, p, q) = (neg[0], neg[1], pos[0], pos[1]);
                split_prism(
                    [a, cut(a, p), cut(a, q)],
                    [b, cut(b, p), cut(b, q)],
                    &mut tets,
                );
            }
            (3, 0, 1) => {
                let p = pos[0];
                split_prism(
                    [neg[0], neg[1], neg[2]],
                    [cut(neg[0], p), cut(neg[1], p), cut(neg[2], p)],
                    &mut tets,
                );
            }
            _ => unreachable!("four signs always fall in one of the cases above"),
        }
    });
    (!stop.is_raised()).then_some(TetMesh {
        nodes: position,
        tets,
    })
}

/// The pyramid over the quadrilateral `quad` (in cyclic order) with apex `apex` as two
/// tetrahedra, the quadrilateral split through its vertex of smallest id.
fn split_pyramid(apex: usize, quad: [usize; 4], out: &mut Vec<[usize; 4]>) {
    let [q0, q1, q2, q3] = quad;
    if q0.min(q2) < q1.min(q3) {
        out.push([apex, q0, q1, q2]);
        out.push([apex, q0, q2, q3]);
    } else {
        out.push([apex, q1, q2, q3]);
        out.push([apex, q1, q3, q0]);
    }
}

/// The triangular prism with ends `top` and `bottom` (`top[i]` joined to `bottom[i]`) as three
/// tetrahedra, each side split through its vertex of smallest id (never cyclic: the smallest
/// vertex of the prism lies on two of the diagonals).
fn split_prism(top: [usize; 3], bottom: [usize; 3], out: &mut Vec<[usize; 4]>) {
    let all = [top[0], top[1], top[2], bottom[0], bottom[1], bottom[2]];
    let smallest = (0..6).min_by_key(|&i| all[i]).unwrap_or(0);
    let (t, b) = if smallest < 3 {
        (top, bottom)
    } else {
        (bottom, top)
    };
    let i = smallest % 3;
    let t = [t[i], t[(i + 1) % 3], t[(i + 2) % 3]];
    let b = [b[i], b[(i + 1) % 3], b[(i + 2) % 3]];
    out.push([t[0], b[0], b[1], b[2]]);
    // The side t1 b1 b2 t2, split through its smallest vertex.
    if t[1].min(b[2]) < b[1].min(t[2]) {
        out.push([t[0], t[1], b[1], b[2]]);
        out.push([t[0], t[1], b[2], t[2]]);
    } else {
        out.push([t[0], t[1], b[1], t[2]]);
        out.push([t[0], t[2], b[1], b[2]]);
    }
}
