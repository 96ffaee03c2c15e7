//! The inertia term an integrator adds to one body's equilibrium within a time step.

use crate::Real;

/// The inertia (and mass-proportional damping) of one body within one time step, in the form
/// every integrator can give it: the solvers look for the configuration `y` (per body DOF, m;
/// `u_{n+1}` itself, or the blend of `u_n` and `u_{n+1}` the integrator evaluates its forces at)
/// where
///
/// `f_int(y) + coefficient · M (y − predictor) = f_ext`
///
/// with `M` the lumped mass (diagonal). The tangent gains `coefficient · M` on its diagonal.
/// The integrator maps the solved `y` back to the displacements, velocities and accelerations
/// at the step's end.
#[derive(Clone, Debug, PartialEq)]
pub struct InertiaTerm {
    /// Lumped mass per body DOF, kg (`ρ A L / 2` per member end; every direction of a node
    /// carries the node's mass).
    pub mass: Vec<Real>,
    /// Factor of `M` in the residual and the tangent, 1/s² (`4/h²` for the trapezoidal rule
    /// solved at the midpoint, `1/(β h²)` for Newmark, …).
    pub coefficient: Real,
    /// The configuration at which the inertia force vanishes, per body DOF, m.
    pub predictor: Vec<Real>,
}

impl InertiaTerm {
    /// Add the inertia force `coefficient · M (y − predictor)` (N per body DOF) to `out`.
    pub fn add_force(&self, y: &[Real], out: &mut [Real]) {
        for (((o, &m), &yi), &p) in out.iter_mut().zip(&self.mass).zip(y).zip(&self.predictor) {
            *o += self.coefficient * m * (yi - p);
        }
    }

    /// The diagonal `coefficient · M` the tangent gains, per body DOF, N/m.
    pub fn tangent_diagonal(&self) -> impl Iterator<Item = Real> + '_ {
        self.mass.iter().map(move |&m| self.coefficient * m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_force_is_the_coefficient_times_mass_times_the_distance_from_the_predictor() {
        let term = InertiaTerm {
            mass: vec![2.0, 3.0],
            coefficient: 4.0,
            predictor: vec![0.5, -1.0],
        };
        let mut out = vec![1.0, 0.0];
        term.add_force(&[1.5, 1.0], &mut out);
        // 1 + 4·2·(1.5 − 0.5) = 9; 4·3·(1 − (−1)) = 24.
        assert_eq!(out, vec![9.0, 24.0]);
        assert_eq!(term.tangent_diagonal().collect::<Vec<_>>(), vec![8.0, 12.0]);
    }
}
