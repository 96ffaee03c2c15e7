//! The tie rule: what a node presses when it is equally near several patches (2D: boundary
//! segments) of a surface, so that the choice depends on neither the order of the patches nor
//! the path the solver took.
//!
//! On coincident or touching faces a node's nearest point of the other surface is often a
//! corner or an edge shared by several patches (a node of one face meets a node of the
//! other): every patch around it is then equally near, and picking "the first" (in patch order,
//! or the one the node pressed before) makes the answer depend on the order of the patches
//! (mirror-symmetric set-ups come out unsymmetric) and on the solver's path (two paths that
//! reach the same state settle on different patches and different normals).
//!
//! Used by self-contact (`contact::self_contact`); contact between bodies still keeps the patch
//! a node pressed before (`Geometry::keep_patches`): tried there, this rule settled the face
//! nodes but not the nodes at a box's edge, which lie in the other box's side planes.
//!
//! **Rule.** Of the candidate patches (those a node could press, each with its depth behind the
//! patch's plane), the *tied* ones are those within [`TIE`] times the nearest patch's longest edge of
//! the nearest. One tied patch is pressed as it is, unless the node's foot on it lies within
//! [`BAND`] of an edge or corner of it (3D): then that edge or corner, as if tied. Several tied
//! patches press their common
//! feature: the corner (2D: vertex) they all share, or the edge they share; no common node (two
//! unrelated patches exactly as near, which coincident faces do not make) falls back to the
//! lowest patch number. A feature is pressed along the area-weighted mean of the normals of
//! its patches that turn by less than 45° ([`SMOOTH_COS`]) from the tied ones (an edge: its
//! two, else the patch; a corner: on a flat or gently bent face all of them, at a box's edge
//! those of the face the node lies behind, not those of the side faces). The force goes to the
//! nearest point of the feature: an edge's two nodes share it by the node's position along the
//! edge, a corner's node takes it whole; the pressing node takes the opposite force, so the
//! pair's forces are equal and opposite. On a flat face the mean normal is the face's, and the
//! contact is the one either patch would give there.
//!
//! The rule depends only on the current positions: a state is a settled answer or not whatever
//! path reached it.

use crate::Real;
use nalgebra::Vector3;

/// Two patches are equally near a node when their distances differ by at most this fraction of
/// the nearest patch's longest edge (round-off of nodes that coincide, not a real offset: a
/// node 1e-6 of a member beside a corner of a flat face is farther from the patches it does
/// not lie in by only about (1e-6 member)² / (2 depth), which is within the tie at a depth of a
/// member's 1%; it then presses the corner, along the face's normal all the same).
pub const TIE: Real = 1e-9;

/// A node whose foot on the one patch it presses lies within this fraction of the patch (in
/// barycentric weight) of an edge or corner of it presses that edge or corner. Not round-off
/// only: where two faces meet with their nodes nearly coincident, a node settles a little to
/// one side of the other face's corner, and the patch on that side, whose normal is tilted by
/// the faces' bending, holds it there; on the other side the other patch would hold it just as
/// well, so the answer depended on the side the path came from (two boxes meeting face to
/// face: nodes 4e-4 of a patch from the corner, normals tilted ±0.013, 0.9% in
/// displacements). Within the band the corner's mean normal holds it whichever side it is on.
pub const BAND: Real = 0.01;

/// An edge or corner presses with the patches around it whose normals turn by less than 45°
/// from those the node tied on (this is the cosine): the faces of a smooth or gently bent
/// surface, not the side faces beyond a box's edge.
pub const SMOOTH_COS: Real = std::f64::consts::FRAC_1_SQRT_2;

/// The edge or corner of the triangle `corners` (node numbers, positions `position(node)`, m)
/// that the foot of `x` (m) on its plane lies within [`BAND`] of, `None` when it lies farther
/// inside (or the triangle is degenerate).
pub(crate) fn near_feature(
    x: &Vector3<Real>,
    corners: &[usize; 3],
    position: impl Fn(usize) -> Vector3<Real>,
) -> Option<Pressed> {
    let [a, b, c] = corners.map(&position);
    let cross = (b - a).cross(&(c - a));
    let area2 = cross.norm();
    if area2 <= 0.0 || !area2.is_finite() {
        return None;
    }
    let n = cross / area2;
    let p = x + n * (a - x).dot(&n);
    let wa = (b - p).cross(&(c - p)).dot(&n) / area2;
    let wb = (c - p).cross(&(a - p)).dot(&n) / area2;
    let w = [wa, wb, 1.0 - wa - wb];
    let small: Vec<usize> = (0..3).filter(|&i| w[i] <= BAND).collect();
    match small.as_slice() {
        [i, j] => Some(Pressed::Corner(corners[3 - i - j], Vec::new())),
        [i] => {
            let (p, q) = (corners[(i + 1) % 3], corners[(i + 2) % 3]);
            Some(Pressed::Edge([p.min(q), p.max(q)]))
        }
        _ => None,
    }
}

