//! `[contact]` friction and `[[contact.pairs]]`: coefficients checked, pair names resolved against the scene's bodies and obstacles.

use crate::contact::{FrictionPair, FrictionSettings};
use crate::scene::spec::{ContactPairSpec, ContactSpec};
use crate::Real;
use std::ops::Range;

/// The friction of `[contact]` and its pairs, each name checked against `names` (the scene's
/// bodies and obstacles). `Err` with the span of the table or pair at fault and the message.
pub(crate) fn friction_settings(
    spec: &ContactSpec,
    names: &[&str],
    table: Range<usize>,
) -> Result<FrictionSettings, (Range<usize>, String)> {
    let coefficient =
        coefficient("[contact] friction", spec.friction).map_err(|e| (table.clone(), e))?;
    let stick_stiffness =
        stiffness("[contact] stick_stiffness", spec.stick_stiffness).map_err(|e| (table, e))?;
    let mut pairs: Vec<FrictionPair> = Vec::with_capacity(spec.pairs.len());
    for (k, p) in spec.pairs.iter().enumerate() {
        let pair = pair_from(k + 1, p.get_ref(), names).map_err(|e| (p.span(), e))?;
        let same = |q: &FrictionPair| {
            let mut a = q.between.clone();
            let mut b = pair.between.clone();
            a.sort();
            b.sort();
            a == b
        };
        if let Some(j) = pairs.iter().position(same) {
            return Err((
                p.span(),
                format!(
                    "[[contact.pairs]] {} repeats pair {} (between \"{}\" and \"{}\"): give each pair once",
                    k + 1,
                    j + 1,
                    pair.between[0],
                    pair.between[1]
                ),
            ));
        }
        pairs.push(pair);
    }
    Ok(FrictionSettings {
        coefficient: coefficient.unwrap_or(0.0),
        stick_stiffness,
        pairs,
    })
}

/// Pair number `k` (1-based) of `[[contact.pairs]]`.
fn pair_from(k: usize, p: &ContactPairSpec, names: &[&str]) -> Result<FrictionPair, String> {
    let [a, b] = p.between.as_slice() else {
        return Err(format!(
            "[[contact.pairs]] {k}: between has {} names: give two, bodies or obstacles, e.g. between = [\"block\", \"floor\"]",
            p.between.len()
        ));
    };
    for name in [a, b] {
        if !names.contains(&name.as_str()) {
            return Err(format!(
                "[[contact.pairs]] {k}: no body or obstacle is named \"{name}\" (the scene has {})",
                names
                    .iter()
                    .map(|n| format!("\"{n}\""))
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
    }
    if p.friction.is_none() && p.stick_stiffness.is_none() {
        return Err(format!(
            "[[contact.pairs]] {k} (between \"{a}\" and \"{b}\") sets nothing: give friction or stick_stiffness"
        ));
    }
    Ok(FrictionPair {
        between: [a.clone(), b.clone()],
        coefficient: coefficient(&format!("[[contact.pairs]] {k}: friction"), p.friction)?,
        stick_stiffness: stiffness(
            &format!("[[contact.pairs]] {k}: stick_stiffness"),
            p.stick_stiffness,
        )?,
    })
}

/// A Coulomb coefficient: finite and ≥ 0.
fn coefficient(key: &str, value: Option<Real>) -> Result<Option<Real>, String> {
    match value {
        Some(v) if !(v.is_finite() && v >= 0.0) => Err(format!(
            "{key} = {v}: give a Coulomb coefficient ≥ 0 (0: frictionless)"
        )),
        v => Ok(v),
    }
}

/// A stick stiffness: finite and > 0, N/m.
fn stiffness(key: &str, value: Option<Real>) -> Result<Option<Real>, String> {
    match value {
        Some(v) if !(v.is_finite() && v > 0.0) => Err(format!(
            "{key} = {v}: give a stiffness > 0, N/m of elastic slip"
        )),
        v => Ok(v),
    }
}
