//! Which linear solver a body's stiffness gets, and which one it got.
//!
//! The choice a scene makes, its settings, and the solver that was used in the end.

use crate::Real;
use std::fmt;

/// Which linear solver a body's `K_ff` gets.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SolverChoice {
    /// Sparse Cholesky (LDLᵀ past a limit point) with a nested-dissection ordering.
    Direct,
    /// Conjugate gradients preconditioned by smoothed-aggregation multigrid.
    Iterative,
    /// Direct below [`AUTO_ITERATIVE_DOFS_3D`] / [`AUTO_ITERATIVE_DOFS_2D`] free DOFs, iterative above.
    #[default]
    Auto,
}

/// Free DOFs of a 3D body above which `auto` picks the iterative solver. Measured on box
/// lattices (docs/performance-history.md): one multigrid solve beats one factorization from about
/// 10,000 DOFs; above 30,000 it is 3× faster and needs a fraction of the memory, and a
/// linear run with several load schedules or a Newton run still favours it there.
pub const AUTO_ITERATIVE_DOFS_3D: usize = 30_000;

/// Free DOFs of a linear 3D body in a contact scene above which `auto` picks the iterative
/// solver: below, the body is factored once per run and condensed on its contact candidates,
/// and each contact step costs little; the coupled conjugate-gradient path instead solves at
/// every Newton iteration (two 64,600-DOF boxes: 8 s of set-up and 0.5 s a step condensed,
/// 41–144 s a step iteratively; a factorization of 86,000 DOFs takes 3.4 s, of 200,000 23 s
/// and 2.7 GB: docs/performance-history.md).
pub const AUTO_CONTACT_ITERATIVE_DOFS_3D: usize = 100_000;

/// Free DOFs of a 2D body above which `auto` picks the iterative solver: plane linkages
/// factor with little fill, so the direct solver stays ahead far longer.
pub const AUTO_ITERATIVE_DOFS_2D: usize = 400_000;

/// How the iterative solver stops.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IterativeSettings {
    /// Relative residual `‖F − K u‖ / ‖F‖` at which a solve stops (default 1e-10).
    pub tolerance: Real,
    /// Conjugate-gradient iterations allowed per solve before falling back to the direct
    /// solver (default 500).
    pub max_iterations: usize,
    /// Start each solve from the best combination of recent solutions, and solve a Newton
    /// correction as the new displacement warm-started from the previous iterate (default
    /// true; false starts every solve from zero, for comparison).
    pub warm_start: bool,
}

impl Default for IterativeSettings {
    fn default() -> Self {
        IterativeSettings {
            tolerance: 1e-10,
            max_iterations: 500,
            warm_start: true,
        }
    }
}

/// A body's solver choice and the iterative solver's stopping rule.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SolverSettings {
    /// Direct, iterative or automatic.
    pub choice: SolverChoice,
    /// Stopping rule of the iterative solver.
    pub iterative: IterativeSettings,
}

impl SolverSettings {
    /// Whether a body of `dimension` (2 or 3) with `free_dofs` unknowns is solved iteratively.
    pub fn use_iterative(&self, dimension: usize, free_dofs: usize) -> bool {
        match self.choice {
            SolverChoice::Direct => false,
            SolverChoice::Iterative => true,
            SolverChoice::Auto => {
                let limit = if dimension == 2 {
                    AUTO_ITERATIVE_DOFS_2D
                } else {
                    AUTO_ITERATIVE_DOFS_3D
                };
                free_dofs > limit
            }
        }
    }
}

impl SolverSettings {
    /// Whether a body in a contact scene is solved iteratively: as [`Self::use_iterative`],
    /// but `auto` keeps a `linear` 3D body direct up to [`AUTO_CONTACT_ITERATIVE_DOFS_3D`]
    /// free DOFs, where the condensed contact path is far ahead.
    pub fn use_iterative_in_contact(
        &self,
        dimension: usize,
        free_dofs: usize,
        linear: bool,
    ) -> bool {
        match self.choice {
            SolverChoice::Auto if linear && dimension == 3 => {
                free_dofs > AUTO_CONTACT_ITERATIVE_DOFS_3D
            }
            _ => self.use_iterative(dimension, free_dofs),
        }
    }
}

/// The linear solver that produced a body's answers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SolverUsed {
    /// Sparse Cholesky or LDLᵀ.
    Direct,
    /// Conjugate gradients with multigrid.
    Iterative,
    /// Conjugate gradients did not converge on a linear body, and the direct solver answered.
    IterativeThenDirect,
}

impl SolverUsed {
    /// The name `summary.json` gives it: "direct", "iterative" or "iterative, then direct".
    pub fn as_str(self) -> &'static str {
        match self {
            SolverUsed::Direct => "direct",
            SolverUsed::Iterative => "iterative",
            SolverUsed::IterativeThenDirect => "iterative, then direct",
        }
    }
}

impl fmt::Display for SolverUsed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl PartialEq<&str> for SolverUsed {
    fn eq(&self, other: &&str) -> bool {
        self.as_str() == *other
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn auto_keeps_a_linear_3d_body_in_contact_direct_longer() {
        let auto = SolverSettings::default();
        assert_eq!(auto.choice, SolverChoice::Auto);
        let (below, between, above) = (
            AUTO_ITERATIVE_DOFS_3D,
            AUTO_ITERATIVE_DOFS_3D + 1,
            AUTO_CONTACT_ITERATIVE_DOFS_3D + 1,
        );
        assert!(!auto.use_iterative(3, below) && auto.use_iterative(3, between));
        assert!(!auto.use_iterative_in_contact(3, between, true));
        assert!(auto.use_iterative_in_contact(3, above, true));
        // A nonlinear body refactors every iteration anyway: the body rule holds.
        assert!(auto.use_iterative_in_contact(3, between, false));
        // What the scene says is what it gets.
        let direct = SolverSettings {
            choice: SolverChoice::Direct,
            ..Default::default()
        };
        assert!(!direct.use_iterative_in_contact(3, above, true));
        let iterative = SolverSettings {
            choice: SolverChoice::Iterative,
            ..Default::default()
        };
        assert!(iterative.use_iterative_in_contact(3, below, true));
    }
}