/// What a node presses among tied patches.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum Pressed {
    /// One patch (segment): its index.
    Patch(usize),
    /// The node shared by every tied patch (a corner; 2D: a vertex), and the tied patches
    /// (segments), ascending.
    Corner(usize, Vec<usize>),
    /// The two nodes shared by every tied patch (an edge, 3D), smaller first.
    Edge([usize; 2]),
}

/// One candidate patch (segment) of a node: its index, its corner nodes and its distance (m).
pub(crate) struct Candidate<'a> {
    /// Index of the patch (segment).
    pub(crate) index: usize,
    /// Its corner nodes.
    pub(crate) corners: &'a [usize],
    /// Its distance (or depth) from the node, m.
    pub(crate) distance: Real,
}

/// What a node presses among `candidates` (see the module documentation), with `margin` (m)
/// the tie's width: [`TIE`] times the nearest patch's longest edge. `None` without candidates.
pub(crate) fn pressed(candidates: &[Candidate], margin: Real) -> Option<Pressed> {
    let nearest = candidates
        .iter()
        .map(|c| c.distance)
        .fold(Real::INFINITY, Real::min);
    if !nearest.is_finite() {
        return None;
    }
    let tied: Vec<&Candidate> = candidates
        .iter()
        .filter(|c| c.distance <= nearest + margin)
        .collect();
    let lowest = tied.iter().map(|c| c.index).min()?;
    if tied.len() == 1 {
        return Some(Pressed::Patch(lowest));
    }
    let mut indices: Vec<usize> = tied.iter().map(|c| c.index).collect();
    indices.sort_unstable();
    indices.dedup();
    let mut common: Vec<usize> = tied[0].corners.to_vec();
    for c in &tied[1..] {
        common.retain(|n| c.corners.contains(n));
    }
    common.sort_unstable();
    common.dedup();
    Some(match common.as_slice() {
        [n] => Pressed::Corner(*n, indices),
        [a, b] => Pressed::Edge([*a, *b]),
        // The same patch twice (not in a valid surface) or nothing shared.
        _ => Pressed::Patch(lowest),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn candidate(index: usize, corners: &[usize], distance: Real) -> Candidate<'_> {
        Candidate {
            index,
            corners,
            distance,
        }
    }

    /// A node straight over a corner shared by four patches of a flat face presses that
    /// corner whatever the patches' order; over the edge of two, the edge; inside one, it.
    #[test]
    fn ties_press_the_shared_feature_in_any_order() {
        let fan = [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]];
        let d = 0.01;
        let all: Vec<Candidate> = (0..4).map(|i| candidate(i, &fan[i], d)).collect();
        let corner = Some(Pressed::Corner(4, vec![0, 1, 2, 3]));
        assert_eq!(pressed(&all, 1e-12), corner);
        let reversed: Vec<Candidate> = (0..4).rev().map(|i| candidate(i, &fan[i], d)).collect();
        assert_eq!(pressed(&reversed, 1e-12), corner);
        // Two of the fan tied (the others behind a sharp edge, farther): the corner, with those.
        let two = [
            candidate(0, &fan[0], d),
            candidate(2, &fan[2], d),
            candidate(1, &fan[1], 2.0 * d),
        ];
        assert_eq!(pressed(&two, 1e-12), Some(Pressed::Corner(4, vec![0, 2])));
        // Beside the corner over the edge 1–4: patches 0 and 1 at d, the others farther.
        let edge = [
            candidate(2, &fan[2], d + 1e-6),
            candidate(1, &fan[1], d),
            candidate(0, &fan[0], d + 1e-13),
            candidate(3, &fan[3], d + 1e-6),
        ];
        assert_eq!(pressed(&edge, 1e-12), Some(Pressed::Edge([1, 4])));
        let one = [candidate(2, &fan[2], d + 1e-6), candidate(3, &fan[3], d)];
        assert_eq!(pressed(&one, 1e-12), Some(Pressed::Patch(3)));
        // Two unrelated patches exactly as near: the lower number.
        let apart = [
            candidate(7, &[10, 11, 12], d),
            candidate(5, &[20, 21, 22], d),
        ];
        assert_eq!(pressed(&apart, 1e-12), Some(Pressed::Patch(5)));
        assert_eq!(pressed(&[], 1e-12), None);
    }

    /// 2D: two segments meeting at a vertex, equally deep: the vertex.
    #[test]
    fn two_segments_tied_press_their_vertex() {
        let s = [candidate(3, &[7, 8], 0.002), candidate(4, &[8, 9], 0.002)];
        assert_eq!(pressed(&s, 1e-12), Some(Pressed::Corner(8, vec![3, 4])));
    }
}
