//! What the plots of a run show (`[output] plot`, `plot_node`, `plot_body`, `plot_obstacle`):
//! checked against the bodies and obstacles when the scene is built, so a wrong node is named
//! before anything runs; stored beside the results (`plot_settings.json`) so that
//! `linkage render` draws the same plots again.

use crate::linkage::Body;
use crate::scene::spec::{OutputSpec, PlotSpec};
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

/// A support with a `name` in the scene (`[[bodies.supports]] name`), as built.
#[derive(Clone, Debug, PartialEq)]
pub struct NamedSupport {
    /// Its name.
    pub name: String,
    /// Its body's name.
    pub body: String,
    /// Its body's index in the scene (0-based).
    pub body_index: usize,
    /// Its nodes (0-based).
    pub nodes: Vec<usize>,
    /// Its prescribed displacement at full schedule, m (zero: held in place).
    pub displacement: [f64; 3],
}

/// The place whose force the load–displacement plot shows against its displacement
/// (`[output] plot`): a named support or nodes of a body.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlotPlace {
    /// How plots name it: `support 'pull'` or `nodes 3, 4 of body 'plate'`.
    pub label: String,
    /// The body's name.
    pub body: String,
    /// The body's index in the scene (0-based).
    pub body_index: usize,
    /// The nodes (0-based).
    pub nodes: Vec<usize>,
    /// The unit direction the force and the displacement are taken along: a support's
    /// prescribed displacement; `None`: the direction of the largest component of the force
    /// total over the run.
    pub direction: Option<[f64; 3]>,
}

/// What the plots drawn with the pictures show (see `docs/SCENES.md`, `[output]`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PlotSettings {
    /// `plot_node`: plot the load factor against this node's displacement and the reaction
    /// total against the load factor; `None`: against the largest displacement of any node.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub node: Option<PlotNode>,
    /// `plot_obstacle`: the obstacle whose push is the load: the load–displacement plot is the
    /// force the bodies receive from it against its travel (see
    /// [`crate::render::plots::obstacle_force`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub obstacle: Option<String>,
    /// `plot`: the load–displacement plot is the force at this place (the sum of the support
    /// reactions and applied loads at its nodes along a direction) against its displacement
    /// (see [`crate::render::plots::place_force`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub place: Option<PlotPlace>,
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
    /// `plot` is checked against the scene's `supports` with a name.
    pub fn from_spec(
        spec: &OutputSpec,
        bodies: &[Body],
        obstacles: &[&str],
        supports: &[NamedSupport],
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
        let place = match &spec.plot {
            None => None,
            Some(plot) => {
                if let Some(o) = &spec.plot_obstacle {
                    return Err(format!(
                        "[output] plot and plot_obstacle = {o:?} both choose the load–displacement plot: keep one"
                    ));
                }
                Some(place_from_spec(plot, bodies, supports)?)
            }
        };
        Ok(PlotSettings {
            node,
            obstacle,
            place,
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

/// `[output] plot` checked against `bodies` and the named `supports`.
fn place_from_spec(
    plot: &PlotSpec,
    bodies: &[Body],
    supports: &[NamedSupport],
) -> Result<PlotPlace, String> {
    match (&plot.support, &plot.nodes) {
        (Some(name), None) => {
            if plot.body.is_some() {
                return Err(format!(
                    "[output] plot = {{ support = {name:?}, body = .. }}: a support names its body itself; leave `body` out"
                ));
            }
            let Some(s) = supports.iter().find(|s| &s.name == name) else {
                return Err(if supports.is_empty() {
                    format!("[output] plot = {{ support = {name:?} }}: the scene has no named support; give the support `name = {name:?}` in its [[bodies.supports]]")
                } else {
                    format!(
                        "[output] plot = {{ support = {name:?} }}: no support of that name; the scene's named supports: {}",
                        supports
                            .iter()
                            .map(|s| format!("'{}'", s.name))
                            .collect::<Vec<_>>()
                            .join(", ")
                    )
                });
            };
            let d = s.displacement;
            let norm = d.iter().map(|x| x * x).sum::<f64>().sqrt();
            Ok(PlotPlace {
                label: format!("support '{}'", s.name),
                body: s.body.clone(),
                body_index: s.body_index,
                nodes: s.nodes.clone(),
                direction: (norm > 0.0 && norm.is_finite()).then(|| d.map(|x| x / norm)),
            })
        }
        (None, Some(nodes)) => {
            let body_index = match &plot.body {
                None => 0,
                Some(name) => bodies.iter().position(|b| &b.name == name).ok_or_else(|| {
                    format!(
                        "[output] plot = {{ body = {name:?} }}: no body of that name; the scene's bodies: {}",
                        bodies
                            .iter()
                            .map(|b| format!("'{}'", b.name))
                            .collect::<Vec<_>>()
                            .join(", ")
                    )
                })?,
            };
            let Some(body) = bodies.get(body_index) else {
                return Err("[output] plot: the scene has no body".to_string());
            };
            let count = body.nodes.len();
            if nodes.is_empty() {
                return Err("[output] plot = { nodes = [] }: list at least one node (1-based)".to_string());
            }
            let mut picked = Vec::with_capacity(nodes.len());
            for &n in nodes {
                if n < 1 || n as u64 > count as u64 {
                    return Err(format!(
                        "[output] plot: node {n}: give nodes of body '{}' from 1 to {count}",
                        body.name
                    ));
                }
                picked.push(n as usize - 1);
            }
            let shown: Vec<String> = nodes.iter().take(8).map(|n| n.to_string()).collect();
            Ok(PlotPlace {
                label: format!(
                    "node{} {}{} of body '{}'",
                    if nodes.len() == 1 { "" } else { "s" },
                    shown.join(", "),
                    if nodes.len() > 8 { ", …" } else { "" },
                    body.name
                ),
                body: body.name.clone(),
                body_index,
                nodes: picked,
                direction: None,
            })
        }
        (Some(_), Some(_)) => Err(
            "[output] plot: give `support` or `nodes` (with `body`), not both".to_string(),
        ),
        (None, None) => Err(
            "[output] plot: give `support = \"NAME\"` (a support's name) or `nodes = [..]` (with `body`)"
                .to_string(),
        ),
    }
}
