//! What the plots of a run show (`[output] plot_node`, `plot_body`, `plot_obstacle`):
//! checked against the bodies and obstacles when the scene is built, so a wrong node is named
//! before anything runs; stored beside the results (`plot_settings.json`) so that
//! `linkage render` draws the same plots again.

use crate::linkage::Body;
use crate::scene::spec::OutputSpec;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The file in a results folder that keeps the run's [`PlotSettings`].
pub const PLOT_SETTINGS: &str = "plot_settings.json";

/// A node whose displacement the load–displacement plot follows.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct PlotNode {
    /// The body's name.
    pub body: String,
    /// The body's index in the scene (0-based).
    pub body_index: usize,
    /// The node's index in the body (0-based; the scene gives it 1-based).
    pub node: usize,
}

/// What the plots drawn with the pictures show (see `docs/SCENES.md`, `[output]`).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct PlotSettings {
    /// `plot_node`: plot the load factor against this node's displacement and the reaction
    /// total against the load factor; `None`: against the largest displacement of any node.
    #[serde(default)]
    pub node: Option<PlotNode>,
    /// `plot_obstacle`: the obstacle whose push is the load: the load–displacement plot is the
    /// force the bodies receive from it against its travel (see
    /// [`crate::render::plots::obstacle_force`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub obstacle: Option<String>,
    /// Whether the results' load factor is the step fraction (`step / steps`) rather than
    /// what the schedules say: they differ, or there are no loads
    /// ([`crate::scene::world::common_schedule`]). Frames and plots then call it "step
    /// fraction".
    #[serde(default)]
    pub step_fraction: bool,
}

impl PlotSettings {
    /// What the results' load factor is called in frames and plots: "load factor", or "step
    /// fraction" when it is not what the schedules say.
    pub fn load_name(&self) -> &'static str {
        load_name(self.step_fraction)
    }
}

/// "step fraction" when `step_fraction`, else "load factor".
pub fn load_name(step_fraction: bool) -> &'static str {
    if step_fraction {
        "step fraction"
    } else {
        "load factor"
    }
}

impl PlotSettings {
    /// Check `[output] plot_node` and `plot_body` against `bodies`; the error names the key and
    /// says what to give instead.
    pub fn from_spec(
        spec: &OutputSpec,
        bodies: &[Body],
        obstacles: &[&str],
    ) -> Result<Self, String> {
        let obstacle = match &spec.plot_obstacle {
            None => None,
            Some(name) if obstacles.contains(&name.as_str()) => Some(name.clone()),
            Some(name) => {
                return Err(if obstacles.is_empty() {
                    format!("[output] plot_obstacle = {name:?}: the scene has no obstacles; leave plot_obstacle out or add the obstacle")
                } else {
                    format!(
                        "[output] plot_obstacle = {name:?}: no obstacle of that name; the scene's obstacles: {}",
                        obstacles
                            .iter()
                            .map(|o| format!("'{o}'"))
                            .collect::<Vec<_>>()
                            .join(", ")
                    )
                })
            }
        };
        let node = Self::node_from_spec(spec, bodies)?;
        Ok(PlotSettings {
            node,
            obstacle,
            step_fraction: crate::scene::world::common_schedule(bodies).is_none(),
        })
    }

    /// The settings kept in the results folder `dir` ([`PLOT_SETTINGS`]); the default ones
    /// when the file is missing (a run written before it was kept) or does not read.
    pub fn read(dir: &Path) -> PlotSettings {
        std::fs::read(dir.join(PLOT_SETTINGS))
            .ok()
            .and_then(|b| serde_json::from_slice(&b).ok())
            .unwrap_or_default()
    }

    /// Keep these settings in the results folder `dir` ([`PLOT_SETTINGS`], atomically).
    pub fn write(&self, dir: &Path) -> std::io::Result<()> {
        let text = serde_json::to_vec_pretty(self).map_err(std::io::Error::other)?;
        crate::scene::atomic_file::write_atomically(&dir.join(PLOT_SETTINGS), &text)
    }

    /// `plot_node` and `plot_body` checked against `bodies`.
    fn node_from_spec(spec: &OutputSpec, bodies: &[Body]) -> Result<Option<PlotNode>, String> {
        let Some(node) = spec.plot_node else {
            if let Some(name) = &spec.plot_body {
                return Err(format!(
                    "[output] plot_body = {name:?} without plot_node: give plot_node = N too (a 1-based node of that body)"
                ));
            }
            return Ok(None);
        };
        let body_index = match &spec.plot_body {
            None => 0,
            Some(name) => bodies.iter().position(|b| &b.name == name).ok_or_else(|| {
                format!(
                    "[output] plot_body = {name:?}: no body of that name; the scene's bodies: {}",
                    bodies
                        .iter()
                        .map(|b| format!("'{}'", b.name))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            })?,
        };
        let Some(body) = bodies.get(body_index) else {
            return Err("[output] plot_node: the scene has no body".to_string());
        };
        let count = body.nodes.len();
        if node == 0 || node > count {
            let why = if node == 0 {
                "node numbers start at 1".to_string()
            } else {
                format!("body '{}' has {count} nodes", body.name)
            };
            return Err(format!(
                "[output] plot_node = {node}: {why}; give a node of body '{}' from 1 to {count}{}",
                body.name,
                if spec.plot_body.is_none() && bodies.len() > 1 {
                    " (or name another body with plot_body)"
                } else {
                    ""
                }
            ));
        }
        Ok(Some(PlotNode {
            body: body.name.clone(),
            body_index,
            node: node - 1,
        }))
    }
}
