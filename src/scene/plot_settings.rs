//! What the plots of a run show (`[output] plot_node`, `plot_body`): checked against the
//! bodies when the scene is built, so a wrong node is named before anything runs.

use crate::linkage::Body;
use crate::scene::spec::OutputSpec;

/// A node whose displacement the load–displacement plot follows.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PlotNode {
    /// The body's name.
    pub body: String,
    /// The body's index in the scene (0-based).
    pub body_index: usize,
    /// The node's index in the body (0-based; the scene gives it 1-based).
    pub node: usize,
}

/// What the plots drawn with the pictures show (see `docs/SCENES.md`, `[output]`).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PlotSettings {
    /// `plot_node`: plot the load factor against this node's displacement and the reaction
    /// total against the load factor; `None`: against the largest displacement of any node.
    pub node: Option<PlotNode>,
}

impl PlotSettings {
    /// Check `[output] plot_node` and `plot_body` against `bodies`; the error names the key and
    /// says what to give instead.
    pub fn from_spec(spec: &OutputSpec, bodies: &[Body]) -> Result<Self, String> {
        let Some(node) = spec.plot_node else {
            if let Some(name) = &spec.plot_body {
                return Err(format!(
                    "[output] plot_body = {name:?} without plot_node: give plot_node = N too (a 1-based node of that body)"
                ));
            }
            return Ok(PlotSettings::default());
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
        Ok(PlotSettings {
            node: Some(PlotNode {
                body: body.name.clone(),
                body_index,
                node: node - 1,
            }),
        })
    }
}
