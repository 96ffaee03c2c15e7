//! A job's key results as the report shows them: the batch table's row, with the sizes and
//! contact forces of its summary, formatted with units.

use crate::render::format_si;
use crate::render::report::html::escape;
use crate::render::report::job_files::JobFiles;
use crate::scene::batch::Row;

/// One job's facts, each already HTML (escaped).
#[derive(Clone, Debug, Default)]
pub struct Facts {
    /// `ok`, `failed` or `collapsed`: the row's class.
    pub kind: &'static str,
    /// The status as the table says it.
    pub status: String,
    /// Nodes, members and DOFs (all and free), one per line.
    pub size: String,
    /// Steps solved and their wall time; the drawing time.
    pub time: String,
    /// The largest displacement at the last step.
    pub displacement: String,
    /// The peak member stress and its ratio to strength.
    pub stress: String,
    /// Overloaded and broken members.
    pub members: String,
    /// The total contact force of each pair at the last step, one per line.
    pub contact: Vec<String>,
    /// Warnings, one per line.
    pub warnings: Vec<String>,
    /// Why the run stopped, when it did.
    pub failure: Option<String>,
}

fn number(cell: &str) -> Option<f64> {
    cell.trim().parse::<f64>().ok().filter(|v| v.is_finite())
}

impl Facts {
    /// The facts of `row` and what its `files` hold.
    pub fn of(row: &Row, files: &JobFiles) -> Facts {
        let kind = if row.status == "ok" {
            "ok"
        } else if row.status.starts_with("collapsed") {
            "collapsed"
        } else {
            "failed"
        };
        let summary = files.summary.as_ref();
        let dofs = summary.map(|s| {
            let all: usize = s.bodies.iter().map(|b| b.nodes * b.dimension).sum();
            let free: usize = s.bodies.iter().map(|b| b.free_dofs).sum();
            format!("{all} DOFs ({free} free)")
        });
        let size = if row.nodes.is_empty() {
            String::new()
        } else {
            let mut s = format!(
                "{} nodes<br>{} members",
                escape(&row.nodes),
                escape(&row.members)
            );
            if let Some(d) = dofs {
                s.push_str("<br>");
                s.push_str(&escape(&d));
            }
            s
        };
        let mut time = String::new();
        if let Some(t) = number(&row.seconds) {
            time = format!("{} steps: {t:.3} s", escape(&row.steps));
        }
        if let Some(d) = summary.map(|s| s.phases.drawing).filter(|d| *d > 0.0) {
            time.push_str(&format!("<br>drawing: {d:.3} s"));
        }
        let displacement = number(&row.max_displacement)
            .map(|u| format_si(u, "m"))
            .unwrap_or_default();
        let mut stress = number(&row.peak_stress)
            .map(|s| format_si(s, "Pa"))
            .unwrap_or_default();
        if let Some(r) = number(&row.stress_ratio) {
            stress.push_str(&format!(" ({:.0}% of strength)", 100.0 * r));
        }
        let mut members = String::new();
        if !row.overloaded.is_empty() {
            members = format!("{} overloaded", row.overloaded);
        }
        if !row.broken.is_empty() {
            members.push_str(&format!(", {} broken", row.broken));
        }
        if let Some(s) = summary {
            // A collapse's breaks come after the last stored step: say them all. A softening
            // member's teeth are not breaks.
            let teeth = s.breaks.iter().filter(|b| b.tooth.is_some()).count();
            let broke = s.breaks.len() - teeth;
            if broke > 0 {
                members.push_str(&format!(" ({broke} broke in all)"));
            }
            if teeth > 0 {
                members.push_str(&format!(", {teeth} softening teeth passed"));
            }
        }
        let contact = summary
            .and_then(|s| s.steps.last())
            .map(|last| {
                last.contact_forces
                    .iter()
                    .map(|p| {
                        let f = p.force.iter().map(|c| c * c).sum::<f64>().sqrt();
                        escape(&format!(
                            "{} from {}: {}",
                            p.body,
                            p.with,
                            format_si(f, "N")
                        ))
                    })
                    .collect()
            })
            .unwrap_or_default();
        let warnings = row
            .warnings
            .split("; ")
            .filter(|w| !w.is_empty())
            .map(escape)
            .collect();
        let failure = summary
            .and_then(|s| s.failure.clone())
            .or_else(|| row.status.strip_prefix("failed: ").map(str::to_string))
            .map(|f| escape(&f));
        Facts {
            kind,
            status: escape(&row.status),
            size,
            time,
            displacement: escape(&displacement),
            stress: escape(&stress),
            members: escape(&members),
            contact,
            warnings,
            failure,
        }
    }
}
