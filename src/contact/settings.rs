//! The scene's `[contact]` settings.

use crate::contact::FrictionSettings;
use crate::Real;

/// How contact is treated in a scene (`[contact]`).
#[derive(Clone, Debug, PartialEq)]
pub struct ContactSettings {
    /// Penalty stiffness, N/m of penetration; `None`: the default rule of
    /// [`crate::contact::default_penalty`].
    pub penalty: Option<Real>,
    /// Penetration above which a step is warned about, m; `None`: 1% of the mean member length
    /// ([`crate::contact::penetration_tolerance`]).
    pub tolerance: Option<Real>,
    /// Contact iterations (solve, query, new penalties) allowed per step.
    pub max_iterations: usize,
    /// When every body is linear: factor each body once per run and solve the contact problem
    /// on its contact candidates (`true`, the default), rather than factoring the coupled
    /// system of all bodies at every contact iteration.
    pub condense: bool,
    /// Coulomb friction of the contact pairs (frictionless by default).
    pub friction: FrictionSettings,
    /// Contact of every body with itself (`[contact] self`): its surface nodes against its own
    /// surface, and its closed cracks (see [`crate::contact::self_contact_on`]); `None`: on
    /// for bodies with breaking members only.
    pub self_contact: Option<bool>,
}

impl Default for ContactSettings {
    fn default() -> Self {
        ContactSettings {
            penalty: None,
            tolerance: None,
            max_iterations: 50,
            condense: true,
            friction: FrictionSettings::default(),
            self_contact: None,
        }
    }
}
