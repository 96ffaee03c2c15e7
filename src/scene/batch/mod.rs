//! Batches: the jobs of a `linkage run` (scenes and sweep variants), their table `batch.csv`, shards of them, resumed runs, `linkage collect` and Slurm job arrays.

pub use self::collect::{collect, Collected};
pub use self::error::BatchError;
pub use self::jobs::{plan_jobs, write_job_list, write_variant_lists, Job, JOB_LIST};
pub use self::row::{complete_summary, job_row};
pub use self::run_job::{run_job, JobSettings, Ran};
pub use self::shard::{Shard, ARRAY_VARIABLES};
pub use self::slurm::{write_slurm, SlurmOptions, SlurmPlan};
pub use self::table::{parse_table, table_csv, write_table, Row, TABLE};

mod collect;
pub(crate) mod csv;
mod error;
mod jobs;
mod row;
mod run_job;
mod shard;
mod slurm;
mod table;
