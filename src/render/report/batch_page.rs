//! `DIR/index.html`: one row per job of the batch with its status, sizes, time, key results,
//! plots and animation, each linked to its own page.

use crate::render::report::facts::{swept_value, Facts};
use crate::render::report::html::{escape, link, page};
use crate::render::report::job_files::JobFiles;
use crate::scene::batch::Row;

/// The batch page of `rows` (in batch order) with what each job left on disk, and `after`
/// (HTML: the sweep plots) below the table.
pub fn batch_page(title: &str, jobs: &[(&Row, JobFiles)], after: &str) -> String {
    let mut body = format!(
        "<h1>{}</h1>\n<p class=\"note\">{} job{} of the batch; the table's numbers are in \
         <a href=\"batch.csv\">batch.csv</a>. Each scene's name opens its page with every \
         frame.</p>\n",
        escape(title),
        jobs.len(),
        if jobs.len() == 1 { "" } else { "s" },
    );
    body.push_str(
        "<table>\n<thead><tr><th>scene</th><th>status</th><th>size</th><th>time</th>\
         <th>key results</th><th>warnings and failures</th><th>plots</th>\
         <th>animation</th></tr></thead>\n<tbody>\n",
    );
    for (row, files) in jobs {
        body.push_str(&job_row(row, files));
    }
    body.push_str("</tbody>\n</table>\n");
    body.push_str(after);
    page(title, &body)
}

fn job_row(row: &Row, files: &JobFiles) -> String {
    let f = Facts::of(row, files);
    let has_page = !files.folder.is_empty();
    let mut name = escape(&row.job);
    if !row.values.is_empty() {
        let values: Vec<String> = row
            .values
            .iter()
            .map(|(k, v)| format!("{} = {}", escape(k), escape(&swept_value(k, v))))
            .collect();
        name.push_str(&format!("<br><small>{}</small>", values.join("<br>")));
    }
    let scene = if has_page {
        format!(
            "<a href=\"{}\">{name}</a>",
            link(&files.batch_path(&["index.html"]))
        )
    } else {
        name
    };
    let mut notes: Vec<String> = f
        .warnings
        .iter()
        .map(|w| format!("<li class=\"warn\">{w}</li>"))
        .collect();
    if let Some(why) = &f.failure {
        notes.push(format!("<li class=\"fail\">{why}</li>"));
    }
    let plots: Vec<String> = files
        .plots
        .iter()
        .map(|p| {
            let png = format!("{p}.png");
            let src = link(&files.batch_path(&["plots", &png]));
            format!(
                "<a href=\"{src}\"><img class=\"thumb\" src=\"{src}\" alt=\"{}\"></a>",
                escape(p)
            )
        })
        .collect();
    let anim = if files.gif {
        format!(
            "<a href=\"{}\"><img class=\"anim\" src=\"{}\" alt=\"animation of {}\"></a>",
            link(&files.batch_path(&["index.html"])),
            link(&files.batch_path(&["anim.gif"])),
            escape(&row.job)
        )
    } else {
        String::new()
    };
    let mut results = Vec::new();
    for (what, value) in [
        ("largest displacement", &f.displacement),
        ("peak stress", &f.stress),
        ("members", &f.members),
    ] {
        if !value.is_empty() {
            results.push(format!("<li>{what}: {value}</li>"));
        }
    }
    results.extend(f.contact.iter().map(|c| format!("<li>contact: {c}</li>")));
    format!(
        "<tr class=\"{}\" data-job=\"{}\"><td>{scene}</td><td class=\"status\">{}</td>\
         <td class=\"size\">{}</td><td>{}</td><td class=\"results\"><ul class=\"plain\">{}</ul></td>\
         <td><ul class=\"plain\">{}</ul></td><td class=\"plots\">{}</td><td>{anim}</td></tr>\n",
        f.kind,
        escape(&row.job),
        f.status,
        f.size,
        f.time,
        results.join(""),
        notes.join(""),
        plots.join(""),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_values_and_messages_are_escaped_and_a_job_without_results_has_no_link() {
        let row = Row {
            job: "a<b>&c".into(),
            scene: "a<b>&c".into(),
            values: vec![("materials.\"x\".area".into(), "<1e-4>".into())],
            status: "failed: <script>alert(1)</script>".into(),
            warnings: "deep & <wide>".into(),
            ..Row::default()
        };
        let html = batch_page("batch <1>", &[(&row, JobFiles::default())], "");
        for raw in ["a<b>", "<script>", "<1e-4>", "<wide>", "batch <1>"] {
            assert!(!html.contains(raw), "{raw} unescaped in {html}");
        }
        assert!(html.contains("data-job=\"a&lt;b&gt;&amp;c\""));
        assert!(html.contains("&lt;script&gt;alert(1)&lt;/script&gt;"));
        assert!(html.contains("deep &amp; &lt;wide&gt;"));
        // No results folder: no link to a page that does not exist, no images.
        assert!(!html.contains("index.html\"") && !html.contains("<img"));
    }
}
