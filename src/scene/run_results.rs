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
}

impl RunResults {
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
