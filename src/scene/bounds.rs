//! The largest lengths and angles a scene may give: beyond them the solvers' and parry's
//! products (squared lengths, volumes, penalty forces) would overflow to infinity or NaN, and a
//! written file would hold `null`. They are far outside any physical scene, so nothing real is
//! refused; what is refused is refused at input, before anything is solved.

use crate::Real;
use nalgebra::Vector3;

/// The largest coordinate, length or travel, m: its square (1e200) and cube (1e300, a mesh's
/// enclosed volume) stay finite, with room for the stiffnesses and penalties that multiply them.
pub const MAX_LENGTH: Real = 1e100;

/// The largest rotation angle, degrees (about 2800 turns): beyond it an angle has lost the
/// digits that place it within a turn (at 1e17 degrees f64 cannot tell 0° from 360°), so it
/// means nothing a user could have wanted.
pub const MAX_ROTATION_DEGREES: Real = 1e6;

/// `Ok` when `value` (m) is finite and within [`MAX_LENGTH`]; else what is wrong with `key`.
pub fn check_length(value: Real, key: &str) -> Result<Real, String> {
    if !value.is_finite() {
        Err(format!(
            "`{key}` = {value} is not a finite number of metres"
        ))
    } else if value.abs() > MAX_LENGTH {
        Err(format!(
            "`{key}` = {value:e} m is beyond ±{MAX_LENGTH:e} m, too large to compute with (its square and the contact forces would overflow): give lengths in metres, within ±{MAX_LENGTH:e}"
        ))
    } else {
        Ok(value)
    }
}

/// Every component of `v` through [`check_length`].
pub fn check_lengths(v: &Vector3<Real>, key: &str) -> Result<Vector3<Real>, String> {
    for x in v.iter() {
        check_length(*x, key)?;
    }
    Ok(*v)
}

/// `Ok` when every angle of `degrees` is finite and within [`MAX_ROTATION_DEGREES`].
pub fn check_rotation(degrees: &Vector3<Real>, key: &str) -> Result<(), String> {
    match degrees.iter().find(|x| !x.is_finite() || x.abs() > MAX_ROTATION_DEGREES) {
        Some(x) if !x.is_finite() => Err(format!("`{key}` has the non-finite angle {x}")),
        Some(x) => Err(format!(
            "`{key}` has the angle {x:e} degrees, beyond ±{MAX_ROTATION_DEGREES:e}: an angle that large has lost the digits that place it within a turn; give it in degrees within ±{MAX_ROTATION_DEGREES:e} (reduce it modulo 360)"
        )),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_accept_ordinary_values_and_refuse_absurd_ones() {
        assert!(check_length(1e3, "radius").is_ok());
        assert!(check_length(1e155, "radius")
            .unwrap_err()
            .contains("`radius`"));
        assert!(check_length(Real::NAN, "radius").is_err());
        assert!(check_rotation(&Vector3::new(0.0, 0.0, 720.0), "rotation").is_ok());
        let e = check_rotation(&Vector3::new(0.0, 1e308, 0.0), "rotation").unwrap_err();
        assert!(e.contains("1e308 degrees"), "{e}");
        assert!(check_rotation(&Vector3::new(Real::NAN, 0.0, 0.0), "rotation").is_err());
    }
}
