//! The viewer's data: an [`AnimatedRun`] as compact JSON for a page, its arrays float32 or
//! uint32 in base64, a frame's array left `null` where it is the previous frame's.

use crate::render::animated_run::{AnimatedRun, BodyShape, FrameBudget};
use crate::render::viewer::base64::{base64_f32, base64_u32};
use serde_json::{json, Value};

/// What a page's viewer holds at most: 400 frames and 512 Ki `frames × vertices` (6 MiB of
/// float32 positions, 8 MiB as base64); longer or larger runs keep evenly spaced frames, and
/// the page says so.
pub const VIEWER_BUDGET: FrameBudget = FrameBudget {
    max_frames: 400,
    max_vertex_frames: 512 << 10,
};

/// Per frame, `encode(frame)` of each of `frames`, `null` where equal to the previous one.
fn changes<T: PartialEq>(frames: &[T], encode: impl Fn(&T) -> String) -> Vec<Value> {
    frames
        .iter()
        .enumerate()
        .map(|(k, f)| {
            if k > 0 && frames[k - 1] == *f {
                Value::Null
            } else {
                Value::String(encode(f))
            }
        })
        .collect()
}

/// The JSON text of `run` for the viewer (see `viewer.js` for how it is read), safe inside a
/// `<script>` element: every `<` is written `\u003c`.
pub fn viewer_data(run: &AnimatedRun) -> String {
    let mut ratio_limit: f32 = 0.0;
    let bodies: Vec<Value> = run
        .bodies
        .iter()
        .map(|b| {
            let (surface, index): (bool, Vec<u32>) = match &b.shape {
                BodyShape::Surface(t) => (true, t.iter().flatten().copied().collect()),
                BodyShape::Lines(l) => (false, l.iter().flatten().copied().collect()),
            };
            if let Some(r) = &b.ratio {
                ratio_limit = r.iter().flatten().fold(ratio_limit, |m, v| m.max(*v));
            }
            let contacts: Vec<String> = b
                .positions
                .iter()
                .zip(&b.contacts)
                .map(|(p, c)| {
                    base64_f32(c.iter().flat_map(|(v, f)| {
                        let at = p.get(*v as usize).copied().unwrap_or([0.0; 3]);
                        [at[0], at[1], at[2], f[0], f[1], f[2]]
                    }))
                })
                .collect();
            json!({
                "name": b.name,
                "surface": surface,
                "index": base64_u32(index),
                "rest": base64_f32(b.rest.iter().flatten().copied()),
                "positions": changes(&b.positions, |p| base64_f32(p.iter().flatten().copied())),
                "stress": changes(&b.stress, |s| base64_f32(s.iter().copied())),
                "ratio": b.ratio.as_ref().map(|r| changes(r, |s| base64_f32(s.iter().copied()))),
                "broken": changes(&b.broken, |m| base64_u32(m.iter().flatten().copied())),
                "contacts": contacts,
            })
        })
        .collect();
    let obstacles: Vec<Value> = run
        .obstacles
        .iter()
        .map(|o| {
            json!({
                "name": o.name,
                "vertices": base64_f32(o.vertices.iter().flatten().copied()),
                "index": base64_u32(o.triangles.iter().flatten().copied()),
                "offsets": o.offsets,
            })
        })
        .collect();
    let frames: Vec<Value> = run
        .frames
        .iter()
        .map(|f| json!({"step": f.step, "time": f.time, "load_factor": f.load_factor}))
        .collect();
    let has_ratio = run.bodies.iter().any(|b| b.ratio.is_some());
    json!({
        "scene": run.scene,
        "is3d": run.is_3d,
        "magnification": run.magnification,
        "stored": run.stored_steps,
        "timed": run.timed,
        "loadName": run.load_name,
        "up": run.up,
        "frames": frames,
        "stressLimit": run.stress_limit,
        "ratioLimit": if has_ratio { Some(ratio_limit.max(1.0)) } else { None },
        "maxContact": run.max_contact,
        "bodies": bodies,
        "obstacles": obstacles,
    })
    .to_string()
    .replace('<', "\\u003c")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unchanged_frames_are_null_and_text_cannot_close_the_script() {
        let f = changes(&[1, 1, 2, 2, 1], |v| v.to_string());
        assert_eq!(
            f,
            vec![json!("1"), Value::Null, json!("2"), Value::Null, json!("1")]
        );
        let run = AnimatedRun {
            scene: "</script><b>".into(),
            is_3d: false,
            magnification: 1.0,
            frames: vec![],
            stored_steps: 0,
            timed: false,
            load_name: "load factor",
            up: None,
            bodies: vec![],
            obstacles: vec![],
            stress_limit: 0.0,
            max_contact: 0.0,
        };
        let text = viewer_data(&run);
        assert!(!text.contains('<'), "{text}");
        let back: Value = serde_json::from_str(&text).unwrap();
        assert_eq!(back["scene"], "</script><b>");
    }
}
