//! `linkage slurm`: a Slurm job-array script whose tasks run the shards of a batch, and a
//! collect script to run after them (`sbatch --dependency=afterany:<array job>`).

use crate::scene::batch::error::{io_at, BatchError};
use std::path::{Path, PathBuf};

/// The job-array script's name in `DIR`.
pub const ARRAY_SCRIPT: &str = "linkage.sbatch";
/// The collect script's name in `DIR`.
pub const COLLECT_SCRIPT: &str = "linkage-collect.sbatch";

/// What the job array asks of Slurm.
#[derive(Clone, Debug, PartialEq)]
pub struct SlurmOptions {
    /// Array tasks wanted (capped at the number of jobs); `None`: one task per 8 jobs.
    pub tasks: Option<usize>,
    /// Wall-time limit per task, Slurm's format (`01:00:00`, `2-00:00:00`, `90`).
    pub time: Option<String>,
    /// Cores per task; the task's runs share them.
    pub cpus_per_task: usize,
    /// Partition to submit to (default: the cluster's default).
    pub partition: Option<String>,
}

/// What [`write_slurm`] wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct SlurmPlan {
    /// `DIR/linkage.sbatch`.
    pub script: PathBuf,
    /// `DIR/linkage-collect.sbatch`.
    pub collect_script: PathBuf,
    /// Array tasks.
    pub tasks: usize,
    /// Jobs of the batch.
    pub jobs: usize,
    /// The shell command that submits the array and, after it, the collect job.
    pub submit: String,
}

/// Jobs per task when `--tasks` is not given: short runs share a task rather than each paying
/// a task's start-up and scheduling.
const JOBS_PER_TASK: usize = 8;

/// `s` quoted for a POSIX shell.
fn quote(s: &str) -> String {
    format!("'{}'", s.replace('\'', r"'\''"))
}

/// An absolute path for `p` (relative ones against the current folder).
fn absolute(p: &Path) -> Result<PathBuf, BatchError> {
    std::path::absolute(p).map_err(io_at(p))
}

