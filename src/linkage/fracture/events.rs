//! What a breaking body records: members broken so far, the breaks of a step, pieces that fell off.

use crate::linkage::{Body, Failure};
use crate::Real;

/// One member breaking, or softening by a tooth, during a load step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BreakEvent {
    /// The member, 0-based.
    pub member: usize,
    /// Where in the step's load increment it broke: the loads were `F(s−1) + t (F(s) − F(s−1))`
    /// (and prescribed displacements likewise), `t ≤ 1`; `t` below the previous break's is a
    /// snap-back (the structure, weakened, failed at a lower load).
    pub fraction: Real,
    /// `Some(k)`: the member did not break but passed its tooth `k` (1-based, below its
    /// material's `softening.teeth`), its stiffness and strength dropping to tooth `k + 1`'s;
    /// `None`: it broke (past its last tooth, or brittle).
    pub tooth: Option<usize>,
}

/// A piece left without support by a break: removed from the solve (it fell off).
#[derive(Clone, Debug, PartialEq)]
pub struct FallenPiece {
    /// The member (0-based) whose break released it.
    pub member: usize,
    /// Its nodes, 0-based, ascending.
    pub nodes: Vec<usize>,
}

/// The fracture part of a breaking body's step state.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FractureState {
    /// Members broken so far (this step included), 0-based, in the order they broke.
    pub broken: Vec<usize>,
    /// The breaks of this step, and the teeth softening members passed, in order.
    pub breaks: Vec<BreakEvent>,
    /// Pieces that fell off during this step.
    pub fallen: Vec<FallenPiece>,
}

/// Whether any member of `body` is of a material that breaks.
pub fn breaks_members(body: &Body) -> bool {
    body.materials.iter().any(|m| m.failure == Failure::Break)
        && body
            .members
            .iter()
            .any(|m| body.materials[m.material].failure == Failure::Break)
}
