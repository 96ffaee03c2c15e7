//! Bodies prepared from triangle meshes and outlines: their volume against the mesh's, surface
//! nodes on the mesh, closed outward patches, dihedral angles, member lengths, a solve without
//! a mechanism, determinism and bad input named.

use linkage::linkage::prepare::{dihedral_angles, enclosed_volume, prepare_mesh, PreparedBody};
use linkage::linkage::{
    Body, Dimension, Equilibrium, Material, Member, NodalLoad, Schedule, Support,
};
use nalgebra::Vector3;
use std::collections::HashMap;
use std::f64::consts::PI;

/// A sphere of `radius` (m) as an icosahedron subdivided `levels` times, vertices on the
/// sphere, faces outward.
fn sphere(radius: f64, levels: usize) -> (Vec<Vector3<f64>>, Vec<[usize; 3]>) {
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<Vector3<f64>> = [
        [-1.0, g, 0.0],
        [1.0, g, 0.0],
        [-1.0, -g, 0.0],
        [1.0, -g, 0.0],
        [0.0, -1.0, g],
        [0.0, 1.0, g],
        [0.0, -1.0, -g],
        [0.0, 1.0, -g],
        [g, 0.0, -1.0],
        [g, 0.0, 1.0],
        [-g, 0.0, -1.0],
        [-g, 0.0, 1.0],
    ]
    .iter()
    .map(|p| Vector3::from(*p).normalize() * radius)
    .collect();
    let mut t: Vec<[usize; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut mid: HashMap<(usize, usize), usize> = HashMap::new();
        let mut next = Vec::new();
        for [a, b, c] in t {
            let mut m = |x: usize, y: usize| {
                *mid.entry((x.min(y), x.max(y))).or_insert_with(|| {
                    v.push(((v[x] + v[y]) / 2.0).normalize() * radius);
                    v.len() - 1
                })
            };
            let (ab, bc, ca) = (m(a, b), m(b, c), m(c, a));
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        t = next;
    }
    (v, t)
}

/// A torus about z: tube centre radius `big`, tube radius `small` (m), `n × m` quads split.
fn torus(big: f64, small: f64, n: usize, m: usize) -> (Vec<Vector3<f64>>, Vec<[usize; 3]>) {
    let mut v = Vec::new();
    for i in 0..n {
        let u = 2.0 * PI * i as f64 / n as f64;
        for j in 0..m {
            let w = 2.0 * PI * j as f64 / m as f64;
            let r = big + small * w.cos();
            v.push(Vector3::new(r * u.cos(), r * u.sin(), small * w.sin()));
        }
    }
    let id = |i: usize, j: usize| (i % n) * m + (j % m);
    let mut t = Vec::new();
    for i in 0..n {
        for j in 0..m {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            t.push([a, b, c]);
            t.push([a, c, d]);
        }
    }
    (v, t)
}

/// The distance from `p` to triangle `abc` (m), by projecting into it or onto its edges.
fn distance_to_triangle(p: Vector3<f64>, a: Vector3<f64>, b: Vector3<f64>, c: Vector3<f64>) -> f64 {
    let n = (b - a).cross(&(c - a)).normalize();
    let q = p - n * (p - a).dot(&n);
    let inside = [(a, b), (b, c), (c, a)]
        .iter()
        .all(|&(x, y)| (y - x).cross(&(q - x)).dot(&n) >= -1e-15);
    if inside {
        return (p - q).norm();
    }
    [(a, b), (b, c), (c, a)]
        .iter()
        .map(|&(x, y)| {
            let s = ((p - x).dot(&(y - x)) / (y - x).norm_squared()).clamp(0.0, 1.0);
            (p - (x + (y - x) * s)).norm()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Every check of a prepared 3D body against its mesh; returns the body for a solve.
fn check_prepared(
    name: &str,
    mesh: &(Vec<Vector3<f64>>, Vec<[usize; 3]>),
    spacing: f64,
) -> PreparedBody {
    let (v, t) = mesh;
    let p = prepare_mesh(v, t, spacing).unwrap();
    let g = &p.geometry;
    let r = &p.report;
    println!("{name}: {r}");
    // Volume from the closed patches within 2% of the mesh's.
    let mesh_volume = enclosed_volume(v, t);
    let volume = enclosed_volume(&g.nodes, &g.patches);
    assert!(
        (volume / mesh_volume - 1.0).abs() < 0.02,
        "{name}: {volume} {mesh_volume}"
    );
    assert!((r.measure - volume).abs() < 1e-12 * volume);
    // Closed and outward: every patch edge is met once each way; the volume is positive.
    let mut half_edges: HashMap<(usize, usize), i32> = HashMap::new();
    for &[a, b, c] in &g.patches {
        for (x, y) in [(a, b), (b, c), (c, a)] {
            *half_edges.entry((x.min(y), x.max(y))).or_default() += if x < y { 1 } else { -1 };
        }
    }
    assert!(
        half_edges.values().all(|&s| s == 0),
        "{name}: patches not closed"
    );
    assert!(volume > 0.0);
    // Every surface node on the mesh to 1e-9 of the bounding box (brute force over faces).
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = -lo;
    for q in v {
        lo = lo.inf(q);
        hi = hi.sup(q);
    }
    let diagonal = (hi - lo).norm();
    let mut surface: Vec<usize> = g.patches.iter().flatten().copied().collect();
    surface.sort_unstable();
    surface.dedup();
    for &n in &surface {
        let d = t
            .iter()
            .map(|&[a, b, c]| distance_to_triangle(g.nodes[n], v[a], v[b], v[c]))
            .fold(f64::INFINITY, f64::min);
        assert!(
            d < 1e-9 * diagonal,
            "{name}: surface node {n} is {d} m off the mesh"
        );
    }
    // Dihedral angles within [9°, 165°].
    let (mut small, mut large) = (f64::INFINITY, 0.0f64);
    for &c in &p.cells {
        for a in dihedral_angles(&g.nodes, c) {
            small = small.min(a.to_degrees());
            large = large.max(a.to_degrees());
        }
    }
    assert!(
        small >= 9.0 && large <= 165.0,
        "{name}: dihedral angles {small}° to {large}°"
    );
    assert!((small - r.smallest_angle).abs() < 1e-9 && (large - r.largest_angle).abs() < 1e-9);
    // Member lengths within the documented band [0.2, 1.75] × spacing.
    for &[a, b] in &g.members {
        let l = (g.nodes[a] - g.nodes[b]).norm() / spacing;
        assert!(
            (0.2..=1.75).contains(&l),
            "{name}: member {a}-{b} is {l} × spacing"
        );
    }
    p
}

/// The prepared body as a steel body with its lowest nodes held and its highest pushed down.
fn solve_under_load(name: &str, p: &PreparedBody) {
    let g = &p.geometry;
    let mut body = Body::new(name, Dimension::Three);
    body.materials.push(Material::new("steel", 200e9, 1e-6));
    body.nodes = g.nodes.clone();
    body.members = g
        .members
        .iter()
        .map(|&nodes| Member { nodes, material: 0 })
        .collect();
    body.patches = g.patches.clone();
    let zmin = g.nodes.iter().map(|q| q.z).fold(f64::INFINITY, f64::min);
    let zmax = g
        .nodes
        .iter()
        .map(|q| q.z)
        .fold(f64::NEG_INFINITY, f64::max);
    let h = p.report.spacing;
    for (n, q) in g.nodes.iter().enumerate() {
        if q.z < zmin + 0.3 * h {
            body.supports.push(Support::fixed(n, [true, true, true]));
        } else if q.z > zmax - 0.3 * h {
            body.loads.push(NodalLoad {
                node: n,
                force: Vector3::new(0.0, 0.0, -100.0),
                schedule: Schedule::Linear,
            });
        }
    }
    assert!(!body.supports.is_empty() && !body.loads.is_empty());
    let eq = Equilibrium::new(&body).unwrap_or_else(|e| panic!("{name}: {e}"));
    let state = eq
        .solve_step(&body, 1, 1)
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    let largest = state
        .displacements
        .iter()
        .map(|u| u.norm())
        .fold(0.0, f64::max);
    assert!(largest.is_finite() && largest > 0.0, "{name}: {largest}");
}

#[test]
fn a_sphere_is_filled_within_two_percent_with_bounded_angles_and_solves() {
    let mesh = sphere(0.05, 4);
    let p = check_prepared("sphere", &mesh, 0.01);
    solve_under_load("sphere", &p);
}

#[test]
fn a_torus_is_filled_within_two_percent_with_bounded_angles_and_solves() {
    let mesh = torus(0.1, 0.04, 96, 48);
    let p = check_prepared("torus", &mesh, 0.01);
    solve_under_load("torus", &p);
}

#[test]
fn the_same_mesh_gives_the_same_body_bit_for_bit() {
    let (v, t) = sphere(0.05, 3);
    let a = prepare_mesh(&v, &t, 0.012).unwrap();
    let b = prepare_mesh(&v, &t, 0.012).unwrap();
    assert_eq!(a.geometry, b.geometry);
    assert_eq!(a.cells, b.cells);
}

#[test]
fn bad_spacings_are_named_before_any_work() {
    let (v, t) = sphere(0.05, 2);
    let e = prepare_mesh(&v, &t, 0.05).unwrap_err().to_string();
    assert!(
        e.contains("larger than the part") && e.contains("0.1 m"),
        "{e}"
    );
    let e = prepare_mesh(&v, &t, 1e-5).unwrap_err().to_string();
    assert!(
        e.contains("members") && e.contains("GB") && e.contains("at least"),
        "{e}"
    );
    let e = prepare_mesh(&v, &t, -1.0).unwrap_err().to_string();
    assert!(e.contains("spacing = -1"), "{e}");
}

#[test]
fn a_degenerate_face_is_named() {
    let (mut v, mut t) = sphere(0.05, 1);
    let (a, b) = (t[3][0], t[3][1]);
    v.push((v[a] + v[b]) / 2.0);
    t[3] = [a, b, v.len() - 1];
    let e = prepare_mesh(&v, &t, 0.01).unwrap_err().to_string();
    assert!(e.contains("face 4") && e.contains("no area"), "{e}");
}
