//! Linear bodies in contact, factored once per run and condensed on their contact candidates: the body, the contact Jacobian and the condensed Newton.

pub(crate) use self::body::{CondenseFailure, CondensedBody, NOT_CANDIDATE};
pub(crate) use self::jacobian::{
    approximate_from, exact_for, ContactJacobian, ContactRow, Correction, FrictionRow,
};
pub(crate) use self::solver::{CondensedSolver, CondensedState};

mod anderson;
mod body;
mod jacobian;
#[cfg(test)]
mod large_set_tests;
mod solver;
