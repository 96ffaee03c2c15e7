//! The scene's `[contact]` settings.

use crate::Real;

/// How contact is treated in a scene (`[contact]`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactSettings {
    /// Penalty stiffness, N/m of penetration; `None`: the default rule of
    /// [`crate::contact::default_penalty`].
    pub penalty: Option<Real>,
    /// Penetration above which a step is warned about, m; `None`: 1% of the mean member length
    /// ([`crate::contact::penetration_tolerance`]).
    pub tolerance: Option<Real>,
    /// Contact iterations (solve, query, new penalties) allowed per step.
    pub max_iterations: usize,
}

impl Default for ContactSettings {
    fn default() -> Self {
        ContactSettings {
            penalty: None,
            tolerance: None,
            max_iterations: 50,
        }
    }
}
