//! Schedules in time: a load's, prescribed displacement's or gravity's factor at a time of a
//! dynamic scene.

use crate::linkage::{prescribed_displacements, Body, Schedule};
use crate::Real;

/// The factor of `schedule` at time `t` (s) of a run lasting `duration` (s): `n` factors stand
/// at the equally spaced times `k · duration / (n − 1)`, `k = 0..n`, linear in between and
/// held after the last (one factor: constant from t = 0, so `[1.0]` is full from the start);
/// [`Schedule::Linear`] is the ramp `t / duration` (the scene builder gives a load without
/// schedule `[1.0]` and a support displacement `[0.0, 1.0]`).
pub fn time_factor(schedule: &Schedule, t: Real, duration: Real) -> Real {
    let s = (t / duration).clamp(0.0, 1.0);
    match schedule {
        Schedule::Linear => s,
        Schedule::Factors(f) if f.is_empty() => 0.0,
        Schedule::Factors(f) if f.len() == 1 => f[0],
        Schedule::Factors(f) => {
            let x = s * (f.len() - 1) as Real;
            let k = (x.floor() as usize).min(f.len() - 2);
            let w = x - k as Real;
            f[k] + w * (f[k + 1] - f[k])
        }
    }
}

/// The applied force per body DOF at time `t` (s) of `duration`, N.
pub fn loads_at_time(body: &Body, t: Real, duration: Real) -> Vec<Real> {
    let d = body.dimension.dofs_per_node();
    let mut f = vec![0.0; body.dof_count()];
    for l in &body.loads {
        let factor = time_factor(&l.schedule, t, duration);
        for k in 0..d {
            f[l.node * d + k] += factor * l.force[k];
        }
    }
    f
}

/// The prescribed displacement per body DOF at time `t` (s) of `duration`, m (zero at free
/// DOFs and at supports that only hold).
pub fn prescribed_at_time(body: &Body, t: Real, duration: Real) -> Vec<Real> {
    prescribed_displacements(body, |s| time_factor(s, t, duration))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn factors_stand_at_equally_spaced_times_including_zero() {
        let ramp = Schedule::Factors(vec![0.0, 1.0, 0.0]);
        // Factors at t = 0, 1, 2 s of a 2 s run: 0.5 at 0.5 s, 0.25 at 1.75 s.
        assert!((time_factor(&ramp, 0.5, 2.0) - 0.5).abs() < 1e-15);
        assert!((time_factor(&ramp, 1.75, 2.0) - 0.25).abs() < 1e-15);
        assert_eq!(time_factor(&ramp, 3.0, 2.0), 0.0);
        assert_eq!(time_factor(&Schedule::Factors(vec![1.0]), 0.0, 2.0), 1.0);
        assert_eq!(time_factor(&Schedule::Linear, 0.5, 2.0), 0.25);
    }
}
