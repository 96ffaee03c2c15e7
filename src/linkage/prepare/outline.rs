//! A 2D body from an outline: loops of points (the first the outside, the others holes)
//! triangulated by `spade`'s constrained Delaunay triangulation with Ruppert refinement; the
//! triangles' edges are the members.

use super::mesh_body::PreparedBody;
use super::quality::finish;
use super::PrepareError;
use crate::linkage::{Dimension, Geometry, Interrupt};
use crate::Real;
use nalgebra::Vector3;
use spade::{
    AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation,
};

/// The smallest angle refinement asks for, degrees (Ruppert's algorithm terminates below
/// about 30°; input corners sharper than this keep their own angle).
pub const MIN_TRIANGLE_ANGLE: Real = 25.0;

/// Largest triangles allowed, as a multiple of the equilateral triangle of side `spacing`.
const AREA_FACTOR: Real = 1.0;

/// Most triangles an outline may make before it is refused (the memory estimate in 2D).
pub const MAX_TRIANGLES: u64 = 20_000_000;

/// Twice the signed area of a loop, m² (positive counter-clockwise).
fn twice_area(points: &[[Real; 2]]) -> Real {
    (0..points.len())
        .map(|i| {
            let (p, q) = (points[i], points[(i + 1) % points.len()]);
            p[0] * q[1] - q[0] * p[1]
        })
        .sum()
}

/// Whether segments `ab` and `cd` cross or touch (shared end points excepted by the caller).
fn segments_meet(a: [Real; 2], b: [Real; 2], c: [Real; 2], d: [Real; 2]) -> bool {
    let orient = |p: [Real; 2], q: [Real; 2], r: [Real; 2]| {
        (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])
    };
    let (d1, d2) = (orient(a, b, c), orient(a, b, d));
    let (d3, d4) = (orient(c, d, a), orient(c, d, b));
    d1 * d2 <= 0.0 && d3 * d4 <= 0.0 && (d1 != 0.0 || d2 != 0.0 || d3 != 0.0 || d4 != 0.0)
}

/// Whether `p` is inside the loop `points` (even–odd rule).
fn inside(points: &[[Real; 2]], p: [Real; 2]) -> bool {
    let mut inside = false;
    for i in 0..points.len() {
        let (a, b) = (points[i], points[(i + 1) % points.len()]);
        if (a[1] > p[1]) != (b[1] > p[1])
            && p[0] < a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1])
        {
            inside = !inside;
        }
    }
    inside
}

/// Check the loops: three or more distinct points each, an area, no crossing segments, holes
/// inside the outside loop. Numbers in messages are 1-based.
fn check_loops(loops: &[Vec<[Real; 2]>]) -> Result<Real, PrepareError> {
    let fail = |m: String| Err(PrepareError::Outline(m));
    if loops.is_empty() {
        return fail("no points: give the outside loop as \"x y\" lines".to_string());
    }
    let mut area = 0.0;
    for (l, points) in loops.iter().enumerate() {
        if points.len() < 3 {
            return fail(format!(
                "loop {} has {} points: a loop needs 3 or more",
                l + 1,
                points.len()
            ));
        }
        if let Some(p) = points.iter().flatten().find(|v| !v.is_finite()) {
            return fail(format!(
                "loop {} has the coordinate {p}: give finite numbers in metres",
                l + 1
            ));
        }
        let a = twice_area(points).abs() / 2.0;
        if a == 0.0 {
            return fail(format!("loop {} encloses no area", l + 1));
        }
        area += if l == 0 { a } else { -a };
        if l > 0 && !inside(&loops[0], points[0]) {
            return fail(format!(
                "loop {} (a hole) starts at {:?}, outside the outside loop (loop 1): holes lie inside the first loop",
                l + 1,
                points[0]
            ));
        }
    }
    // Segments, as (loop, index); O(n²), which outlines of a few thousand points afford.
    let segments: Vec<(usize, usize)> = loops
        .iter()
        .enumerate()
        .flat_map(|(l, p)| (0..p.len()).map(move |i| (l, i)))
        .collect();
    if segments.len() > 20_000 {
        return fail(format!(
            "{} segments: give at most 20,000 (coarsen the outline)",
            segments.len()
        ));
    }
    let ends = |(l, i): (usize, usize)| (loops[l][i], loops[l][(i + 1) % loops[l].len()]);
    for (x, &s) in segments.iter().enumerate() {
        for &t in &segments[x + 1..] {
            let (n_s, n_t) = (loops[s.0].len(), loops[t.0].len());
            let adjacent = s.0 == t.0 && ((s.1 + 1) % n_s == t.1 || (t.1 + 1) % n_t == s.1);
            let ((a, b), (c, d)) = (ends(s), ends(t));
            if !adjacent && segments_meet(a, b, c, d) {
                return fail(format!(
                    "segment {} of loop {} (from {a:?} to {b:?}) meets segment {} of loop {} (from {c:?} to {d:?}): loops must not cross or touch",
                    s.1 + 1,
                    s.0 + 1,
                    t.1 + 1,
                    t.0 + 1
                ));
            }
        }
    }
    if area <= 0.0 {
        return fail("the holes cover the outside loop".to_string());
    }
    Ok(area)
}

