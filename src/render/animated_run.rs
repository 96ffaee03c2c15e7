//! A run as an animation: each body's drawn surface (patches, or its members as lines), its
//! magnified positions, stress values, broken members and contact forces at each kept frame,
//! and each obstacle's offsets. One pass over the results that both the glTF file
//! ([`crate::render::gltf`]) and the report's viewer ([`crate::render::viewer`]) read.

use crate::render::deformed_body::vec3;
use crate::render::draw3d::node_stresses;
use crate::scene::{ModelBody, RunResults, StepResult};
use crate::Real;

/// Stored steps per second of animation when the steps carry no time (quasi-static runs):
/// the i-th stored step is shown at `i / FRAME_RATE` s.
pub const FRAME_RATE: Real = 10.0;

/// The time of stored step `step`, s, when its file carries one. The step files of this
/// version hold none (quasi-static runs); when a dynamic run's steps gain `time`, this returns
/// it, and every animation follows it.
pub fn stored_time(step: &StepResult) -> Option<Real> {
    step.time
}

/// How much of a run an animation may hold: long or large runs keep evenly spaced frames.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameBudget {
    /// Most frames kept (≥ 2).
    pub max_frames: usize,
    /// Most `frames × vertices` (over all bodies) kept: positions are 12 bytes each.
    pub max_vertex_frames: usize,
}

/// One kept frame: which stored step it shows and when.
#[derive(Clone, Debug, PartialEq)]
pub struct AnimationFrame {
    /// The stored step number.
    pub step: usize,
    /// Its load factor.
    pub load_factor: Real,
    /// When it is shown, s: the step's time in a dynamic run, else its place among the stored
    /// steps over [`FRAME_RATE`].
    pub time: Real,
}

/// What a body is drawn as.
#[derive(Clone, Debug, PartialEq)]
pub enum BodyShape {
    /// A 3D body's surface patches, as vertex triples (0-based vertex indices).
    Surface(Vec<[u32; 3]>),
    /// A 2D body, or a 3D one without patches: its members as vertex pairs, in member order.
    Lines(Vec<[u32; 2]>),
}

/// One body of the animation.
#[derive(Clone, Debug, PartialEq)]
pub struct AnimatedBody {
    /// Body name.
    pub name: String,
    /// 2 or 3.
    pub dimension: usize,
    /// The drawn shape over the vertices.
    pub shape: BodyShape,
    /// The model's node (0-based) of each vertex: the surface's nodes and those of members
    /// that break or contacts (a surface body); every node (lines).
    pub nodes: Vec<usize>,
    /// Undeformed position of each vertex, m.
    pub rest: Vec<[f32; 3]>,
    /// Per frame, the drawn position of each vertex (undeformed + magnification ×
    /// displacement), m.
    pub positions: Vec<Vec<[f32; 3]>>,
    /// Per frame, the stress that colours each vertex (surface: the mean stress of the
    /// members at its node) or each line (its member's), Pa, tension positive.
    pub stress: Vec<Vec<f32>>,
    /// Per frame, the same places' stress over the strength in that sense (surface: the
    /// largest over the node's members); `None` when the body's materials give no strength.
    pub ratio: Option<Vec<Vec<f32>>>,
    /// Per frame, the members broken so far as vertex pairs.
    pub broken: Vec<Vec<[u32; 2]>>,
    /// Per frame, the contacts' vertices and the forces they receive, N.
    pub contacts: Vec<Vec<(u32, [f32; 3])>>,
}

/// One rigid obstacle of the animation.
#[derive(Clone, Debug, PartialEq)]
pub struct AnimatedObstacle {
    /// Obstacle name.
    pub name: String,
    /// Surface vertices at step 0, m.
    pub vertices: Vec<[f32; 3]>,
    /// Triangles (0-based vertex indices).
    pub triangles: Vec<[u32; 3]>,
    /// Translation at each frame, m.
    pub offsets: Vec<[f32; 3]>,
}

