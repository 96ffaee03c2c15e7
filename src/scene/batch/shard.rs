//! `--shard I/N`: the I-th of N disjoint slices of a batch's jobs (job j, 0-based, belongs to
//! shard `j mod N + 1`, so similar variants spread over the shards), or `--shard slurm`: I and
//! N from a job-array scheduler's variables.

use crate::scene::batch::error::BatchError;

/// The array variables `--shard slurm` reads, in the order tried: (scheduler, index variable,
/// first-index variable, last-index or count variable, whether the last is a count).
pub const ARRAY_VARIABLES: &[(&str, &str, &str, &str, bool)] = &[
    (
        "Slurm",
        "SLURM_ARRAY_TASK_ID",
        "SLURM_ARRAY_TASK_MIN",
        "SLURM_ARRAY_TASK_COUNT",
        true,
    ),
    (
        "Grid Engine",
        "SGE_TASK_ID",
        "SGE_TASK_FIRST",
        "SGE_TASK_LAST",
        false,
    ),
    ("LSF", "LSB_JOBINDEX", "", "LSB_JOBINDEX_END", false),
];

/// One slice of a batch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// 1-based slice number, 1 ≤ index ≤ count.
    pub index: usize,
    /// Number of slices.
    pub count: usize,
}

impl Shard {
    /// Parse `I/N` (1 ≤ I ≤ N), or `slurm`: I and N from the environment (see [`Shard::from_env`]).
    pub fn parse(given: &str) -> Result<Self, BatchError> {
        if given == "slurm" {
            return Self::from_env(|name| std::env::var(name).ok());
        }
        let bad = |problem: &str| BatchError::Shard {
            given: given.to_string(),
            problem: problem.to_string(),
        };
        let (i, n) = given
            .split_once('/')
            .ok_or_else(|| bad("give I/N, e.g. 2/3 (the second of three slices), or `slurm`"))?;
        let index: usize = i
            .trim()
            .parse()
            .map_err(|_| bad("I in I/N must be a whole number from 1"))?;
        let count: usize = n
            .trim()
            .parse()
            .map_err(|_| bad("N in I/N must be a whole number from 1"))?;
        Self::new(index, count).map_err(|p| bad(&p))
    }

    /// A checked shard.
    pub fn new(index: usize, count: usize) -> Result<Self, String> {
        if count == 0 || index == 0 || index > count {
            return Err(format!("I/N = {index}/{count}: give 1 ≤ I ≤ N"));
        }
        Ok(Shard { index, count })
    }

    /// I and N from the first scheduler in [`ARRAY_VARIABLES`] whose index variable is set
    /// (`var` looks a variable up): I = index − first + 1.
    pub fn from_env(var: impl Fn(&str) -> Option<String>) -> Result<Self, BatchError> {
        for &(scheduler, index, first, last, is_count) in ARRAY_VARIABLES {
            let Some(id) = var(index) else { continue };
            let number = |name: &str| -> Result<usize, BatchError> {
                let text = var(name).ok_or_else(|| BatchError::Shard {
                    given: "slurm".into(),
                    problem: format!("{index} = {id} is set but {name} is not: run inside a {scheduler} job array, or give --shard I/N"),
                })?;
                text.trim().parse().map_err(|_| BatchError::Shard {
                    given: "slurm".into(),
                    problem: format!("{name} = {text:?} is not a whole number"),
                })
            };
            let id = number(index)?;
            let first = if first.is_empty() {
                1
            } else {
                number(first).unwrap_or(1)
            };
            let end = number(last)?;
            let count = if is_count {
                end
            } else {
                end + 1 - first.min(end + 1)
            };
            let i = (id + 1).saturating_sub(first);
            return Self::new(i, count).map_err(|p| BatchError::Shard {
                given: "slurm".into(),
                problem: format!("{scheduler}'s {index} = {id} ({first} first) gives {p}"),
            });
        }
        Err(BatchError::Shard {
            given: "slurm".into(),
            problem: "no job-array variable is set (SLURM_ARRAY_TASK_ID, SGE_TASK_ID or LSB_JOBINDEX): submit the script `linkage slurm` writes, or give --shard I/N".into(),
        })
    }

    /// Whether job `j` (0-based, in batch order) is in this slice.
    pub fn takes(&self, j: usize) -> bool {
        j % self.count == self.index - 1
    }

    /// This shard's part of the table: `batch.part-I-of-N.csv`.
    pub fn part_name(&self) -> String {
        format!("batch.part-{}-of-{}.csv", self.index, self.count)
    }
}

/// (I, N) of a part's file name `batch.part-I-of-N.csv`.
pub(crate) fn part_of(file_name: &str) -> Option<(usize, usize)> {
    let rest = file_name
        .strip_prefix("batch.part-")?
        .strip_suffix(".csv")?;
    let (i, n) = rest.split_once("-of-")?;
    Some((i.parse().ok()?, n.parse().ok()?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_of_seven_jobs_take_each_once() {
        let shards: Vec<Shard> = (1..=3)
            .map(|i| Shard::parse(&format!("{i}/3")).unwrap())
            .collect();
        for j in 0..7 {
            assert_eq!(shards.iter().filter(|s| s.takes(j)).count(), 1);
        }
        assert_eq!(part_of(&shards[1].part_name()), Some((2, 3)));
        for bad in ["0/3", "4/3", "1/0", "x/2", "2", "1/y"] {
            assert!(Shard::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn array_variables_give_the_shard() {
        let env = |pairs: &'static [(&'static str, &'static str)]| {
            move |name: &str| {
                pairs
                    .iter()
                    .find(|(k, _)| *k == name)
                    .map(|(_, v)| v.to_string())
            }
        };
        let slurm = env(&[
            ("SLURM_ARRAY_TASK_ID", "3"),
            ("SLURM_ARRAY_TASK_MIN", "1"),
            ("SLURM_ARRAY_TASK_COUNT", "3"),
        ]);
        assert_eq!(
            Shard::from_env(slurm).unwrap(),
            Shard { index: 3, count: 3 }
        );
        // Grid Engine numbers tasks 1..=last by default.
        let sge = env(&[
            ("SGE_TASK_ID", "2"),
            ("SGE_TASK_FIRST", "1"),
            ("SGE_TASK_LAST", "4"),
        ]);
        assert_eq!(Shard::from_env(sge).unwrap(), Shard { index: 2, count: 4 });
        let lsf = env(&[("LSB_JOBINDEX", "1"), ("LSB_JOBINDEX_END", "2")]);
        assert_eq!(Shard::from_env(lsf).unwrap(), Shard { index: 1, count: 2 });
        assert!(Shard::from_env(env(&[])).is_err());
        assert!(Shard::from_env(env(&[("SLURM_ARRAY_TASK_ID", "1")])).is_err());
    }
}
