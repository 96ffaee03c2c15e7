//! Linear bodies in contact, factored once per run and condensed on their contact candidates: the body, the contact Jacobian and the condensed Newton.

pub(crate) use self::body::{CondenseFailure, CondensedBody, NOT_CANDIDATE};
pub(crate) use self::jacobian::{
    exact_for, ContactJacobian, ContactRow, Correction, FrictionRow, APPROXIMATE_FROM,
};
pub(crate) use self::solver::CondensedSolver;

mod body;
mod jacobian;
mod solver;