/// Write `DIR/linkage.sbatch` (an array of tasks, each `linkage run SCENES --out DIR --shard
/// slurm`, packing ⌈jobs / tasks⌉ jobs into each) and `DIR/linkage-collect.sbatch`, for a batch
/// of `jobs` jobs over `scenes`, run by the program `exe`.
pub fn write_slurm(
    exe: &Path,
    scenes: &[PathBuf],
    out: &Path,
    jobs: usize,
    options: &SlurmOptions,
) -> Result<SlurmPlan, BatchError> {
    if let Some(t) = &options.time {
        if t.is_empty()
            || !t
                .chars()
                .all(|c| c.is_ascii_digit() || c == ':' || c == '-')
        {
            return Err(BatchError::Argument {
                argument: "--time",
                problem: format!("{t:?}: give Slurm's time format, e.g. 01:00:00 or 2-00:00:00"),
            });
        }
    }
    if let Some(p) = &options.partition {
        if p.is_empty()
            || !p
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "_-.,".contains(c))
        {
            return Err(BatchError::Argument {
                argument: "--partition",
                problem: format!("{p:?}: give a partition name (letters, digits, '_', '-', '.')"),
            });
        }
    }
    if options.cpus_per_task == 0 {
        return Err(BatchError::Argument {
            argument: "--cpus-per-task",
            problem: "0: give 1 or more".into(),
        });
    }
    if options.tasks == Some(0) {
        return Err(BatchError::Argument {
            argument: "--tasks",
            problem: "0: give 1 or more".into(),
        });
    }
    let tasks = options
        .tasks
        .unwrap_or(jobs.div_ceil(JOBS_PER_TASK))
        .min(jobs)
        .max(1);
    let exe = absolute(exe)?;
    let out = absolute(out)?;
    let logs = out.join("slurm");
    std::fs::create_dir_all(&logs).map_err(io_at(&logs))?;
    let mut scene_args = Vec::new();
    for s in scenes {
        scene_args.push(quote(&absolute(s)?.display().to_string()));
    }
    let name = out
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "batch".into());
    let name: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "_-.".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    let mut head = format!(
        "#!/bin/bash\n\
         # Written by `linkage slurm`: {jobs} jobs in {tasks} array tasks (each runs shard I of {tasks},\n\
         # about {} jobs). Submit with:\n\
         #   jid=$(sbatch --parsable {array}) && sbatch --dependency=afterany:${{jid%%;*}} {collect}\n\
         # A task that timed out is finished by submitting again: complete results are skipped.\n\
         #SBATCH --job-name=linkage-{name}\n\
         #SBATCH --array=1-{tasks}\n\
         #SBATCH --cpus-per-task={cpus}\n\
         #SBATCH --output={logs}/linkage-%A_%a.out\n",
        jobs.div_ceil(tasks),
        array = quote(&out.join(ARRAY_SCRIPT).display().to_string()),
        collect = quote(&out.join(COLLECT_SCRIPT).display().to_string()),
        cpus = options.cpus_per_task,
        logs = logs.display(),
    );
    if let Some(t) = &options.time {
        head.push_str(&format!("#SBATCH --time={t}\n"));
    }
    if let Some(p) = &options.partition {
        head.push_str(&format!("#SBATCH --partition={p}\n"));
    }
    let exe_q = quote(&exe.display().to_string());
    let out_q = quote(&out.display().to_string());
    let array = format!(
        "{head}set -eu\n\
         # The runs of a task share its cores.\n\
         export RAYON_NUM_THREADS=\"${{SLURM_CPUS_PER_TASK:-{cpus}}}\"\n\
         exec {exe_q} run {} --out {out_q} --shard slurm\n",
        scene_args.join(" "),
        cpus = options.cpus_per_task,
    );
    let mut collect = format!(
        "#!/bin/bash\n\
         # Written by `linkage slurm`: merges the array's table parts into batch.csv.\n\
         #SBATCH --job-name=linkage-{name}-collect\n\
         #SBATCH --cpus-per-task=1\n\
         #SBATCH --output={logs}/collect-%j.out\n",
        logs = logs.display(),
    );
    if let Some(p) = &options.partition {
        collect.push_str(&format!("#SBATCH --partition={p}\n"));
    }
    collect.push_str(&format!("set -eu\nexec {exe_q} collect {out_q}\n"));
    let script = out.join(ARRAY_SCRIPT);
    let collect_script = out.join(COLLECT_SCRIPT);
    for (path, text) in [(&script, &array), (&collect_script, &collect)] {
        crate::scene::atomic_file::write_atomically(path, text.as_bytes()).map_err(io_at(path))?;
    }
    let submit = format!(
        "jid=$(sbatch --parsable {}) && sbatch --dependency=afterany:${{jid%%;*}} {}",
        quote(&script.display().to_string()),
        quote(&collect_script.display().to_string())
    );
    Ok(SlurmPlan {
        script,
        collect_script,
        tasks,
        jobs,
        submit,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_jobs_share_tasks_and_bad_options_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let options = SlurmOptions {
            tasks: None,
            time: Some("00:10:00".into()),
            cpus_per_task: 2,
            partition: Some("debug".into()),
        };
        let plan = write_slurm(
            Path::new("/bin/linkage"),
            &[PathBuf::from("/s/a b.toml")],
            dir.path(),
            20,
            &options,
        )
        .unwrap();
        // 20 jobs, 8 a task: 3 tasks.
        assert_eq!(plan.tasks, 3);
        let text = std::fs::read_to_string(&plan.script).unwrap();
        for line in [
            "#SBATCH --array=1-3\n",
            "#SBATCH --time=00:10:00\n",
            "#SBATCH --partition=debug\n",
            "#SBATCH --cpus-per-task=2\n",
            "'/s/a b.toml' --out",
            "--shard slurm\n",
        ] {
            assert!(text.contains(line), "{line} in {text}");
        }
        assert!(plan.submit.contains("--dependency=afterany:"));
        let many = SlurmOptions {
            tasks: Some(50),
            ..options.clone()
        };
        let plan = write_slurm(Path::new("/bin/linkage"), &[], dir.path(), 6, &many).unwrap();
        assert_eq!(plan.tasks, 6);
        for bad in [
            SlurmOptions {
                time: Some("1h; rm".into()),
                ..options.clone()
            },
            SlurmOptions {
                partition: Some("a b".into()),
                ..options.clone()
            },
            SlurmOptions {
                cpus_per_task: 0,
                ..options.clone()
            },
            SlurmOptions {
                tasks: Some(0),
                ..options.clone()
            },
        ] {
            assert!(write_slurm(Path::new("/bin/linkage"), &[], dir.path(), 6, &bad).is_err());
        }
    }
}
