//! `DIR/<job>/index.html`: one job's key results, its plots (with their SVG and data) and
//! every frame.

use crate::render::report::facts::{swept_value, Facts};
use crate::render::report::html::{escape, link, page};
use crate::render::report::job_files::JobFiles;
use crate::scene::batch::Row;

/// The page of the job of `row`, in its results folder (`files.folder`), with `viewer` (the
/// HTML of its 3D view, [`crate::render::viewer::viewer_section`], or a note why there is
/// none) after its facts.
pub fn scene_page(row: &Row, files: &JobFiles, viewer: &str) -> String {
    let f = Facts::of(row, files);
    let up: Vec<&str> = files.folder.iter().map(|_| "..").collect();
    let mut back = up.clone();
    back.push("index.html");
    let mut body = format!(
        "<p><a href=\"{}\">&larr; the batch</a></p>\n<h1>{}</h1>\n",
        link(&back),
        escape(&row.job)
    );
    let mut facts = vec![(
        "status",
        format!("<span class=\"{}\">{}</span>", f.kind, f.status),
    )];
    for (k, v) in &row.values {
        facts.push((
            "swept",
            format!("{} = {}", escape(k), escape(&swept_value(k, v))),
        ));
    }
    facts.extend([
        ("size", f.size.clone()),
        ("time", f.time.clone()),
        ("largest displacement", f.displacement.clone()),
        ("peak stress", f.stress.clone()),
        ("members", f.members.clone()),
        ("contact forces", f.contact.join("<br>")),
    ]);
    for w in &f.warnings {
        facts.push(("warning", format!("<span class=\"warn\">{w}</span>")));
    }
    if let Some(why) = &f.failure {
        facts.push(("failure", format!("<span class=\"fail\">{why}</span>")));
    }
    body.push_str("<dl class=\"facts\">\n");
    for (k, v) in facts.iter().filter(|(_, v)| !v.is_empty()) {
        body.push_str(&format!("<dt>{k}</dt><dd>{v}</dd>\n"));
    }
    body.push_str(
        "</dl>\n<p class=\"note\">Results: <a href=\"summary.json\">summary.json</a>, \
         <code>steps/</code>.</p>\n",
    );
    body.push_str(viewer);
    if !files.plots.is_empty() {
        body.push_str("<h2>Plots</h2>\n");
        for p in &files.plots {
            let png = link(&["plots", &format!("{p}.png")]);
            body.push_str(&format!(
                "<figure class=\"plot\"><img src=\"{png}\" alt=\"{0}\"><figcaption>{0}: \
                 <a href=\"{1}\">SVG</a>, <a href=\"{2}\">data (CSV)</a></figcaption></figure>\n",
                escape(p),
                link(&["plots", &format!("{p}.svg")]),
                link(&["plots", &format!("{p}.csv")]),
            ));
        }
    }
    if files.gif {
        body.push_str(&format!(
            "<h2>Animation</h2>\n<figure class=\"frame\"><img src=\"{}\" alt=\"animation\"></figure>\n",
            link(&["anim.gif"])
        ));
    }
    if !files.frames.is_empty() {
        body.push_str(&format!("<h2>Frames ({})</h2>\n", files.frames.len()));
        for name in &files.frames {
            let step = name
                .trim_end_matches(".png")
                .trim_start_matches('0')
                .to_string();
            let step = if step.is_empty() { "0".into() } else { step };
            body.push_str(&format!(
                "<figure class=\"frame\"><img src=\"{}\" alt=\"step {step}\"><figcaption>step {step}</figcaption></figure>\n",
                link(&["png", name]),
            ));
        }
    }
    page(&row.job, &body)
}
