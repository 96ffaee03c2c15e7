//! Time integration: bodies with inertia. A time step is a load step with inertia (see
//! `DESIGN.md`): an integrator turns one time step into the problem a load step is, with the
//! residual gaining an inertia term and the tangent its matrix.

pub use self::inertia::InertiaTerm;

mod inertia;
