//! A member's material and section: Young's modulus, area, strength, and which sign it carries.

use crate::Real;

/// Which sign of axial force a member can carry.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Behaviour {
    /// Carries tension and compression alike: `N = E A ε`.
    #[default]
    Elastic,
    /// A cable: `N = E A ε` when stretched (ε > 0), zero when slack.
    TensionOnly,
    /// A strut that only pushes (a contact rod): `N = E A ε` when shortened (ε < 0), zero otherwise.
    CompressionOnly,
}

impl Behaviour {
    /// Whether a member at engineering strain `strain` carries force.
    pub fn is_active(self, strain: Real) -> bool {
        match self {
            Behaviour::Elastic => true,
            Behaviour::TensionOnly => strain > 0.0,
            Behaviour::CompressionOnly => strain < 0.0,
        }
    }
}

/// What happens to a member of a material when its stress reaches the strength.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Failure {
    /// It is only marked overloaded (the paper's Fig. 6) and keeps carrying load.
    #[default]
    Mark,
    /// It breaks: it carries nothing from then on and its load passes to its neighbours.
    Break,
}

/// Scatter of the members' strengths: each member's strength is the material's times a factor
/// drawn from a Weibull law of unit scale, `F(x) = 1 − exp(−x^m)`, `m` the Weibull modulus.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scatter {
    /// The Weibull modulus m (shape): larger is less scatter; finite and > 0.
    pub weibull_modulus: Real,
    /// Seed of the generator (ChaCha8): the same seed draws the same strengths everywhere.
    pub seed: u64,
}

/// The saw-tooth softening of breaking members (see `linkage::fracture::saw_tooth`): each
/// member passes through `teeth` teeth of falling stiffness and strength before it breaks,
/// dissipating `fracture_energy` over its cross-section.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Softening {
    /// Fracture energy G_f, J/m² (per unit of the member's cross-section area); finite, > 0.
    pub fracture_energy: Real,
    /// Number of teeth n ≥ 1 (1: brittle).
    pub teeth: usize,
}

/// The material and cross-section of a member: what the paper's `AE` is made of.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Name used by scene files and links files to refer to it.
    pub name: String,
    /// Young's modulus E, Pa.
    pub youngs_modulus: Real,
    /// Cross-section area A, m².
    pub area: Real,
    /// Largest tensile stress before the member counts as overloaded, Pa (none: no limit).
    pub tensile_strength: Option<Real>,
    /// Largest compressive stress (given as a positive number), Pa (none: no limit).
    pub compressive_strength: Option<Real>,
    /// Whether members of this material carry tension, compression or both.
    pub behaviour: Behaviour,
    /// Whether members reaching their strength are marked or break.
    pub failure: Failure,
    /// Scatter of the strengths of breaking members (none: every member has the strength).
    pub scatter: Option<Scatter>,
    /// Saw-tooth softening of breaking members (none: they break at their strength).
    pub softening: Option<Softening>,
    /// Young's modulus the body should have as a solid, Pa (`continuum_modulus`): when given,
    /// `area` is chosen per body to give it (see [`crate::linkage::homogenize`]).
    pub continuum_modulus: Option<Real>,
}

impl Material {
    /// A material without strength limits.
    pub fn new(name: &str, youngs_modulus: Real, area: Real) -> Self {
        Material {
            name: name.to_string(),
            youngs_modulus,
            area,
            tensile_strength: None,
            compressive_strength: None,
            behaviour: Behaviour::Elastic,
            failure: Failure::Mark,
            scatter: None,
            softening: None,
            continuum_modulus: None,
        }
    }

    /// Whether a member of this material at `stress` (Pa, tension positive) is beyond its strength.
    pub fn is_overloaded(&self, stress: Real) -> bool {
        match (self.tensile_strength, self.compressive_strength) {
            (Some(t), _) if stress > t => true,
            (_, Some(c)) if stress < -c => true,
            _ => false,
        }
    }

    /// Why this material cannot be used, if it cannot: E, A and their product E A must be
    /// finite and positive, strengths finite and positive when given.
    pub fn problem(&self) -> Option<String> {
        let positive = |v: Real| v.is_finite() && v > 0.0;
        if !positive(self.youngs_modulus) {
            return Some(format!(
                "youngs_modulus = {} must be a finite positive number of Pa",
                self.youngs_modulus
            ));
        }
        if !positive(self.area) {
            return Some(format!(
                "area = {} must be a finite positive number of m²",
                self.area
            ));
        }
        let axial = self.youngs_modulus * self.area;
        if !positive(axial) {
            return Some(format!(
                "youngs_modulus = {:e} times area = {:e} gives E A = {axial:e} N, out of the range that can be computed with (finite and > 0): check the units (Pa and m²)",
                self.youngs_modulus, self.area
            ));
        }
        for (key, v) in [
            ("tensile_strength", self.tensile_strength),
            ("compressive_strength", self.compressive_strength),
        ] {
            if let Some(v) = v {
                if !positive(v) {
                    return Some(format!(
                        "{key} = {v} must be a finite positive number of Pa"
                    ));
                }
            }
        }
        if let Some(scatter) = self.scatter {
            if !positive(scatter.weibull_modulus) {
                return Some(format!(
                    "scatter.weibull_modulus = {} must be a finite positive number",
                    scatter.weibull_modulus
                ));
            }
        }
        if let Some(softening) = self.softening {
            if !positive(softening.fracture_energy) {
                return Some(format!(
                    "softening.fracture_energy = {} must be a finite positive number of J/m²",
                    softening.fracture_energy
                ));
            }
            if softening.teeth == 0 {
                return Some("softening.teeth = 0: give at least 1 tooth (1 is brittle)".into());
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overload_respects_sign_and_limits() {
        let mut m = Material::new("s", 1.0, 1.0);
        assert!(!m.is_overloaded(1e30));
        m.tensile_strength = Some(10.0);
        m.compressive_strength = Some(5.0);
        assert!(m.is_overloaded(10.5));
        assert!(!m.is_overloaded(10.0));
        assert!(!m.is_overloaded(-5.0));
        assert!(m.is_overloaded(-5.5));
    }

    #[test]
    fn bad_values_are_named() {
        assert!(Material::new("s", 0.0, 1.0)
            .problem()
            .unwrap()
            .contains("youngs_modulus"));
        assert!(Material::new("s", 1.0, Real::NAN)
            .problem()
            .unwrap()
            .contains("area"));
        assert!(Material::new("s", 1.0, 1.0).problem().is_none());
    }
}
