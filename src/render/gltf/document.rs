//! The glTF 2.0 document of an [`AnimatedRun`]: a mesh per body with one morph target per
//! frame, a node per obstacle moved by translation, and one animation of them all.

use crate::render::animated_run::{AnimatedRun, BodyShape};
use crate::render::colour_scale::{ColourScale, OBSTACLE_SURFACE};
use crate::render::gltf::glb::glb_bytes;
use serde_json::{json, Value};

/// `bufferView.target` of vertex attributes.
const ARRAY_BUFFER: u32 = 34962;
/// `bufferView.target` of indices.
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
/// `accessor.componentType` of f32.
const FLOAT: u32 = 5126;
/// `accessor.componentType` of u32.
const UNSIGNED_INT: u32 = 5125;
/// `primitive.mode` of line segments.
const LINES: u32 = 1;
/// `primitive.mode` of triangles.
const TRIANGLES: u32 = 4;

/// The binary buffer and the `bufferViews` and `accessors` that describe it.
#[derive(Default)]
struct Buffer {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Buffer {
    /// Add `values` (f32, `width` per element: 1 SCALAR, 3 VEC3) as a new view and accessor;
    /// `bounds` writes its min and max (required of POSITION and of animation inputs).
    fn floats(&mut self, values: &[f32], width: usize, target: Option<u32>, bounds: bool) -> usize {
        let count = values.len() / width;
        let mut acc = json!({
            "bufferView": self.view(bytemuck_f32(values), target),
            "componentType": FLOAT,
            "count": count,
            "type": if width == 1 { "SCALAR" } else { "VEC3" },
        });
        if bounds {
            let mut lo = vec![f32::INFINITY; width];
            let mut hi = vec![f32::NEG_INFINITY; width];
            for e in values.chunks_exact(width) {
                for k in 0..width {
                    lo[k] = lo[k].min(e[k]);
                    hi[k] = hi[k].max(e[k]);
                }
            }
            if count == 0 {
                lo.fill(0.0);
                hi.fill(0.0);
            }
            acc["min"] = json!(lo);
            acc["max"] = json!(hi);
        }
        self.accessors.push(acc);
        self.accessors.len() - 1
    }

    /// Add vertex indices as a new view and accessor.
    fn indices(&mut self, values: &[u32]) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(bytes, Some(ELEMENT_ARRAY_BUFFER));
        self.accessors.push(json!({
            "bufferView": view,
            "componentType": UNSIGNED_INT,
            "count": values.len(),
            "type": "SCALAR",
        }));
        self.accessors.len() - 1
    }

    /// Append `bytes` (a multiple of 4 long) as a buffer view; its index.
    fn view(&mut self, bytes: Vec<u8>, target: Option<u32>) -> usize {
        let mut v = json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()});
        if let Some(t) = target {
            v["target"] = json!(t);
        }
        self.bin.extend_from_slice(&bytes);
        self.views.push(v);
        self.views.len() - 1
    }
}

