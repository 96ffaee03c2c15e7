//! The pieces every report page shares: escaping text and links, the page shell and its style.

use crate::render::viewer::VIEWER_STYLE;

/// `text` with the characters HTML gives a meaning to replaced by their entities, safe in
/// element content and in quoted attributes.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// A relative link to the file at `segments` (folder names, then the file), each
/// percent-encoded (all but letters, digits and `-._~`), and escaped for an attribute.
pub fn link(segments: &[&str]) -> String {
    let mut out = String::new();
    for (k, s) in segments.iter().enumerate() {
        if k > 0 {
            out.push('/');
        }
        if *s == ".." {
            out.push_str("..");
            continue;
        }
        for b in s.bytes() {
            if b.is_ascii_alphanumeric() || b"-._~".contains(&b) {
                out.push(b as char);
            } else {
                out.push_str(&format!("%{b:02X}"));
            }
        }
    }
    escape(&out)
}

/// The style of every page: plain, readable, printable; no fonts or files from elsewhere.
const STYLE: &str = "
body { font-family: system-ui, 'DejaVu Sans', Arial, sans-serif; margin: 1.5em; color: #222; }
h1 { font-size: 1.5em; margin-bottom: 0.2em; }
h2 { font-size: 1.2em; margin-top: 1.5em; }
p.note { color: #555; margin-top: 0; }
table { border-collapse: collapse; width: 100%; }
th, td { border: 1px solid #ccc; padding: 0.35em 0.55em; vertical-align: top; text-align: left; overflow-wrap: anywhere; }
th { background: #f1f3f5; position: sticky; top: 0; }
td.num { text-align: right; white-space: nowrap; font-variant-numeric: tabular-nums; }
tr.ok td.status { color: #1b6e2a; font-weight: 600; }
tr.failed td.status { color: #b00020; font-weight: 600; }
tr.collapsed td.status { color: #a15c00; font-weight: 600; }
ul.plain { list-style: none; padding: 0; margin: 0; }
.warn { color: #a15c00; }
.fail { color: #b00020; }
td.plots { max-width: 340px; }
td.size { white-space: nowrap; }
td.results { min-width: 12em; }
img.thumb { width: 160px; max-width: 100%; height: auto; border: 1px solid #ddd; margin: 1px; }
img.anim { width: 220px; max-width: 100%; height: auto; border: 1px solid #ddd; }
td.status { max-width: 16em; }
figure { display: inline-block; margin: 0.4em; vertical-align: top; }
figure img { max-width: 100%; height: auto; border: 1px solid #ddd; }
figure.plot img { width: 640px; }
figure.frame img { width: 480px; }
figcaption { font-size: 0.9em; color: #555; }
dl.facts { display: grid; grid-template-columns: max-content auto; gap: 0.2em 1em; }
dl.facts dt { font-weight: 600; }
dl.facts dd { margin: 0; }
";

/// A complete page titled `title` around `body`.
pub fn page(title: &str, body: &str) -> String {
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>{}</title>\n<style>{STYLE}{VIEWER_STYLE}</style>\n</head>\n<body>\n{body}</body>\n</html>\n",
        escape(title)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_escaped_and_links_encoded() {
        assert_eq!(
            escape("<b>\"a\" & 'b'</b>"),
            "&lt;b&gt;&quot;a&quot; &amp; &#39;b&#39;&lt;/b&gt;"
        );
        assert_eq!(link(&["a b", "x&y.png"]), "a%20b/x%26y.png");
        assert_eq!(link(&["..", "index.html"]), "../index.html");
    }
}
