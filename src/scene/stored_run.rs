//! A results folder read back: `model.json` and the stored `steps/NNNN.json`, checked against
//! each other, for drawing and exporting a run without solving it again.

use crate::scene::model_file::ModelFile;
use crate::scene::results::StepResult;
use crate::scene::run_results::{step_stem, RunResults, MIN_STEP_DIGITS};
use std::path::{Path, PathBuf};

/// Why a results folder cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum StoredRunError {
    /// The folder or one of its files is missing or unreadable.
    #[error("{path}: cannot read: {source}; {hint}")]
    Read {
        /// File or folder.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
        /// What to do.
        hint: &'static str,
    },
    /// A file that is not what `linkage run` writes (torn, edited or from another version).
    #[error("{path}: {problem}; run the scene again with `linkage run`")]
    Bad {
        /// File.
        path: PathBuf,
        /// What is wrong.
        problem: String,
    },
}

const FOLDER_HINT: &str =
    "give a folder written by `linkage run SCENE --out DIR` (DIR/<scene name>)";

/// A complete results folder: the model and the numbers of its stored steps (the steps
/// themselves are read by [`StoredRun::read_step`] or, all at once, [`StoredRun::read_all`]).
#[derive(Clone, Debug)]
pub struct StoredRun {
    /// The folder, `DIR/<scene>`.
    pub dir: PathBuf,
    /// The undeformed model.
    pub model: ModelFile,
    /// Stored step numbers, ascending (step 0 first).
    pub steps: Vec<usize>,
    /// Digits of the step numbers in the step files' names (the most any has, at least 4):
    /// pictures and VTK files drawn from the folder are named with as many.
    pub digits: usize,
    /// The step files' names, in the order of `steps`.
    files: Vec<String>,
}

impl StoredRun {
    /// Read `dir/model.json` and list `dir/steps/NNNN.json` (any number of digits from 4, as
    /// many as the run's last step needs).
    pub fn open(dir: &Path) -> Result<Self, StoredRunError> {
        let path = dir.join("model.json");
        let bytes = std::fs::read(&path).map_err(|source| StoredRunError::Read {
            hint: if dir.is_dir() {
                "the folder was written by an older linkage or is not a results folder: run the scene again with `linkage run`"
            } else {
                FOLDER_HINT
            },
            path: path.clone(),
            source,
        })?;
        let model: ModelFile = serde_json::from_slice(&bytes).map_err(|e| StoredRunError::Bad {
            path: path.clone(),
            problem: format!("not a model file ({e})"),
        })?;
        if let Some(problem) = model.problem() {
            return Err(StoredRunError::Bad { path, problem });
        }
        let steps_dir = dir.join("steps");
        let entries = std::fs::read_dir(&steps_dir).map_err(|source| StoredRunError::Read {
            path: steps_dir.clone(),
            source,
            hint: FOLDER_HINT,
        })?;
        let mut found: Vec<(usize, String)> = Vec::new();
        for entry in entries {
            let entry = entry.map_err(|source| StoredRunError::Read {
                path: steps_dir.clone(),
                source,
                hint: FOLDER_HINT,
            })?;
            let name = entry.file_name().to_string_lossy().into_owned();
            if let Some(stem) = name.strip_suffix(".json") {
                if stem.len() >= MIN_STEP_DIGITS && stem.bytes().all(|b| b.is_ascii_digit()) {
                    if let Ok(k) = stem.parse::<usize>() {
                        found.push((k, name));
                    }
                }
            }
        }
        found.sort_unstable();
        if let Some(w) = found.windows(2).find(|w| w[0].0 == w[1].0) {
            return Err(StoredRunError::Bad {
                path: steps_dir,
                problem: format!(
                    "holds two files of step {}: {} and {}",
                    w[0].0, w[0].1, w[1].1
                ),
            });
        }
        let digits = found
            .iter()
            .map(|(_, name)| name.len() - ".json".len())
            .fold(MIN_STEP_DIGITS, usize::max);
        let (steps, files): (Vec<usize>, Vec<String>) = found.into_iter().unzip();
        if steps.is_empty() {
            return Err(StoredRunError::Bad {
                path: steps_dir,
                problem: "holds no step files (NNNN.json)".to_string(),
            });
        }
        Ok(StoredRun {
            dir: dir.to_path_buf(),
            model,
            steps,
            digits,
            files,
        })
    }

    /// The file of stored step `step` (as it is named in the folder; a step not stored: the
    /// name it would have).
    pub fn step_path(&self, step: usize) -> PathBuf {
        let name = match self.steps.binary_search(&step) {
            Ok(i) => self.files[i].clone(),
            Err(_) => format!("{}.json", step_stem(step, self.digits)),
        };
        self.dir.join("steps").join(name)
    }

    /// Read stored step `step` and check that it matches the model (bodies, nodes, members).
    pub fn read_step(&self, step: usize) -> Result<StepResult, StoredRunError> {
        let path = self.step_path(step);
        let bytes = std::fs::read(&path).map_err(|source| StoredRunError::Read {
            path: path.clone(),
            source,
            hint: "the folder is incomplete",
        })?;
        let result: StepResult =
            serde_json::from_slice(&bytes).map_err(|e| StoredRunError::Bad {
                path: path.clone(),
                problem: format!("not a step file ({e})"),
            })?;
        if let Some(problem) = self.model.step_problem(&result) {
            return Err(StoredRunError::Bad { path, problem });
        }
        Ok(result)
    }

    /// Read every stored step into memory, each checked against the model and its file name.
    pub fn read_all(self) -> Result<RunResults, StoredRunError> {
        let mut steps = Vec::with_capacity(self.steps.len());
        for &k in &self.steps {
            let result = self.read_step(k)?;
            if result.step != k {
                return Err(StoredRunError::Bad {
                    path: self.step_path(k),
                    problem: format!("says step {} but is named for step {k}", result.step),
                });
            }
            steps.push(result);
        }
        Ok(RunResults {
            model: self.model,
            steps,
            digits: self.digits,
        })
    }
}

impl RunResults {
    /// Read the results folder `dir` (`DIR/<scene>`): [`StoredRun::open`], then
    /// [`StoredRun::read_all`].
    pub fn read(dir: &Path) -> Result<Self, StoredRunError> {
        StoredRun::open(dir)?.read_all()
    }
}