fn bytemuck_f32(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// The GLB file of `run` (see the module README): each body a mesh whose morph target k
/// holds the POSITION and COLOR_0 deltas of frame k from the rest mesh (the undeformed
/// positions, coloured as frame 0), its node's `weights` animated by STEP keyframes that
/// select target k at frame k's time; each obstacle a node whose translation is animated the
/// same way. Colours are the stress colour scale of the pictures over ±`run.stress_limit`.
pub fn gltf_of_run(run: &AnimatedRun) -> Vec<u8> {
    let mut buf = Buffer::default();
    let scale = ColourScale::new(run.stress_limit);
    let frames = run.frames.len();
    let times: Vec<f32> = run.frames.iter().map(|f| f.time as f32).collect();
    let mut nodes = Vec::new();
    let mut meshes = Vec::new();
    let mut channels = Vec::new();
    let mut samplers = Vec::new();
    let input = (frames > 0).then(|| buf.floats(&times, 1, None, true));
    for body in &run.bodies {
        // Per vertex: surfaces colour vertices, lines colour each member's two ends.
        let (vertices, indices, mode): (Vec<usize>, Vec<u32>, u32) = match &body.shape {
            BodyShape::Surface(t) => (
                (0..body.nodes.len()).collect(),
                t.iter().flatten().copied().collect(),
                TRIANGLES,
            ),
            BodyShape::Lines(l) => (
                l.iter().flatten().map(|&v| v as usize).collect(),
                (0..2 * l.len() as u32).collect(),
                LINES,
            ),
        };
        let mut node = json!({"name": body.name});
        if indices.is_empty() || frames == 0 {
            nodes.push(node);
            continue;
        }
        let colour_of = |frame: usize, i: usize| -> [f32; 3] {
            let s = match &body.shape {
                BodyShape::Surface(_) => body.stress[frame].get(i),
                BodyShape::Lines(_) => body.stress[frame].get(i / 2),
            };
            let c = scale.colour(s.copied().unwrap_or(0.0) as f64);
            [c.0, c.1, c.2]
        };
        let rest: Vec<f32> = vertices.iter().flat_map(|&v| body.rest[v]).collect();
        let colours0: Vec<[f32; 3]> = (0..vertices.len()).map(|i| colour_of(0, i)).collect();
        let position = buf.floats(&rest, 3, Some(ARRAY_BUFFER), true);
        let colour = buf.floats(
            &colours0.iter().flatten().copied().collect::<Vec<_>>(),
            3,
            Some(ARRAY_BUFFER),
            false,
        );
        let index = buf.indices(&indices);
        let mut targets = Vec::with_capacity(frames);
        for k in 0..frames {
            let dp: Vec<f32> = vertices
                .iter()
                .flat_map(|&v| {
                    let (p, r) = (body.positions[k][v], body.rest[v]);
                    [p[0] - r[0], p[1] - r[1], p[2] - r[2]]
                })
                .collect();
            let dc: Vec<f32> = (0..vertices.len())
                .flat_map(|i| {
                    let (c, c0) = (colour_of(k, i), colours0[i]);
                    [c[0] - c0[0], c[1] - c0[1], c[2] - c0[2]]
                })
                .collect();
            targets.push(json!({
                "POSITION": buf.floats(&dp, 3, Some(ARRAY_BUFFER), true),
                "COLOR_0": buf.floats(&dc, 3, Some(ARRAY_BUFFER), false),
            }));
        }
        let names: Vec<String> = run
            .frames
            .iter()
            .map(|f| format!("step {}", f.step))
            .collect();
        meshes.push(json!({
            "name": body.name,
            "primitives": [{
                "attributes": {"POSITION": position, "COLOR_0": colour},
                "indices": index,
                "mode": mode,
                "material": 0,
                "targets": targets,
            }],
            "weights": vec![0.0; frames],
            "extras": {"targetNames": names},
        }));
        node["mesh"] = json!(meshes.len() - 1);
        // Keyframe k: weight 1 on target k, 0 elsewhere.
        let mut weights = vec![0.0f32; frames * frames];
        for k in 0..frames {
            weights[k * frames + k] = 1.0;
        }
        samplers.push(json!({
            "input": input,
            "output": buf.floats(&weights, 1, None, false),
            "interpolation": "STEP",
        }));
        channels.push(json!({
            "sampler": samplers.len() - 1,
            "target": {"node": nodes.len(), "path": "weights"},
        }));
        nodes.push(node);
    }
    for o in &run.obstacles {
        let mut node = json!({"name": o.name});
        if let Some(first) = o.offsets.first() {
            node["translation"] = json!(first);
        }
        if !o.triangles.is_empty() {
            let position = buf.floats(
                &o.vertices.iter().flatten().copied().collect::<Vec<_>>(),
                3,
                Some(ARRAY_BUFFER),
                true,
            );
            let index = buf.indices(&o.triangles.iter().flatten().copied().collect::<Vec<_>>());
            meshes.push(json!({
                "name": o.name,
                "primitives": [{"attributes": {"POSITION": position}, "indices": index,
                                "mode": TRIANGLES, "material": 1}],
            }));
            node["mesh"] = json!(meshes.len() - 1);
        }
        if o.offsets.windows(2).any(|w| w[0] != w[1]) {
            samplers.push(json!({
                "input": input,
                "output": buf.floats(
                    &o.offsets.iter().flatten().copied().collect::<Vec<_>>(),
                    3,
                    None,
                    false,
                ),
                "interpolation": "STEP",
            }));
            channels.push(json!({
                "sampler": samplers.len() - 1,
                "target": {"node": nodes.len(), "path": "translation"},
            }));
        }
        nodes.push(node);
    }
    let obstacle = OBSTACLE_SURFACE;
    let mut doc = json!({
        "asset": {
            "version": "2.0",
            "generator": concat!("linkage ", env!("CARGO_PKG_VERSION")),
            "extras": {
                "scene": run.scene,
                "magnification": run.magnification,
                "stored_steps": run.stored_steps,
                "frames": run.frames.iter().map(|f| f.step).collect::<Vec<_>>(),
                "time": if run.timed { "the steps' times, s" } else { "stored steps at 10 per second" },
                "stress_limit_pa": run.stress_limit,
            },
        },
        "scene": 0,
        "scenes": [{"name": run.scene, "nodes": [nodes.len()]}],
        "nodes": nodes.iter().cloned().chain([standing(run.up, nodes.len())]).collect::<Vec<_>>(),
        "materials": [
            {"name": "bodies (vertex colours: member stress)", "doubleSided": true,
             "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0],
                                      "metallicFactor": 0.0, "roughnessFactor": 0.8}},
            {"name": "obstacles", "doubleSided": true, "alphaMode": "BLEND",
             "pbrMetallicRoughness": {"baseColorFactor": [obstacle.0, obstacle.1, obstacle.2, 0.5],
                                      "metallicFactor": 0.0, "roughnessFactor": 0.9}},
        ],
    });
    if !meshes.is_empty() {
        doc["meshes"] = json!(meshes);
    }
    if !channels.is_empty() {
        doc["animations"] = json!([{"name": "run", "channels": channels, "samplers": samplers}]);
    }
    if !buf.bin.is_empty() {
        doc["buffers"] = json!([{"byteLength": buf.bin.len()}]);
        doc["bufferViews"] = json!(buf.views);
        doc["accessors"] = json!(buf.accessors);
    }
    // The numbers come from result files checked finite when written (a NaN would become
    // null, which the validator reports).
    glb_bytes(doc.to_string().as_bytes(), &buf.bin)
}

