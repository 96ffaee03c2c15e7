//! Why a generator cannot build the shape asked for.

use crate::Real;

/// Why a generator cannot build the shape asked for.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GeneratorError {
    /// A length that is zero, negative, NaN or infinite.
    #[error(
        "{shape}: {parameter} = {value} m is not allowed: give a finite length greater than 0 m"
    )]
    BadLength {
        /// The generator, e.g. `"disk"`.
        shape: &'static str,
        /// The parameter, e.g. `"radius"`.
        parameter: &'static str,
        /// The value given, m.
        value: Real,
    },
    /// Too few cells, rings or sectors to make a body.
    #[error("{shape}: {parameter} = {value} is too few: give {minimum} or more")]
    TooFew {
        /// The generator, e.g. `"disk"`.
        shape: &'static str,
        /// The parameter, e.g. `"sectors"`.
        parameter: &'static str,
        /// The value given.
        value: usize,
        /// The smallest value allowed.
        minimum: usize,
    },
    /// So many cells that the node or member list cannot be held in memory.
    #[error("{shape}: {parameter} = {value} asks for more nodes or members than fit in memory: give fewer")]
    TooLarge {
        /// The generator, e.g. `"box_lattice"`.
        shape: &'static str,
        /// The parameters, e.g. `"cells"` or `"rings, sectors"`.
        parameter: &'static str,
        /// The values given, as written in the message.
        value: String,
    },
}

/// `Ok` if `value` is a finite length greater than zero.
pub(super) fn check_length(
    shape: &'static str,
    parameter: &'static str,
    value: Real,
) -> Result<(), GeneratorError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(GeneratorError::BadLength {
            shape,
            parameter,
            value,
        })
    }
}

/// `Ok` if `value` is at least `minimum`.
pub(super) fn check_count(
    shape: &'static str,
    parameter: &'static str,
    value: usize,
    minimum: usize,
) -> Result<(), GeneratorError> {
    if value >= minimum {
        Ok(())
    } else {
        Err(GeneratorError::TooFew {
            shape,
            parameter,
            value,
            minimum,
        })
    }
}

/// The sum of the products of `terms`, or `None` on overflow: the size of a list to allocate.
pub(super) fn sum_of_products(terms: &[Vec<usize>]) -> Option<usize> {
    terms.iter().try_fold(0usize, |sum, factors| {
        let product = factors.iter().try_fold(1usize, |p, &f| p.checked_mul(f))?;
        sum.checked_add(product)
    })
}

/// An empty list with room for exactly `count` items; an error instead of an abort when that
/// much memory cannot be had (a mistyped cell count should not kill the program).
pub(super) fn allocate<T>(
    count: Option<usize>,
    shape: &'static str,
    parameter: &'static str,
    value: impl FnOnce() -> String,
) -> Result<Vec<T>, GeneratorError> {
    let mut list = Vec::new();
    match count.map(|c| list.try_reserve_exact(c)) {
        Some(Ok(())) => Ok(list),
        _ => Err(GeneratorError::TooLarge {
            shape,
            parameter,
            value: value(),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_name_the_parameter_and_the_allowed_values() {
        let e = check_length("disk", "radius", -1.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("disk: radius = -1 m"), "{e}");
        assert!(e.contains("greater than 0"), "{e}");
        let e = check_count("disk", "sectors", 2, 3)
            .unwrap_err()
            .to_string();
        assert!(e.contains("sectors = 2") && e.contains("3 or more"), "{e}");
        assert!(check_length("disk", "radius", Real::NAN).is_err());
        assert!(check_length("disk", "radius", Real::INFINITY).is_err());
        assert!(check_length("disk", "radius", 0.0).is_err());
    }

    #[test]
    fn overflowing_sizes_are_an_error_not_an_abort() {
        assert_eq!(sum_of_products(&[vec![2, 3], vec![4]]), Some(10));
        assert_eq!(sum_of_products(&[vec![usize::MAX, 2]]), None);
        let r = allocate::<u8>(None, "box_lattice", "cells", || "[1, 2, 3]".into());
        assert!(r
            .unwrap_err()
            .to_string()
            .contains("box_lattice: cells = [1, 2, 3] asks for more"));
    }
}
