//! Bodies prepared from triangle meshes and outlines: their volume against the mesh's, surface
//! nodes on the mesh, closed outward patches, dihedral angles, member lengths, a solve without
//! a mechanism, determinism and bad input named.

use linkage::bench::prepare::torus_mesh;
use linkage::linkage::prepare::{
    dihedral_angles, enclosed_volume, prepare_mesh, prepare_outline, PreparedBody,
    MIN_TRIANGLE_ANGLE,
};
use linkage::linkage::{
    Body, Dimension, Equilibrium, Material, Member, NodalLoad, Schedule, Support,
};
use nalgebra::Vector3;
use std::collections::HashMap;
use std::f64::consts::PI;
use std::path::Path;
use std::process::Command;

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
    let mesh = torus_mesh(0.1, 0.04, 96, 48);
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

/// The plate 0.4 m × 0.2 m with a 48-gon hole of radius 0.04 m at its centre.
fn plate_with_hole() -> Vec<Vec<[f64; 2]>> {
    let hole = (0..48)
        .map(|i| {
            let t = 2.0 * PI * i as f64 / 48.0;
            [0.2 + 0.04 * t.cos(), 0.1 + 0.04 * t.sin()]
        })
        .collect();
    vec![vec![[0.0, 0.0], [0.4, 0.0], [0.4, 0.2], [0.0, 0.2]], hole]
}

/// The distance from `p` to the nearest segment of the loops, m.
fn distance_to_outline(loops: &[Vec<[f64; 2]>], p: Vector3<f64>) -> f64 {
    let mut best = f64::INFINITY;
    for l in loops {
        for i in 0..l.len() {
            let (a, b) = (l[i], l[(i + 1) % l.len()]);
            let (a, b) = (Vector3::new(a[0], a[1], 0.0), Vector3::new(b[0], b[1], 0.0));
            let s = ((p - a).dot(&(b - a)) / (b - a).norm_squared()).clamp(0.0, 1.0);
            best = best.min((p - (a + (b - a) * s)).norm());
        }
    }
    best
}

#[test]
fn a_plate_with_a_hole_is_triangulated_within_half_a_percent_and_solves_in_tension() {
    let loops = plate_with_hole();
    let h = 0.01;
    let p = prepare_outline(&loops, h).unwrap();
    let g = &p.geometry;
    println!("plate: {}", p.report);
    // Area within 0.5% of the outline's (the 48-gon's area: 24 r² sin(2π/48)).
    let hole_area = 24.0 * 0.04f64.powi(2) * (2.0 * PI / 48.0).sin();
    let area = 0.08 - hole_area;
    let triangles: f64 = p
        .triangles
        .iter()
        .map(|&[a, b, c]| {
            (g.nodes[b] - g.nodes[a])
                .cross(&(g.nodes[c] - g.nodes[a]))
                .z
                / 2.0
        })
        .map(f64::abs)
        .sum();
    assert!((triangles / area - 1.0).abs() < 0.005, "{triangles} {area}");
    assert!((p.report.reference - area).abs() < 1e-12);
    // Minimum angle as documented.
    assert!(
        p.report.smallest_angle >= MIN_TRIANGLE_ANGLE,
        "{}",
        p.report.smallest_angle
    );
    // No member crossing the hole: its midpoint is not inside the hole.
    for &[a, b] in &g.members {
        let m = (g.nodes[a] + g.nodes[b]) / 2.0;
        let r = ((m.x - 0.2).powi(2) + (m.y - 0.1).powi(2)).sqrt();
        assert!(
            r > 0.04 * (PI / 48.0).cos() - 1e-12,
            "member {a}-{b} crosses the hole"
        );
    }
    // Every boundary node on the outline: edges used by one triangle.
    let mut uses: HashMap<(usize, usize), usize> = HashMap::new();
    for &[a, b, c] in &p.triangles {
        for (x, y) in [(a, b), (b, c), (c, a)] {
            *uses.entry((x.min(y), x.max(y))).or_default() += 1;
        }
    }
    let boundary: Vec<(usize, usize)> = uses
        .iter()
        .filter(|(_, &n)| n == 1)
        .map(|(e, _)| *e)
        .collect();
    assert_eq!(boundary.len(), p.report.patches);
    for &(a, b) in &boundary {
        for n in [a, b] {
            let d = distance_to_outline(&loops, g.nodes[n]);
            assert!(
                d < 1e-9 * 0.45,
                "boundary node {n} is {d} m off the outline"
            );
        }
    }
    // Held on the left edge, pulled on the right: solved, no mechanism.
    let mut body = Body::new("plate", Dimension::Two);
    body.materials.push(Material::new("steel", 200e9, 1e-5));
    body.nodes = g.nodes.clone();
    body.members = g
        .members
        .iter()
        .map(|&nodes| Member { nodes, material: 0 })
        .collect();
    for (n, q) in g.nodes.iter().enumerate() {
        if q.x < 1e-12 {
            body.supports
                .push(Support::fixed(n, [true, q.y < 1e-12, false]));
        } else if q.x > 0.4 - 1e-12 {
            body.loads.push(NodalLoad {
                node: n,
                force: Vector3::new(100.0, 0.0, 0.0),
                schedule: Schedule::Linear,
            });
        }
    }
    let eq = Equilibrium::new(&body).unwrap();
    let state = eq.solve_step(&body, 1, 1).unwrap();
    let right = g.nodes.iter().position(|q| q.x > 0.4 - 1e-12).unwrap();
    assert!(state.displacements[right].x > 0.0);
}