/// Triangulate the outline `loops` (m; the first loop the outside, the others holes, either
/// orientation) with triangles of edges about `spacing` (m), every angle at least
/// [`MIN_TRIANGLE_ANGLE`] except at sharper input corners. Boundary nodes lie on the outline;
/// its segments are split to at most `spacing` first.
pub fn prepare_outline(
    loops: &[Vec<[Real; 2]>],
    spacing: Real,
) -> Result<PreparedBody, PrepareError> {
    prepare_outline_until(loops, spacing, Interrupt::default())
}

/// [`prepare_outline`], stopping with [`PrepareError::Interrupted`] once `stop` is raised:
/// between the outline's segments and phases, and within 50 ms during the refinement, which
/// `spade` does in one call: it runs on a thread of its own that is left to finish (its result
/// dropped) when the stop comes. Uninterrupted, the body is the same.
pub fn prepare_outline_until(
    loops: &[Vec<[Real; 2]>],
    spacing: Real,
    stop: Interrupt,
) -> Result<PreparedBody, PrepareError> {
    let stopped = || {
        if stop.is_raised() {
            Err(PrepareError::Interrupted)
        } else {
            Ok(())
        }
    };
    if !(spacing.is_finite() && spacing > 0.0) {
        return Err(PrepareError::BadSpacing { spacing });
    }
    let area = check_loops(loops)?;
    let (mut lo, mut hi) = ([Real::INFINITY; 2], [-Real::INFINITY; 2]);
    for p in &loops[0] {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let extent = (hi[0] - lo[0]).min(hi[1] - lo[1]);
    if spacing > super::MAX_SPACING_FRACTION * extent {
        return Err(PrepareError::SpacingTooLarge {
            spacing,
            extent,
            limit: super::MAX_SPACING_FRACTION * extent,
        });
    }
    let equilateral = 3f64.sqrt() / 4.0 * spacing * spacing;
    let triangles = 2.0 * area / equilateral;
    if triangles > MAX_TRIANGLES as Real {
        let smallest = spacing * (triangles / MAX_TRIANGLES as Real).sqrt() * 1.01;
        return Err(PrepareError::TooLarge {
            spacing,
            members: 1.5 * triangles,
            gigabytes: triangles * 400.0 / 1e9,
            limit_gigabytes: MAX_TRIANGLES as Real * 400.0 / 1e9,
            smallest: (smallest * 1e6).ceil() / 1e6,
        });
    }
    let spade_error = |e: spade::InsertionError| {
        PrepareError::Outline(format!("a point cannot be triangulated: {e:?}"))
    };
    let mut cdt = ConstrainedDelaunayTriangulation::<Point2<Real>>::new();
    for points in loops {
        stopped()?;
        let mut handles = Vec::new();
        for i in 0..points.len() {
            let (a, b) = (points[i], points[(i + 1) % points.len()]);
            let length = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
            let pieces = (length / spacing).ceil().max(1.0) as usize;
            for k in 0..pieces {
                let s = k as Real / pieces as Real;
                let p = Point2::new(a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1]));
                handles.push(cdt.insert(p).map_err(spade_error)?);
            }
        }
        for i in 0..handles.len() {
            cdt.add_constraint(handles[i], handles[(i + 1) % handles.len()]);
        }
    }
    stopped()?;
    let parameters = RefinementParameters::<Real>::new()
        .with_angle_limit(AngleLimit::from_deg(MIN_TRIANGLE_ANGLE))
        .with_max_allowed_area(AREA_FACTOR * equilateral)
        .with_max_additional_vertices((4.0 * triangles) as usize + 1000)
        .exclude_outer_faces(true);
    let (send, receive) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let result = cdt.refine(parameters);
        // The receiver is gone when the preparation was interrupted: nothing to hand over.
        let _ = send.send((cdt, result));
    });
    let (cdt, result) = loop {
        match receive.recv_timeout(std::time::Duration::from_millis(50)) {
            Ok(refined) => break refined,
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => stopped()?,
            Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
                return Err(PrepareError::Outline(
                    "the refinement of the triangulation failed (spade panicked): smooth the outline or change the spacing".to_string(),
                ))
            }
        }
    };
    stopped()?;
    if !result.refinement_complete {
        return Err(PrepareError::Outline(format!(
            "refinement to {MIN_TRIANGLE_ANGLE}° did not finish: an input corner is too sharp or two loops are too close for spacing {spacing} m; give a smaller spacing or smooth the outline"
        )));
    }
    let mut excluded = vec![false; cdt.num_all_faces()];
    for f in &result.excluded_faces {
        excluded[f.index()] = true;
    }
    let mut new_id = vec![usize::MAX; cdt.num_vertices()];
    let mut nodes = Vec::new();
    let mut faces = Vec::new();
    for face in cdt.inner_faces() {
        if excluded[face.fix().index()] {
            continue;
        }
        faces.push(face.vertices().map(|v| v.fix().index()));
    }
    // Nodes in spade's vertex order (the outline's points first).
    for f in &faces {
        for &v in f {
            new_id[v] = 0;
        }
    }
    for (v, id) in new_id.iter_mut().enumerate() {
        if *id == 0 {
            *id = nodes.len();
            let p = cdt
                .vertex(spade::handles::FixedVertexHandle::from_index(v))
                .position();
            nodes.push(Vector3::new(p.x, p.y, 0.0));
        }
    }
    let triangles: Vec<[usize; 3]> = faces.iter().map(|f| f.map(|v| new_id[v])).collect();
    let mut members: Vec<[usize; 2]> = triangles
        .iter()
        .flat_map(|&[a, b, c]| [[a, b], [b, c], [c, a]])
        .map(|[a, b]| [a.min(b), a.max(b)])
        .collect();
    members.sort_unstable();
    let boundary = members
        .chunk_by(|a, b| a == b)
        .filter(|c| c.len() == 1)
        .count();
    members.dedup();
    let (mut small, mut large) = (Real::INFINITY, 0.0 as Real);
    let mut measure = 0.0;
    for &[a, b, c] in &triangles {
        let p = [nodes[a], nodes[b], nodes[c]];
        measure += (p[1] - p[0]).cross(&(p[2] - p[0])).z.abs() / 2.0;
        for k in 0..3 {
            let (u, v) = (p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
            let angle = (u.dot(&v) / (u.norm() * v.norm())).clamp(-1.0, 1.0).acos();
            small = small.min(angle);
            large = large.max(angle);
        }
    }
    let geometry = Geometry {
        dimension: Dimension::Two,
        nodes,
        members,
        patches: Vec::new(),
    };
    let mut report = finish(&geometry, spacing, measure, area, small, large);
    report.patches = boundary;
    Ok(PreparedBody {
        geometry,
        cells: Vec::new(),
        triangles,
        report,
    })
}