/// A run as an animation (see the module's documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct AnimatedRun {
    /// Scene name.
    pub scene: String,
    /// Whether any body is 3D.
    pub is_3d: bool,
    /// Displacements are drawn this many times larger than they are.
    pub magnification: Real,
    /// The kept frames, in step order.
    pub frames: Vec<AnimationFrame>,
    /// How many steps are stored (the frames are all of them unless decimated).
    pub stored_steps: usize,
    /// Whether `frames` come from the steps' own times (a dynamic run).
    pub timed: bool,
    /// What the frames' load factor is called: "load factor", or "step fraction" when it is
    /// not what the schedules say ([`crate::scene::load_name`]; "load factor" unless set).
    pub load_name: &'static str,
    /// The unit direction that stands up (`model.json`'s `up`; `None`: +y).
    pub up: Option<[Real; 3]>,
    /// Every body, in scene order.
    pub bodies: Vec<AnimatedBody>,
    /// Every obstacle, in scene order.
    pub obstacles: Vec<AnimatedObstacle>,
    /// Largest |stress| over the kept frames, bodies and drawn places, Pa (the colour range).
    pub stress_limit: Real,
    /// Largest contact force at a node over the kept frames, N.
    pub max_contact: Real,
}

/// The indices (into `0..n`) of at most `max` (≥ 2) evenly spaced items, first and last
/// included: item `round(i (n − 1) / (max − 1))` for i = 0..max.
pub fn evenly_spaced(n: usize, max: usize) -> Vec<usize> {
    let max = max.max(2);
    if n <= max {
        return (0..n).collect();
    }
    let mut kept: Vec<usize> = (0..max)
        .map(|i| ((i as f64) * ((n - 1) as f64) / ((max - 1) as f64)).round() as usize)
        .collect();
    kept.dedup();
    kept
}

/// Whether member stresses of `body` can be given over strengths.
fn has_strengths(body: &ModelBody) -> bool {
    body.strengths
        .iter()
        .any(|s| s[0].is_some() || s[1].is_some())
}

/// |σ| over member j's strength in the sense of σ (0 where it has none).
fn member_ratio(body: &ModelBody, j: usize, stress: Real) -> Real {
    let limit = body
        .strengths
        .get(j)
        .and_then(|s| if stress >= 0.0 { s[0] } else { s[1] });
    match limit {
        Some(l) if l > 0.0 => stress.abs() / l,
        _ => 0.0,
    }
}

fn f32x3(p: nalgebra::Vector3<Real>) -> [f32; 3] {
    [p.x as f32, p.y as f32, p.z as f32]
}

impl AnimatedRun {
    /// The animation of `run` with displacements drawn `magnification` times larger, the
    /// frames `budget` allows (evenly spaced stored steps, first and last kept) and `time_of`
    /// giving a step's time, s, when the run has one (all kept steps must have one, rising,
    /// or the frame rate is used).
    pub fn of_run(
        run: &RunResults,
        magnification: Real,
        budget: FrameBudget,
        time_of: impl Fn(&StepResult) -> Option<Real>,
    ) -> AnimatedRun {
        let model = &run.model;
        // The vertices of every body first: they fix the cost of a frame.
        let shapes: Vec<(BodyShape, Vec<usize>)> = model
            .bodies
            .iter()
            .enumerate()
            .map(|(b, body)| body_vertices(body, run, b))
            .collect();
        let vertices: usize = shapes.iter().map(|(_, v)| v.len()).sum::<usize>().max(1);
        let max = budget
            .max_frames
            .min(budget.max_vertex_frames / vertices)
            .max(2);
        let kept = evenly_spaced(run.steps.len(), max);
        let steps: Vec<&StepResult> = kept.iter().map(|&i| &run.steps[i]).collect();
        let times: Vec<Option<Real>> = steps.iter().map(|s| time_of(s)).collect();
        let timed = !times.is_empty()
            && times.iter().all(|t| t.is_some_and(Real::is_finite))
            && times.windows(2).all(|w| w[0] < w[1]);
        let frames = steps
            .iter()
            .zip(&kept)
            .zip(&times)
            .map(|((s, &i), t)| AnimationFrame {
                step: s.step,
                load_factor: s.load_factor,
                time: match t {
                    Some(t) if timed => *t,
                    _ => i as Real / FRAME_RATE,
                },
            })
            .collect();
        let mut stress_limit: Real = 0.0;
        let mut max_contact: Real = 0.0;
        let bodies = model
            .bodies
            .iter()
            .zip(shapes)
            .enumerate()
            .map(|(b, (body, (shape, nodes)))| {
                let a = animate_body(body, shape, nodes, &steps, b, magnification);
                for v in a.stress.iter().flatten() {
                    stress_limit = stress_limit.max(v.abs() as Real);
                }
                for (_, f) in a.contacts.iter().flatten() {
                    let m = f.iter().map(|c| (*c as Real).powi(2)).sum::<Real>().sqrt();
                    max_contact = max_contact.max(m);
                }
                a
            })
            .collect();
        let obstacles = model
            .obstacles
            .iter()
            .map(|o| AnimatedObstacle {
                name: o.name.clone(),
                vertices: o.vertices.iter().map(|v| v.map(|c| c as f32)).collect(),
                triangles: o
                    .triangles
                    .iter()
                    .map(|t| t.map(|k| k.saturating_sub(1) as u32))
                    .collect(),
                offsets: steps
                    .iter()
                    .map(|s| {
                        let d = o
                            .offsets
                            .get(s.step)
                            .or(o.offsets.last())
                            .copied()
                            .unwrap_or([0.0; 3]);
                        d.map(|c| c as f32)
                    })
                    .collect(),
            })
            .collect();
        AnimatedRun {
            scene: model.scene.clone(),
            is_3d: model.bodies.iter().any(|b| b.dimension == 3),
            magnification,
            frames,
            stored_steps: run.steps.len(),
            timed,
            load_name: crate::scene::load_name(false),
            up: model.up,
            bodies,
            obstacles,
            stress_limit,
            max_contact,
        }
    }