/// The root node over the first `count` nodes: turned so that the run's `up` (`None`: +y)
/// points along glTF's +y, so a z-up scene stands upright in Blender and on the web. The
/// rotation is the quaternion [k sin(θ/2), cos(θ/2)] about k = up × y by θ = acos(up · y).
pub fn standing(up: Option<[f64; 3]>, count: usize) -> Value {
    let mut node = json!({"name": "linkage", "children": (0..count).collect::<Vec<_>>()});
    if let Some(q) = up.and_then(rotation_to_y) {
        node["rotation"] = json!(q);
    }
    node
}

/// The unit quaternion `[x, y, z, w]` turning the direction `up` onto +y; `None` when `up`
/// is +y already (or not a direction).
pub fn rotation_to_y(up: [f64; 3]) -> Option<[f32; 4]> {
    let n = (up[0] * up[0] + up[1] * up[1] + up[2] * up[2]).sqrt();
    if !(n > 0.0 && n.is_finite()) {
        return None;
    }
    let u = up.map(|c| c / n);
    // k = u × (0, 1, 0) = (-u_z, 0, u_x); cos θ = u_y.
    let k = [-u[2], 0.0, u[0]];
    let s = (k[0] * k[0] + k[2] * k[2]).sqrt();
    if s < 1e-12 {
        // Along ±y: nothing to turn, or half a turn about x.
        return (u[1] < 0.0).then_some([1.0, 0.0, 0.0, 0.0]);
    }
    let theta = u[1].clamp(-1.0, 1.0).acos();
    let (sin, cos) = ((theta / 2.0).sin(), (theta / 2.0).cos());
    Some([
        (k[0] / s * sin) as f32,
        0.0,
        (k[2] / s * sin) as f32,
        cos as f32,
    ])
}
