//! Members that break (sequentially linear analysis, event by event): the critical load of a member, its saw-tooth softening, pieces that fall off, and the linear solver that breaks members without refactoring.

pub use self::breaking_equilibrium::{
    member_teeth, BreakingEquilibrium, MemberLimits, DEFAULT_REFACTOR_EVERY,
};
pub use self::critical::{critical_fraction, strength_ratio, AT_STRENGTH};
pub use self::events::{breaks_members, BreakEvent, FallenPiece, FractureState};
pub use self::large_breaking::LargeBreakingEquilibrium;
pub use self::pieces::{released_pieces, unsupported_pieces};
pub use self::scatter::{member_limits, weibull_factors};
pub use self::softening::{saw_tooth, saw_tooth_dissipation, Tooth};

mod breaking_equilibrium;
mod critical;
mod events;
mod large_breaking;
mod pieces;
mod scatter;
mod softening;
