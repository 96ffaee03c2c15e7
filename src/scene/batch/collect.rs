//! `linkage collect DIR`: merge the shards' table parts into `DIR/batch.csv`, in batch order,
//! and say which jobs are missing or failed.

use crate::scene::batch::error::{io_at, BatchError};
use crate::scene::batch::jobs::JOB_LIST;
use crate::scene::batch::shard::part_of;
use crate::scene::batch::table::{parse_table, write_table, Row, TABLE};
use std::path::Path;

/// What [`collect`] found.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Collected {
    /// The shards whose parts were read (N of `batch.part-I-of-N.csv`).
    pub shards: usize,
    /// Parts read.
    pub parts: usize,
    /// Rows written to `DIR/batch.csv`.
    pub rows: usize,
    /// Jobs of the batch with no row in any part (their shard did not finish).
    pub missing: Vec<String>,
    /// Jobs whose status is not `ok`, with it.
    pub failed: Vec<(String, String)>,
}

/// Read `DIR/batch.jobs.json` and every `DIR/batch.part-I-of-N.csv`, and write `DIR/batch.csv`
/// with one row per job that has one, in batch order.
pub fn collect(dir: &Path) -> Result<Collected, BatchError> {
    let list = dir.join(JOB_LIST);
    let text = std::fs::read_to_string(&list).map_err(|source| BatchError::Bad {
        path: list.clone(),
        problem: format!(
            "cannot read ({source}): give the --out folder of `linkage run … --shard I/N`"
        ),
    })?;
    let jobs: Vec<String> = serde_json::from_str(&text).map_err(|e| BatchError::Bad {
        path: list.clone(),
        problem: format!("not a job list ({e}): run a shard again to write it"),
    })?;
    let mut parts: Vec<(usize, usize, std::path::PathBuf)> = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(io_at(dir))?.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        if let Some((i, n)) = part_of(&name) {
            parts.push((i, n, entry.path()));
        }
    }
    parts.sort();
    let counts: Vec<usize> = {
        let mut c: Vec<usize> = parts.iter().map(|p| p.1).collect();
        c.dedup();
        c
    };
    if counts.len() > 1 {
        return Err(BatchError::Bad {
            path: dir.to_path_buf(),
            problem: format!(
                "holds table parts of {} shardings ({}): remove the parts of the older one",
                counts.len(),
                counts
                    .iter()
                    .map(|n| format!("batch.part-*-of-{n}.csv"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        });
    }
    let mut rows: Vec<Row> = Vec::new();
    for (_, _, path) in &parts {
        let text = std::fs::read_to_string(path).map_err(io_at(path))?;
        let part = parse_table(&text).map_err(|problem| BatchError::Bad {
            path: path.clone(),
            problem,
        })?;
        for row in part {
            if !jobs.contains(&row.job) {
                return Err(BatchError::Bad {
                    path: path.clone(),
                    problem: format!(
                        "job '{}' is not in {}: the part is from another batch; remove it",
                        row.job,
                        list.display()
                    ),
                });
            }
            if rows.iter().any(|r| r.job == row.job) {
                return Err(BatchError::Bad {
                    path: path.clone(),
                    problem: format!("job '{}' has a row in two parts", row.job),
                });
            }
            rows.push(row);
        }
    }
    rows.sort_by_key(|r| jobs.iter().position(|j| *j == r.job));
    let missing = jobs
        .iter()
        .filter(|j| !rows.iter().any(|r| r.job == **j))
        .cloned()
        .collect();
    let failed = rows
        .iter()
        .filter(|r| r.status != "ok")
        .map(|r| (r.job.clone(), r.status.clone()))
        .collect();
    write_table(&dir.join(TABLE), &rows)?;
    Ok(Collected {
        shards: counts.first().copied().unwrap_or(0),
        parts: parts.len(),
        rows: rows.len(),
        missing,
        failed,
    })
}
