//! The point of a load increment at which a member reaches its strength.

use crate::Real;

/// A member is at its strength when its stress is within this fraction of it (a Newton
/// solve to a relative residual of 1e-10 or below leaves the stresses accurate to about
/// this). The event searches in time ([`crate::scene::BreakingBodies`]), with contact and
/// under large displacements stop there.
pub const AT_STRENGTH: Real = 1e-8;

/// A member's stress `s` (Pa, tension positive) over its strength in that sense: `s/f_t` in
/// tension, `−s/f_c` in compression (`tensile` f_t and `compressive` f_c positive Pa,
/// infinite for none: the ratio is then 0).
pub fn strength_ratio(s: Real, tensile: Real, compressive: Real) -> Real {
    if s >= 0.0 {
        s / tensile
    } else {
        -s / compressive
    }
}

/// For a member whose stress along a load increment is `σ(t) = a + t b` (Pa, tension
/// positive; `t = 0` at the previous step's load, `t = 1` at this step's), the `t` at which it
/// reaches its strength, when it is beyond it at `t = 1`: `(f_t − a)/b` in tension,
/// `(−f_c − a)/b` in compression (`tensile` f_t and `compressive` f_c as positive Pa,
/// infinite for none). The answer is below 0 when the member already was beyond its strength
/// at the previous step's load with the members broken since (a snap-back), and 0 when its
/// stress does not grow with the load (it is beyond the strength from the start of the
/// increment). `None` when it is within its strength at `t = 1`.
pub fn critical_fraction(a: Real, b: Real, tensile: Real, compressive: Real) -> Option<Real> {
    let end = a + b;
    if end > tensile {
        Some(if b > 0.0 { (tensile - a) / b } else { 0.0 })
    } else if end < -compressive {
        Some(if b < 0.0 { (-compressive - a) / b } else { 0.0 })
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tension_and_compression_cross_where_the_line_meets_the_strength() {
        // σ from 10 to 30 Pa, strength 25: reached at t = 15/20 = 0.75 exactly.
        assert_eq!(critical_fraction(10.0, 20.0, 25.0, 100.0), Some(0.75));
        // σ from −10 to −50, compressive strength 40: t = 30/40.
        assert_eq!(critical_fraction(-10.0, -40.0, 25.0, 40.0), Some(0.75));
        assert_eq!(critical_fraction(10.0, 10.0, 25.0, 100.0), None);
        assert_eq!(
            critical_fraction(10.0, 10.0, Real::INFINITY, Real::INFINITY),
            None
        );
    }

    #[test]
    fn the_strength_ratio_takes_the_strength_of_the_stress_sense() {
        assert_eq!(strength_ratio(30.0, 20.0, 60.0), 1.5);
        assert_eq!(strength_ratio(-30.0, 20.0, 60.0), 0.5);
        assert_eq!(strength_ratio(-30.0, 20.0, Real::INFINITY), 0.0);
    }

    #[test]
    fn a_member_already_beyond_at_the_start_gives_a_negative_fraction() {
        // σ(t) = 30 + 10 t, strength 25: on the line it was reached at t = −0.5.
        assert_eq!(critical_fraction(30.0, 10.0, 25.0, 100.0), Some(-0.5));
        // A stress that falls while beyond the strength: from the start of the increment.
        assert_eq!(critical_fraction(40.0, -5.0, 25.0, 100.0), Some(0.0));
    }
}
