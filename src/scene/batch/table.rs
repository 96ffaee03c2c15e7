//! `batch.csv`: one row per scene or sweep variant with its key results (see the README).

use crate::scene::atomic_file::write_atomically;
use crate::scene::batch::csv::{record, records};
use crate::scene::batch::error::{io_at, BatchError};
use std::path::Path;

/// The batch table's file name in `DIR`.
pub const TABLE: &str = "batch.csv";

/// The prefix of the per-pair contact force columns: `contact_force.<body>.<with>.<x|y|z>`.
const CONTACT: &str = "contact_force.";

/// One row of `batch.csv`, every cell as written (empty: no value).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Row {
    /// `<scene>` or `<scene>/<k>` for variant k of a sweep: the results folder under `DIR`.
    pub job: String,
    /// The scene's name.
    pub scene: String,
    /// k (1-based) for a sweep's variant, else empty.
    pub variant: String,
    /// Each swept key (dotted path) with this variant's value.
    pub values: Vec<(String, String)>,
    /// `ok` or `failed: <why>`.
    pub status: String,
    /// Nodes, all bodies.
    pub nodes: String,
    /// Members, all bodies.
    pub members: String,
    /// Load steps solved.
    pub steps: String,
    /// Wall time of the solved steps, s (summary.json's per-step `seconds`, summed).
    pub seconds: String,
    /// Largest node displacement at the last step, m.
    pub max_displacement: String,
    /// The member stress of largest magnitude at the last stored step, Pa (tension positive).
    pub peak_stress: String,
    /// Largest |stress| / strength over the members whose material has a strength in that
    /// sense (empty without strengths).
    pub stress_ratio: String,
    /// Overloaded members at the last step.
    pub overloaded: String,
    /// Broken members at the last step (empty until members can break).
    pub broken: String,
    /// Total contact force per pair at the last step: (`contact_force.<body>.<with>.<x|y|z>`, N).
    pub contact: Vec<(String, String)>,
    /// A dynamic scene's [`DYNAMIC`] columns (name, value): `duration` (s, the simulated time
    /// reached), `peak_contact_force` (N, the largest magnitude of a pair's total contact force over
    /// the stored states, 0 without contact) and `final_kinetic_energy` (J); empty for a static scene.
    pub dynamics: Vec<(String, String)>,
    /// Largest relative residual over the steps.
    pub residual: String,
    /// Every warning of the run, `; `-separated.
    pub warnings: String,
}

const HEAD: [&str; 3] = ["job", "scene", "variant"];
const MIDDLE: [&str; 11] = [
    "status",
    "nodes",
    "members",
    "steps",
    "seconds",
    "max_displacement",
    "peak_stress",
    "stress_ratio",
    "overloaded",
    "broken",
    "residual",
];
const TAIL: [&str; 1] = ["warnings"];
/// The columns of a dynamic scene, after the contact pairs; in the table only when a row has
/// them.
pub(crate) const DYNAMIC: [&str; 3] = ["duration", "peak_contact_force", "final_kinetic_energy"];

impl Row {
    fn fixed(&self) -> [&String; 15] {
        [
            &self.job,
            &self.scene,
            &self.variant,
            &self.status,
            &self.nodes,
            &self.members,
            &self.steps,
            &self.seconds,
            &self.max_displacement,
            &self.peak_stress,
            &self.stress_ratio,
            &self.overloaded,
            &self.broken,
            &self.residual,
            &self.warnings,
        ]
    }

    fn fixed_mut(&mut self) -> [&mut String; 15] {
        [
            &mut self.job,
            &mut self.scene,
            &mut self.variant,
            &mut self.status,
            &mut self.nodes,
            &mut self.members,
            &mut self.steps,
            &mut self.seconds,
            &mut self.max_displacement,
            &mut self.peak_stress,
            &mut self.stress_ratio,
            &mut self.overloaded,
            &mut self.broken,
            &mut self.residual,
            &mut self.warnings,
        ]
    }
}

/// Names in first-appearance order over `lists`.
fn union<'a>(lists: impl Iterator<Item = &'a Vec<(String, String)>>) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for list in lists {
        for (name, _) in list {
            if !names.contains(name) {
                names.push(name.clone());
            }
        }
    }
    names
}

fn cell<'a>(list: &'a [(String, String)], name: &str) -> &'a str {
    list.iter()
        .find(|(n, _)| n == name)
        .map_or("", |(_, v)| v.as_str())
}

