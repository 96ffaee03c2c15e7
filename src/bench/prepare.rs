//! `linkage bench --prepare`: filling a finely triangulated torus with over 1,000,000 members
//! by isosurface stuffing: time and peak memory.

use crate::bench::lattice::peak_memory;
use crate::linkage::prepare::{prepare_mesh, PrepareReport};
use crate::Real;
use nalgebra::Vector3;
use std::f64::consts::PI;
use std::time::Instant;

/// Tube centre radius of the benchmark torus, m.
pub const RADIUS: Real = 0.1;
/// Tube radius of the benchmark torus, m.
pub const TUBE: Real = 0.04;
/// The default spacing, m: about 1.05 million members.
pub const SPACING: Real = 0.0034;

/// What one preparation took.
#[derive(Clone, Debug)]
pub struct PrepareTiming {
    /// Triangles of the mesh.
    pub triangles: usize,
    /// The prepared body's report.
    pub report: PrepareReport,
    /// Wall time of `prepare_mesh`, s.
    pub seconds: Real,
    /// Peak resident memory of the process, bytes.
    pub peak_memory: u64,
}

/// A torus about z (tube centre radius `big`, tube radius `small`, m) of `n × m` quads, each
/// split in two, faces outward.
pub fn torus_mesh(
    big: Real,
    small: Real,
    n: usize,
    m: usize,
) -> (Vec<Vector3<Real>>, Vec<[usize; 3]>) {
    let mut v = Vec::with_capacity(n * m);
    for i in 0..n {
        let u = 2.0 * PI * i as Real / n as Real;
        for j in 0..m {
            let w = 2.0 * PI * j as Real / m as Real;
            let r = big + small * w.cos();
            v.push(Vector3::new(r * u.cos(), r * u.sin(), small * w.sin()));
        }
    }
    let id = |i: usize, j: usize| (i % n) * m + (j % m);
    let mut t = Vec::with_capacity(2 * n * m);
    for i in 0..n {
        for j in 0..m {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            t.push([a, b, c]);
            t.push([a, c, d]);
        }
    }
    (v, t)
}

/// Prepare the benchmark torus (400 × 160 quads) at `spacing` (m).
pub fn measure_prepare(spacing: Real) -> Result<PrepareTiming, String> {
    let (v, t) = torus_mesh(RADIUS, TUBE, 400, 160);
    let start = Instant::now();
    let body = prepare_mesh(&v, &t, spacing).map_err(|e| e.to_string())?;
    let seconds = start.elapsed().as_secs_f64();
    Ok(PrepareTiming {
        triangles: t.len(),
        report: body.report,
        seconds,
        peak_memory: peak_memory(),
    })
}