#[test]
fn a_bad_outline_is_named() {
    let crossing = vec![vec![[0.0, 0.0], [2.0, 2.0], [2.0, 0.0], [0.0, 1.0]]];
    let e = prepare_outline(&crossing, 0.1).unwrap_err().to_string();
    assert!(
        e.contains("segment 1 of loop 1") && e.contains("segment 3 of loop 1"),
        "{e}"
    );
    let outside = vec![
        vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
        vec![[2.0, 2.0], [3.0, 2.0], [3.0, 3.0]],
    ];
    let e = prepare_outline(&outside, 0.1).unwrap_err().to_string();
    assert!(e.contains("loop 2 (a hole)"), "{e}");
    let e = prepare_outline(&[vec![[0.0, 0.0], [1.0, 0.0]]], 0.1)
        .unwrap_err()
        .to_string();
    assert!(e.contains("loop 1 has 2 points"), "{e}");
}

fn linkage() -> Command {
    Command::new(env!("CARGO_BIN_EXE_linkage"))
}

/// A mesh as an OBJ file.
fn write_obj(path: &Path, (v, t): &(Vec<Vector3<f64>>, Vec<[usize; 3]>)) {
    let mut text = String::new();
    for p in v {
        text += &format!("v {:?} {:?} {:?}\n", p.x, p.y, p.z);
    }
    for f in t {
        text += &format!("f {} {} {}\n", f[0] + 1, f[1] + 1, f[2] + 1);
    }
    std::fs::write(path, text).unwrap();
}

#[test]
fn prepare_writes_the_paper_files_and_the_report_the_same_every_time() {
    let dir = tempfile::tempdir().unwrap();
    // Faces turned inward: the command turns them out, as for obstacles.
    let (v, t) = sphere(0.05, 3);
    let inward: Vec<[usize; 3]> = t.iter().map(|&[a, b, c]| [a, c, b]).collect();
    let obj = dir.path().join("ball.obj");
    write_obj(&obj, &(v, inward));
    let mut files = Vec::new();
    for run in ["a", "b"] {
        let out = dir.path().join(run);
        let o = linkage()
            .args([
                "prepare",
                obj.to_str().unwrap(),
                "--spacing",
                "0.01",
                "--out",
            ])
            .arg(&out)
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&o.stdout);
        assert!(
            o.status.success(),
            "{stdout} {}",
            String::from_utf8_lossy(&o.stderr)
        );
        for word in [
            "nodes",
            "members",
            "patches",
            "volume",
            "member length",
            "dihedral angle",
            "as a solid (uniaxial tests of the lattice): Young's modulus",
            "Poisson's ratio",
        ] {
            assert!(stdout.contains(word), "{word}: {stdout}");
        }
        files.push(
            ["nodes", "links", "patches"]
                .map(|e| std::fs::read(out.join(format!("ball.{e}"))).unwrap()),
        );
    }
    assert_eq!(
        files[0], files[1],
        "the same input gives byte-identical files"
    );
    assert!(!files[0][2].is_empty());
}

#[test]
fn an_open_mesh_is_named_by_its_edge() {
    let dir = tempfile::tempdir().unwrap();
    let (v, mut t) = sphere(0.05, 1);
    t.remove(7);
    let obj = dir.path().join("open.obj");
    write_obj(&obj, &(v, t));
    let o = linkage()
        .args([
            "prepare",
            obj.to_str().unwrap(),
            "--spacing",
            "0.01",
            "--out",
        ])
        .arg(dir.path().join("out"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        stderr.contains("open.obj")
            && stderr.contains("the edge from vertex")
            && stderr.contains("open there"),
        "{stderr}"
    );
    assert!(!dir.path().join("out").join("open.nodes").exists());
}

#[test]
fn a_run_of_a_prepared_body_records_the_report_in_its_summary() {
    let dir = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    for (scene, body) in [("ring_press", "ring"), ("plate_with_hole", "plate")] {
        let o = linkage()
            .arg("run")
            .arg(root.join(format!("{scene}.toml")))
            .arg("--out")
            .arg(dir.path())
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let summary: serde_json::Value = serde_json::from_slice(
            &std::fs::read(dir.path().join(scene).join("summary.json")).unwrap(),
        )
        .unwrap();
        let report = &summary["prepared"][body];
        assert!(report["members"].as_u64().unwrap() > 1000, "{report}");
        assert!(
            report["relative_error"].as_f64().unwrap().abs() < 0.03,
            "{report}"
        );
    }
}

#[test]
fn a_self_intersecting_mesh_is_named_by_its_faces() {
    // Two closed spheres overlapping: orientation is fine, but their faces cross.
    let (mut v, mut t) = sphere(0.05, 2);
    let (v2, t2) = sphere(0.05, 2);
    let n = v.len();
    v.extend(v2.iter().map(|p| p + Vector3::new(0.03, 0.0, 0.0)));
    t.extend(t2.iter().map(|f| f.map(|i| i + n)));
    let e = prepare_mesh(&v, &t, 0.01).unwrap_err().to_string();
    assert!(e.contains("cross each other") && e.contains("face "), "{e}");
    // The same spheres apart are two pieces: prepared (no crossing), but refused as a mechanism.
    let mut apart = v.clone();
    for p in &mut apart[n..] {
        p.x += 0.2;
    }
    let e = prepare_mesh(&apart, &t, 0.01).unwrap_err().to_string();
    assert!(e.contains("falls into 2 pieces"), "{e}");
}
