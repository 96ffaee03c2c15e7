//! `linkage collect` and `linkage slurm`: parse, call `linkage::scene::batch`, print.

use anyhow::{bail, Context, Result};
use linkage::scene::batch::{self, SlurmOptions};
use std::path::{Path, PathBuf};

/// Merge the shards' table parts in `dir` into `dir/batch.csv`; an error when jobs are missing
/// or failed (after writing the table of those there).
pub fn collect(dir: &Path) -> Result<()> {
    let c = batch::collect(dir)?;
    say!(
        "wrote {}: {} rows from {} of {} parts",
        dir.join(batch::TABLE).display(),
        c.rows,
        c.parts,
        c.shards
    );
    let table = dir.join(batch::TABLE);
    let rows = std::fs::read_to_string(&table)
        .ok()
        .and_then(|text| batch::parse_table(&text).ok())
        .unwrap_or_default();
    if linkage::render::report::has_pictures(dir, &rows) {
        let page = linkage::render::report::write_report(dir, &rows)
            .with_context(|| format!("cannot write the report in {}", dir.display()))?;
        say!("report {}", page.display());
    }
    for job in &c.missing {
        say!("missing  {job}: its shard did not finish; run it again (complete jobs are skipped)");
    }
    for (job, status) in &c.failed {
        say!("FAIL  {job}: {status}");
    }
    if !c.missing.is_empty() || !c.failed.is_empty() {
        bail!(
            "{} jobs missing, {} failed",
            c.missing.len(),
            c.failed.len()
        );
    }
    Ok(())
}

/// Write the job-array script of `scenes` and print how to submit it.
pub fn slurm(scenes: &[PathBuf], out: &Path, options: SlurmOptions) -> Result<()> {
    let jobs = batch::plan_jobs(scenes)?;
    std::fs::create_dir_all(out)
        .with_context(|| format!("cannot create the output folder {}", out.display()))?;
    let exe = std::env::current_exe().context("cannot tell where this linkage program is")?;
    let plan = batch::write_slurm(&exe, scenes, out, jobs.len(), &options)?;
    say!(
        "wrote {} ({} jobs in {} array tasks) and {}",
        plan.script.display(),
        plan.jobs,
        plan.tasks,
        plan.collect_script.display()
    );
    say!("submit the array, and the collect job to run after it:");
    say!("  {}", plan.submit);
    Ok(())
}