/// The table of `rows`, in their order: the fixed columns, the swept keys after `variant`,
/// the contact pairs after `broken` and then a dynamic scene's [`DYNAMIC`] columns, each in
/// order of first appearance.
pub fn table_csv(rows: &[Row]) -> String {
    let swept = union(rows.iter().map(|r| &r.values));
    let pairs = union(rows.iter().map(|r| &r.contact));
    let dynamic = union(rows.iter().map(|r| &r.dynamics));
    let mut header: Vec<String> = HEAD.iter().map(|s| s.to_string()).collect();
    header.extend(swept.iter().cloned());
    header.extend(MIDDLE[..10].iter().map(|s| s.to_string()));
    header.extend(pairs.iter().cloned());
    header.extend(dynamic.iter().cloned());
    header.push(MIDDLE[10].to_string());
    header.extend(TAIL.iter().map(|s| s.to_string()));
    let mut text = record(&header);
    for r in rows {
        let f = r.fixed();
        let mut line: Vec<&str> = f[..3].iter().map(|s| s.as_str()).collect();
        line.extend(swept.iter().map(|k| cell(&r.values, k)));
        line.extend(f[3..13].iter().map(|s| s.as_str()));
        line.extend(pairs.iter().map(|k| cell(&r.contact, k)));
        line.extend(dynamic.iter().map(|k| cell(&r.dynamics, k)));
        line.extend(f[13..].iter().map(|s| s.as_str()));
        text.push_str(&record(&line));
    }
    text
}

/// Write [`table_csv`] of `rows` to `path`, atomically.
pub fn write_table(path: &Path, rows: &[Row]) -> Result<(), BatchError> {
    write_atomically(path, table_csv(rows).as_bytes()).map_err(io_at(path))
}

/// The rows of a table written by [`table_csv`] (empty cells of swept and contact columns are
/// left out, as [`table_csv`] writes a missing one).
pub fn parse_table(text: &str) -> Result<Vec<Row>, String> {
    let mut records = records(text)?.into_iter();
    let header = records.next().ok_or("empty: no header line")?;
    let fixed: Vec<&str> = HEAD.iter().chain(&MIDDLE).chain(&TAIL).copied().collect();
    for name in &fixed {
        if !header.iter().any(|h| h == name) {
            return Err(format!(
                "no column `{name}`: not a table `linkage run` wrote"
            ));
        }
    }
    let mut rows = Vec::new();
    for (i, fields) in records.enumerate() {
        if fields.len() != header.len() {
            return Err(format!(
                "row {}: {} fields, the header has {}",
                i + 1,
                fields.len(),
                header.len()
            ));
        }
        let mut row = Row::default();
        for (name, value) in header.iter().zip(fields) {
            if let Some(k) = fixed.iter().position(|f| f == name) {
                // `fixed` lists HEAD, MIDDLE, TAIL; `fixed_mut` has residual before warnings.
                *row.fixed_mut()[k] = value;
            } else if value.is_empty() {
                continue;
            } else if name.starts_with(CONTACT) {
                row.contact.push((name.clone(), value));
            } else if DYNAMIC.contains(&name.as_str()) {
                row.dynamics.push((name.clone(), value));
            } else {
                row.values.push((name.clone(), value));
            }
        }
        rows.push(row);
    }
    Ok(rows)
}

/// The contact column of `body` touching `with`, component `axis` (0, 1, 2).
pub(crate) fn contact_column(body: &str, with: &str, axis: usize) -> String {
    format!("{CONTACT}{body}.{with}.{}", ["x", "y", "z"][axis.min(2)])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_table_reads_back_as_the_rows_it_was_written_from() {
        let a = Row {
            job: "beam/1".into(),
            scene: "beam".into(),
            variant: "1".into(),
            values: vec![("loads.1.force".into(), "[0.0, -1000.0]".into())],
            status: "ok".into(),
            nodes: "4".into(),
            contact: vec![(contact_column("beam", "floor", 1), "-2.5".into())],
            warnings: "deep, very".into(),
            ..Row::default()
        };
        let b = Row {
            job: "other".into(),
            status: "failed: no, really".into(),
            residual: "1e-12".into(),
            ..Row::default()
        };
        let text = table_csv(&[a.clone(), b.clone()]);
        assert!(text.starts_with("job,scene,variant,loads.1.force,status,nodes,members,steps,seconds,max_displacement,peak_stress,stress_ratio,overloaded,broken,contact_force.beam.floor.y,residual,warnings\n"));
        assert_eq!(parse_table(&text).unwrap(), vec![a, b]);
    }
}