    /// Whether frames were left out to fit the budget.
    pub fn decimated(&self) -> bool {
        self.frames.len() < self.stored_steps
    }
}

/// The drawn shape of body `b` of `run` and the model node of each of its vertices.
fn body_vertices(body: &ModelBody, run: &RunResults, b: usize) -> (BodyShape, Vec<usize>) {
    let n = body.nodes.len();
    let ok = |k: usize| (1..=n).contains(&k);
    if body.dimension == 3 && !body.patches.is_empty() {
        // The surface's nodes, and those of members that break or of contacts at any step.
        let mut used = vec![false; n];
        for p in &body.patches {
            for &k in p.iter().filter(|&&k| ok(k)) {
                used[k - 1] = true;
            }
        }
        for s in &run.steps {
            let Some(r) = s.bodies.get(b) else { continue };
            for &j in r.fracture.iter().flat_map(|f| &f.broken) {
                for &k in body.members.get(j.wrapping_sub(1)).into_iter().flatten() {
                    if ok(k) {
                        used[k - 1] = true;
                    }
                }
            }
            for c in &r.contacts {
                if ok(c.node) {
                    used[c.node - 1] = true;
                }
            }
        }
        let nodes: Vec<usize> = (0..n).filter(|&k| used[k]).collect();
        let mut vertex = vec![0u32; n];
        for (v, &k) in nodes.iter().enumerate() {
            vertex[k] = v as u32;
        }
        let triangles = body
            .patches
            .iter()
            .filter(|p| p.iter().all(|&k| ok(k)))
            .map(|p| p.map(|k| vertex[k - 1]))
            .collect();
        (BodyShape::Surface(triangles), nodes)
    } else {
        let lines = body
            .members
            .iter()
            .map(|m| {
                if m.iter().all(|&k| ok(k)) {
                    m.map(|k| (k - 1) as u32)
                } else {
                    [0, 0]
                }
            })
            .collect();
        (BodyShape::Lines(lines), (0..n).collect())
    }
}

