//! A job's key results as the report shows them: the batch table's row, with the sizes and
//! contact forces of its summary, formatted with units.

use crate::render::format_si;
use crate::render::report::html::escape;
use crate::render::report::job_files::JobFiles;
use crate::scene::batch::Row;
use std::path::Path;

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

/// `text` with the batch folder `batch` (as given and as an absolute path) left out of the
/// paths it names, so they read relative to the batch folder and stay right when it moves.
pub fn relative_to(text: &str, batch: &Path) -> String {
    let mut out = text.to_string();
    let mut prefixes: Vec<String> = Vec::new();
    if let Ok(c) = std::fs::canonicalize(batch) {
        prefixes.push(c.display().to_string());
    }
    if !batch.as_os_str().is_empty() {
        prefixes.push(batch.display().to_string());
    }
    if let Ok(cwd) = std::env::current_dir() {
        prefixes.push(cwd.join(batch).display().to_string());
    }
    // Longest first: a path is cut once, at its longest matching start.
    prefixes.sort_by_key(|p| std::cmp::Reverse(p.len()));
    prefixes.dedup();
    for p in prefixes {
        let p = p.trim_end_matches(std::path::MAIN_SEPARATOR);
        if p.is_empty() || p == "." {
            continue;
        }
        out = out.replace(&format!("{p}{}", std::path::MAIN_SEPARATOR), "");
    }
    out
}

/// `value` in `unit` as a reader reads it: an SI prefix and at most 3 significant digits,
/// without trailing zeros ("70 GPa", "1.5 mm", "250 N").
pub fn readable(value: f64, unit: &str) -> String {
    let text = format_si(value, unit);
    let Some((number, rest)) = text.split_once(' ') else {
        return text;
    };
    let number = if number.contains('.') {
        number.trim_end_matches('0').trim_end_matches('.')
    } else {
        number
    };
    format!("{number} {rest}")
}

/// A number with no unit as a reader reads it: an integer as it is ("3"), others with at
/// most 4 significant digits ("0.25", "1.5e-4", "7e10").
pub fn plain_number(value: f64) -> String {
    if value == value.round() && value.abs() < 1e9 {
        return format!("{value:.0}");
    }
    let digits = format!("{value:.3e}");
    let (mantissa, exponent) = digits.split_once('e').unwrap_or((&digits, "0"));
    let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
    let exponent: i32 = exponent.parse().unwrap_or(0);
    if (-3..6).contains(&exponent) {
        let v: f64 = format!("{mantissa}e{exponent}").parse().unwrap_or(value);
        format!("{v}")
    } else {
        format!("{mantissa}e{exponent}")
    }
}

/// The unit of a swept key, from its last segment (`materials."steel".youngs_modulus`: Pa);
/// `None` when it has none or is not known.
fn unit_of(key: &str) -> Option<&'static str> {
    let last = key.rsplit('.').next().unwrap_or(key).trim_matches('"');
    Some(match last {
        "youngs_modulus"
        | "strength"
        | "tensile_strength"
        | "compressive_strength"
        | "yield_stress"
        | "pressure"
        | "shear_modulus" => "Pa",
        "density" => "kg/m³",
        "area" => "m²",
        "radius" | "thickness" | "width" | "height" | "length" | "tolerance" => "m",
        "duration" | "time_step" | "dt" => "s",
        "penalty" => "N/m",
        "fracture_energy" => "J/m²",
        _ => return None,
    })
}

/// A swept value of `key` as a reader reads it: a number with its unit ("70 GPa", "1e-4 m²",
/// "20"), other text as it is. Not escaped.
pub fn swept_value(key: &str, value: &str) -> String {
    let Some(v) = number(value) else {
        return value.to_string();
    };
    match unit_of(key) {
        Some(unit @ ("Pa" | "m" | "s")) => readable(v, unit),
        Some(unit) => format!("{} {unit}", plain_number(v)),
        None => plain_number(v),
    }
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
            let one = row.steps.trim() == "1";
            time = format!(
                "{} step{}: {t:.3} s",
                escape(&row.steps),
                if one { "" } else { "s" }
            );
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
        let here = |text: &str| escape(&relative_to(text, &files.batch));
        let warnings = row
            .warnings
            .split("; ")
            .filter(|w| !w.is_empty())
            .map(here)
            .collect();
        let failure = summary
            .and_then(|s| s.failure.clone())
            .or_else(|| row.status.strip_prefix("failed: ").map(str::to_string))
            .map(|f| here(&f));
        // The reason is said once, under warnings and failures: the status is its first word.
        let status = if kind == "failed" && failure.is_some() {
            "failed".to_string()
        } else {
            here(&row.status)
        };
        Facts {
            kind,
            status,
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn swept_values_read_as_numbers_with_units() {
        let e = "materials.\"steel\".youngs_modulus";
        assert_eq!(swept_value(e, "70000000000.0"), "70 GPa");
        assert_eq!(swept_value(e, "2.1e11"), "210 GPa");
        assert_eq!(swept_value("materials.\"s\".area", "0.0001"), "1e-4 m²");
        assert_eq!(swept_value("materials.\"s\".area", "0.25"), "0.25 m²");
        assert_eq!(swept_value("bodies.\"b\".disk.radius", "0.0015"), "1.5 mm");
        assert_eq!(swept_value("steps", "20"), "20");
        assert_eq!(swept_value("contact.friction", "0.300000"), "0.3");
        assert_eq!(swept_value("output.colour", "plain"), "plain");
        assert_eq!(plain_number(123456.0), "123456");
        assert_eq!(plain_number(7e10), "7e10");
        assert_eq!(plain_number(1.23456e-7), "1.235e-7");
        assert_eq!(readable(250.0, "N"), "250 N");
        assert_eq!(readable(4.0e6, "Pa"), "4 MPa");
    }

    #[test]
    fn paths_under_the_batch_folder_read_relative_to_it() {
        let batch = Path::new("/data/runs/sweep");
        let text = "/data/runs/sweep/beam/2.failed/steps/0003.json: cannot write";
        assert_eq!(
            relative_to(text, batch),
            "beam/2.failed/steps/0003.json: cannot write"
        );
        // Other paths stay as they are.
        assert_eq!(relative_to("/data/other/x", batch), "/data/other/x");
    }

    #[test]
    fn one_step_is_one_step_and_a_failure_is_said_once() {
        let row = Row {
            job: "beam/2".into(),
            scene: "beam".into(),
            status: "failed: /data/runs/beam/2.failed/x.json: no room".into(),
            steps: "1".into(),
            seconds: "0.5".into(),
            ..Row::default()
        };
        let files = JobFiles {
            batch: Path::new("/data/runs").to_path_buf(),
            ..JobFiles::default()
        };
        let f = Facts::of(&row, &files);
        assert_eq!(f.status, "failed");
        assert_eq!(f.failure.as_deref(), Some("beam/2.failed/x.json: no room"));
        assert!(f.time.starts_with("1 step: "), "{}", f.time);
    }
}
