//! A results folder read back: `model.json` and the stored `steps/NNNN.json` (or `model.npz`
//! and `steps/NNNN.npz`), checked against each other, for drawing and exporting a run without solving it again.

use crate::linkage::Interrupt;
use crate::scene::model_file::ModelFile;
use crate::scene::npz_files::{read_model_npz, read_step_npz};
use crate::scene::result_format::ResultFormat;
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
    /// Asked to stop (SIGINT, SIGTERM) while the steps were read: nothing was made of them.
    #[error("{dir}: interrupted while reading the stored results: nothing was written")]
    Interrupted {
        /// The results folder.
        dir: PathBuf,
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
    /// Whether the model and the steps are JSON or `.npz` files.
    pub format: ResultFormat,
    /// Stored step numbers, ascending (step 0 first).
    pub steps: Vec<usize>,
    /// Digits of the step numbers in the step files' names (the most any has, at least 4):
    /// pictures and VTK files drawn from the folder are named with as many.
    pub digits: usize,
    /// The step files' names, in the order of `steps`.
    files: Vec<String>,
}

impl StoredRun {
    /// Read `dir/model.json` or `dir/model.npz` (whichever the folder holds: both or neither is
    /// an error) and list the step files of the same format, `dir/steps/NNNN.json` or `.npz`
    /// (any number of digits from 4, as many as the run's last step needs).
    pub fn open(dir: &Path) -> Result<Self, StoredRunError> {
        let format = Self::model_format(dir)?;
        let path = dir.join(format.model_file());
        let bytes = std::fs::read(&path).map_err(|source| StoredRunError::Read {
            hint: FOLDER_HINT,
            path: path.clone(),
            source,
        })?;
        let model: ModelFile = match format {
            ResultFormat::Json => serde_json::from_slice(&bytes).map_err(|e| e.to_string()),
            ResultFormat::Npz => read_model_npz(&bytes),
        }
        .map_err(|e| StoredRunError::Bad {
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
        let ext = format.extension();
        let other = match format {
            ResultFormat::Json => ResultFormat::Npz,
            ResultFormat::Npz => ResultFormat::Json,
        };
        let mut found: Vec<(usize, String)> = Vec::new();
        for entry in entries {
            let entry = entry.map_err(|source| StoredRunError::Read {
                path: steps_dir.clone(),
                source,
                hint: FOLDER_HINT,
            })?;
            let name = entry.file_name().to_string_lossy().into_owned();
            for (e, ours) in [(ext, true), (other.extension(), false)] {
                let Some(k) = step_number(&name, e) else {
                    continue;
                };
                if !ours {
                    return Err(StoredRunError::Bad {
                        path: steps_dir,
                        problem: format!(
                            "holds {name}, but the run's model is {}: its step files are NNNN.{ext}",
                            format.model_file()
                        ),
                    });
                }
                found.push((k, name.clone()));
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
            .map(|(_, name)| name.len() - ext.len() - 1)
            .fold(MIN_STEP_DIGITS, usize::max);
        let (steps, files): (Vec<usize>, Vec<String>) = found.into_iter().unzip();
        if steps.is_empty() {
            return Err(StoredRunError::Bad {
                path: steps_dir,
                problem: format!("holds no step files (NNNN.{ext})"),
            });
        }
        Ok(StoredRun {
            dir: dir.to_path_buf(),
            model,
            format,
            steps,
            digits,
            files,
        })
    }

    /// The format of the results in `dir`: the one whose model file it holds.
    fn model_format(dir: &Path) -> Result<ResultFormat, StoredRunError> {
        let json = dir.join(ResultFormat::Json.model_file());
        let npz = dir.join(ResultFormat::Npz.model_file());
        match (json.exists(), npz.exists()) {
            (true, false) => Ok(ResultFormat::Json),
            (false, true) => Ok(ResultFormat::Npz),
            (true, true) => Err(StoredRunError::Bad {
                path: dir.to_path_buf(),
                problem: "holds both model.json and model.npz, so which results are the run's is not clear: remove the older".to_string(),
            }),
            (false, false) => match std::fs::metadata(dir) {
                Ok(m) if m.is_dir() => Err(StoredRunError::Bad {
                    path: dir.to_path_buf(),
                    problem: "holds neither model.json nor model.npz: it was written by an older linkage or is not a results folder".to_string(),
                }),
                // Not a folder: reading its model.json says why.
                _ => Err(StoredRunError::Read {
                    source: std::fs::read(&json).err().unwrap_or_else(|| {
                        std::io::Error::other("model.json appeared while it was looked for")
                    }),
                    path: json,
                    hint: FOLDER_HINT,
                }),
            },
        }
    }

    /// The file of stored step `step` (as it is named in the folder; a step not stored: the
    /// name it would have).
    pub fn step_path(&self, step: usize) -> PathBuf {
        let name = match self.steps.binary_search(&step) {
            Ok(i) => self.files[i].clone(),
            Err(_) => format!(
                "{}.{}",
                step_stem(step, self.digits),
                self.format.extension()
            ),
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
        let result: StepResult = match self.format {
            ResultFormat::Json => serde_json::from_slice(&bytes).map_err(|e| e.to_string()),
            ResultFormat::Npz => read_step_npz(&bytes, &self.model),
        }
        .map_err(|e| StoredRunError::Bad {
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
        self.read_all_until(Interrupt::default())
    }

    /// [`Self::read_all`], stopping before the next step file once `stop` is raised
    /// ([`StoredRunError::Interrupted`]).
    pub fn read_all_until(self, stop: Interrupt) -> Result<RunResults, StoredRunError> {
        let mut steps = Vec::with_capacity(self.steps.len());
        for &k in &self.steps {
            if stop.is_raised() {
                return Err(StoredRunError::Interrupted { dir: self.dir });
            }
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

/// The step number of a step file's `name` with extension `ext` (`0042.json`: 42), if it is one.
fn step_number(name: &str, ext: &str) -> Option<usize> {
    let stem = name.strip_suffix(ext)?.strip_suffix('.')?;
    if stem.len() >= MIN_STEP_DIGITS && stem.bytes().all(|b| b.is_ascii_digit()) {
        stem.parse().ok()
    } else {
        None
    }
}

impl RunResults {
    /// Read the results folder `dir` (`DIR/<scene>`): [`StoredRun::open`], then
    /// [`StoredRun::read_all`].
    pub fn read(dir: &Path) -> Result<Self, StoredRunError> {
        StoredRun::open(dir)?.read_all()
    }

    /// [`Self::read`], stopping before the next step file once `stop` is raised
    /// ([`StoredRunError::Interrupted`]).
    pub fn read_until(dir: &Path, stop: Interrupt) -> Result<Self, StoredRunError> {
        StoredRun::open(dir)?.read_all_until(stop)
    }
}