/// Body `b` of `model` at the kept `steps`.
fn animate_body(
    body: &ModelBody,
    shape: BodyShape,
    nodes: Vec<usize>,
    steps: &[&StepResult],
    b: usize,
    magnification: Real,
) -> AnimatedBody {
    let mut vertex = vec![None; body.nodes.len()];
    for (v, &k) in nodes.iter().enumerate() {
        vertex[k] = Some(v as u32);
    }
    let vertex_of = |k: usize| vertex.get(k.wrapping_sub(1)).copied().flatten();
    let rest: Vec<[f32; 3]> = nodes.iter().map(|&k| f32x3(vec3(&body.nodes[k]))).collect();
    let strengths = has_strengths(body);
    let surface = matches!(shape, BodyShape::Surface(_));
    let mut a = AnimatedBody {
        name: body.name.clone(),
        dimension: body.dimension,
        shape,
        nodes,
        rest,
        positions: Vec::new(),
        stress: Vec::new(),
        ratio: strengths.then(Vec::new),
        broken: Vec::new(),
        contacts: Vec::new(),
    };
    for s in steps {
        let Some(r) = s.bodies.get(b) else {
            // A step without this body (not from `linkage run`): the body at rest.
            a.positions.push(a.rest.clone());
            a.stress.push(vec![0.0; a.nodes.len()]);
            if let Some(ratio) = a.ratio.as_mut() {
                ratio.push(vec![0.0; a.nodes.len()]);
            }
            a.broken.push(Vec::new());
            a.contacts.push(Vec::new());
            continue;
        };
        a.positions.push(
            a.nodes
                .iter()
                .map(|&k| {
                    let u = r
                        .displacements
                        .get(k)
                        .map_or(Default::default(), |u| vec3(u));
                    f32x3(vec3(&body.nodes[k]) + u * magnification)
                })
                .collect(),
        );
        let ratios: Vec<Real> = if strengths {
            r.stresses
                .iter()
                .enumerate()
                .map(|(j, &s)| member_ratio(body, j, s))
                .collect()
        } else {
            Vec::new()
        };
        if surface {
            let mean = node_stresses(body, &r.stresses);
            a.stress
                .push(a.nodes.iter().map(|&k| mean[k] as f32).collect());
            if let Some(ratio) = a.ratio.as_mut() {
                let mut peak = vec![0.0f32; body.nodes.len()];
                for (m, q) in body.members.iter().zip(&ratios) {
                    for &k in m {
                        if let Some(p) = peak.get_mut(k.wrapping_sub(1)) {
                            *p = p.max(*q as f32);
                        }
                    }
                }
                ratio.push(a.nodes.iter().map(|&k| peak[k]).collect());
            }
        } else {
            a.stress
                .push(r.stresses.iter().map(|&s| s as f32).collect());
            if let Some(ratio) = a.ratio.as_mut() {
                ratio.push(ratios.iter().map(|&q| q as f32).collect());
            }
        }
        a.broken.push(
            r.fracture
                .iter()
                .flat_map(|f| &f.broken)
                .filter_map(|&j| body.members.get(j.wrapping_sub(1)))
                .filter_map(|m| Some([vertex_of(m[0])?, vertex_of(m[1])?]))
                .collect(),
        );
        a.contacts.push(
            r.contacts
                .iter()
                .filter_map(|c| Some((vertex_of(c.node)?, f32x3(vec3(&c.force)))))
                .collect(),
        );
    }
    a
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn evenly_spaced_keeps_first_and_last() {
        assert_eq!(evenly_spaced(3, 10), vec![0, 1, 2]);
        assert_eq!(evenly_spaced(11, 3), vec![0, 5, 10]);
        // 101 steps into 5: 0, 25, 50, 75, 100.
        assert_eq!(evenly_spaced(101, 5), vec![0, 25, 50, 75, 100]);
        assert_eq!(evenly_spaced(0, 4), Vec::<usize>::new());
        assert_eq!(evenly_spaced(7, 1), vec![0, 6]);
    }

    /// A 2D bar of 3 nodes and 2 members over `n` stored steps: at step k node 3 has moved
    /// k mm along x, member 1 carries k MPa, member 2 breaks at step 2, node 3 touches `wall`
    /// with k N.
    fn bar_run(n: usize) -> RunResults {
        use crate::scene::{BodyFracture, BodyResult, ContactForce, ModelFile};
        let model = ModelFile {
            scene: "bar".into(),
            bodies: vec![ModelBody {
                name: "bar".into(),
                dimension: 2,
                nodes: vec![vec![0.0, 0.0], vec![1.0, 0.0], vec![2.0, 0.0]],
                members: vec![[1, 2], [2, 3]],
                patches: vec![],
                supports: vec![],
                member_materials: vec![],
                strengths: vec![],
            }],
            obstacles: vec![],
            up: None,
        };
        let steps = (0..n)
            .map(|k| {
                let u = k as Real * 1e-3;
                StepResult {
                    step: k,
                    time: None,
                    load_factor: k as Real / (n - 1).max(1) as Real,
                    bodies: vec![BodyResult {
                        name: "bar".into(),
                        velocities: vec![],
                        displacements: vec![vec![0.0, 0.0], vec![0.0, 0.0], vec![u, 0.0]],
                        positions: vec![vec![0.0, 0.0], vec![1.0, 0.0], vec![2.0 + u, 0.0]],
                        axial_forces: vec![0.0, 0.0],
                        strains: vec![0.0, 0.0],
                        stresses: vec![k as Real * 1e6, 0.0],
                        overloaded: vec![],
                        reactions: vec![],
                        loads: vec![],
                        contacts: vec![ContactForce {
                            node: 3,
                            with: "wall".into(),
                            force: vec![-(k as Real), 0.0],
                            ..ContactForce::default()
                        }],
                        fracture: Some(BodyFracture {
                            broken: if k >= 2 { vec![2] } else { vec![] },
                            breaks: vec![],
                            fallen: vec![],
                            collapse: false,
                        }),
                    }],
                }
            })
            .collect();
        RunResults {
            model,
            steps,
            digits: 4,
        }
    }

    #[test]
    fn frames_hold_magnified_positions_stresses_breaks_and_contacts() {
        let budget = FrameBudget {
            max_frames: 100,
            max_vertex_frames: 1000,
        };
        let a = AnimatedRun::of_run(&bar_run(4), 10.0, budget, |_| None);
        assert_eq!(a.frames.len(), 4);
        assert!(!a.decimated() && !a.timed);
        // The frame rate: the i-th stored step at i / 10 s.
        assert!((a.frames[3].time - 0.3).abs() < 1e-12);
        let b = &a.bodies[0];
        assert_eq!(b.shape, BodyShape::Lines(vec![[0, 1], [1, 2]]));
        // Step 3: node 3 at 2 + 10 × 3 mm = 2.03 m (f32: within 1e-6).
        assert!((b.positions[3][2][0] - 2.03).abs() < 1e-6);
        assert_eq!(b.stress[3], vec![3e6, 0.0]);
        assert!((a.stress_limit - 3e6).abs() < 1e-6);
        assert_eq!(b.broken[1], Vec::<[u32; 2]>::new());
        assert_eq!(b.broken[2], vec![[1, 2]]);
        assert_eq!(b.contacts[3], vec![(2, [-3.0, 0.0, 0.0])]);
        assert!((a.max_contact - 3.0).abs() < 1e-12);
        assert!(b.ratio.is_none(), "no strengths, no ratio");
    }

    #[test]
    fn long_runs_are_decimated_and_times_are_the_steps_own_when_they_rise() {
        // 3 vertices: a budget of 30 vertex-frames keeps 10 of 101 frames.
        let budget = FrameBudget {
            max_frames: 50,
            max_vertex_frames: 30,
        };
        let a = AnimatedRun::of_run(&bar_run(101), 1.0, budget, |s| Some(s.step as Real * 0.5));
        assert_eq!(a.frames.len(), 10);
        assert!(a.decimated() && a.timed);
        assert_eq!(a.frames[0].step, 0);
        assert_eq!(a.frames[9].step, 100);
        assert_eq!(a.frames[9].time, 50.0);
        // Times that do not rise fall back to the frame rate over the stored index.
        let a = AnimatedRun::of_run(&bar_run(5), 1.0, budget, |_| Some(1.0));
        assert!(!a.timed);
        assert!((a.frames[4].time - 0.4).abs() < 1e-12);
    }

    #[test]
    fn ratio_takes_the_strength_of_the_stress_sense() {
        let body = ModelBody {
            name: "b".into(),
            dimension: 2,
            nodes: vec![vec![0.0, 0.0], vec![1.0, 0.0]],
            members: vec![[1, 2]],
            patches: vec![],
            supports: vec![],
            member_materials: vec![],
            strengths: vec![[Some(200.0), Some(50.0)]],
        };
        assert!((member_ratio(&body, 0, 100.0) - 0.5).abs() < 1e-15);
        assert!((member_ratio(&body, 0, -100.0) - 2.0).abs() < 1e-15);
        assert_eq!(member_ratio(&body, 1, 100.0), 0.0);
    }
}
