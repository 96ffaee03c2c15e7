//! A 3D body from a closed triangle mesh: checks before any long work (faces without area,
//! faces crossing each other, spacing, memory), then isosurface
//! stuffing, the linkage and its quality report.

use super::bcc_lattice::BccLattice;
use super::closed_surface::ClosedSurface;
use super::quality::{enclosed_volume, report_3d, PrepareReport};
use super::self_intersection::check_self_intersection;
use super::stuffing::stuff;
use super::tet_mesh::TetMesh;
use super::PrepareError;
use crate::linkage::{Geometry, Interrupt};
use crate::Real;
use nalgebra::Vector3;

/// The largest spacing accepted, as a fraction of the part's smallest bounding-box extent: a
/// coarser lattice cannot put three members across the part.
pub const MAX_SPACING_FRACTION: Real = 1.0 / 3.0;

/// Memory that preparation may use, bytes (8 GB): larger bodies are refused before the work.
pub const MEMORY_LIMIT: u64 = 8_000_000_000;

/// Estimated bytes per lattice vertex (its side, position and the lists made from them).
const BYTES_PER_LATTICE_VERTEX: u64 = 64;
/// Estimated bytes per lattice cube inside the part (12 tetrahedra, their 48 faces sorted,
/// 72 member ends before duplicates go): measured peaks stay below this
/// (docs/performance-history.md, "Preparing a body from a mesh").
const BYTES_PER_INSIDE_CELL: u64 = 5_000;
/// Members per lattice cube inside the part (3 corner, 3 centre and 8 diagonal edges).
const MEMBERS_PER_CELL: u64 = 14;

/// A body prepared from a mesh or an outline: its linkage, its tetrahedra (3D) and its report.
#[derive(Clone, Debug)]
pub struct PreparedBody {
    /// Nodes, members and (3D) outward closed patches.
    pub geometry: Geometry,
    /// The tetrahedra whose edges are the members (3D; empty in 2D), 0-based node numbers.
    pub cells: Vec<[usize; 4]>,
    /// The triangles whose edges are the members (2D; empty in 3D), 0-based node numbers.
    pub triangles: Vec<[usize; 3]>,
    /// Counts, measure and quality.
    pub report: PrepareReport,
}

/// Fill the closed, outward-facing triangle mesh `triangles` over `vertices` (m) with
/// tetrahedra whose edges, about `spacing` long (m), are the members: isosurface stuffing on
/// a body-centred cubic lattice of cube side `spacing`. Surface nodes lie on the mesh.
/// The mesh must already be closed and oriented (see `orient_outward`); this checks
/// degenerate and crossing faces, the spacing against the part's size and the memory estimate first.
pub fn prepare_mesh(
    vertices: &[Vector3<Real>],
    triangles: &[[usize; 3]],
    spacing: Real,
) -> Result<PreparedBody, PrepareError> {
    prepare_mesh_until(vertices, triangles, spacing, Interrupt::default())
}

/// [`prepare_mesh`], stopped by `stop` (a run's interrupt: SIGINT, SIGTERM).
/// Once `stop` is raised the work ends between its phases ([`PrepareError::Interrupted`]); the
/// lattice's vertices are then skipped, so it ends within a fraction of a second.
pub fn prepare_mesh_until(
    vertices: &[Vector3<Real>],
    triangles: &[[usize; 3]],
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
    let mut lo = Vector3::repeat(Real::INFINITY);
    let mut hi = Vector3::repeat(-Real::INFINITY);
    for p in vertices {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let size = hi - lo;
    let diagonal = size.norm();
    for (f, &t) in triangles.iter().enumerate() {
        let [a, b, c] = t.map(|v| vertices[v]);
        // Twice the area against the diagonal squared: below 1e-12 the face is a sliver of
        // round-off and its normal meaningless.
        if (b - a).cross(&(c - a)).norm() <= 1e-12 * diagonal * diagonal {
            return Err(PrepareError::DegenerateFace {
                face: f + 1,
                vertices: t.map(|v| v + 1),
            });
        }
    }
    stopped()?;
    check_self_intersection(vertices, triangles)?;
    stopped()?;
    let volume = enclosed_volume(vertices, triangles);
    if volume.is_nan() || volume <= 1e-12 * diagonal.powi(3) {
        return Err(PrepareError::NoVolume { volume });
    }
    let extent = size.min();
    if spacing > MAX_SPACING_FRACTION * extent {
        return Err(PrepareError::SpacingTooLarge {
            spacing,
            extent,
            limit: MAX_SPACING_FRACTION * extent,
        });
    }
    let cells = size.map(|s| (s / spacing).ceil() + 2.0);
    let estimate = |h: Real| {
        let c = size.map(|s| (s / h).ceil() + 2.0);
        let lattice = 2.0 * (c.x + 1.0) * (c.y + 1.0) * (c.z + 1.0);
        let inside = volume / h.powi(3);
        (
            lattice * BYTES_PER_LATTICE_VERTEX as Real + inside * BYTES_PER_INSIDE_CELL as Real,
            inside * MEMBERS_PER_CELL as Real,
        )
    };
    let (bytes, members) = estimate(spacing);
    if bytes > MEMORY_LIMIT as Real {
        // The estimate falls like h³: the spacing that meets the limit, rounded up a little.
        let smallest = spacing * (bytes / MEMORY_LIMIT as Real).cbrt() * 1.01;
        return Err(PrepareError::TooLarge {
            spacing,
            members,
            gigabytes: bytes / 1e9,
            limit_gigabytes: MEMORY_LIMIT as Real / 1e9,
            smallest: (smallest * 1e6).ceil() / 1e6,
        });
    }
    let lattice = BccLattice {
        origin: lo - Vector3::repeat(spacing),
        h: spacing,
        cells: [cells.x as usize, cells.y as usize, cells.z as usize],
    };
    let surface = ClosedSurface::new(vertices, triangles, 1e-9 * spacing)?;
    stopped()?;
    let tets: TetMesh = stuff(&surface, &lattice, stop).ok_or(PrepareError::Interrupted)?;
    let (geometry, cells) = tets.into_geometry(spacing)?;
    stopped()?;
    let report = report_3d(&geometry, &cells, spacing, volume);
    Ok(PreparedBody {
        geometry,
        cells,
        triangles: Vec::new(),
        report,
    })
}
