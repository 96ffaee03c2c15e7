//! A run's results in memory: the undeformed model and its stored steps, as every writer after
//! the load steps (VTK, pictures) and `linkage render` take them.

use crate::scene::model_file::ModelFile;
use crate::scene::results::StepResult;

/// The model and the stored steps of one run, held in memory: filled by the driver as the
/// steps are solved, or read back from a results folder by [`crate::scene::StoredRun`].
#[derive(Clone, Debug, PartialEq)]
pub struct RunResults {
    /// The undeformed model (`model.json`).
    pub model: ModelFile,
    /// The stored steps (`steps/NNNN.json`), ascending (step 0 first).
    pub steps: Vec<StepResult>,
    /// Digits of the step numbers in the run's file names (see [`step_digits`]): the
    /// pictures and VTK files of these steps are named with as many.
    pub digits: usize,
}

/// The fewest digits of step numbers in file names (`steps/0000.json`).
pub const MIN_STEP_DIGITS: usize = 4;

/// Digits of the step numbers in the file names of a run whose last step is `last_step`:
/// enough for it, at least [`MIN_STEP_DIGITS`], so the names sort in step order.
pub fn step_digits(last_step: usize) -> usize {
    last_step.to_string().len().max(MIN_STEP_DIGITS)
}

/// `step` zero-padded to `digits` digits, the stem of its file names (`0042`).
pub fn step_stem(step: usize, digits: usize) -> String {
    format!("{step:0digits$}")
}

impl RunResults {
    /// The stem of stored step `step`'s file names, padded to [`RunResults::digits`].
    pub fn stem(&self, step: usize) -> String {
        step_stem(step, self.digits)
    }

    /// The numbers of the stored steps, ascending.
    pub fn step_numbers(&self) -> Vec<usize> {
        self.steps.iter().map(|s| s.step).collect()
    }

    /// Stored step `step`, if it is stored.
    pub fn step(&self, step: usize) -> Option<&StepResult> {
        self.steps
            .binary_search_by_key(&step, |s| s.step)
            .ok()
            .map(|k| &self.steps[k])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_have_enough_digits_for_the_last_step_and_at_least_four() {
        assert_eq!(step_digits(0), 4);
        assert_eq!(step_digits(9_999), 4);
        assert_eq!(step_digits(10_000), 5);
        assert_eq!(step_digits(100_000), 6);
        assert_eq!(step_stem(42, 4), "0042");
        assert_eq!(step_stem(42, 6), "000042");
        assert_eq!(step_stem(100_000, 6), "100000");
    }
}
