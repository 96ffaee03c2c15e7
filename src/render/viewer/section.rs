//! The viewer's part of a scene's page: its canvas, controls, colour scale and note, then
//! three.js, the run's data and the viewer's script, all inline (ES module imports and
//! `fetch` from `file://` pages are blocked by CORS; classic inline scripts are not).

/// three.js r187's parts the viewer uses, a classic script defining `THREE`
/// (`third_party/three/README.md`).
const THREE_JS: &str = include_str!("../../../third_party/three/three.viewer.min.js");
/// The viewer (`viewer.js` beside this file).
const VIEWER_JS: &str = include_str!("viewer.js");

/// The style of the viewer's elements, added to the page's.
pub const VIEWER_STYLE: &str = "
.viewer { max-width: 1280px; }
.viewer canvas { border: 1px solid #ddd; display: block; touch-action: none; }
.viewer-controls { display: flex; flex-wrap: wrap; gap: 0.4em 1em; align-items: center; margin: 0.4em 0; }
.viewer-controls input[type=range] { width: 24em; }
.viewer-bar { height: 0.8em; width: 24em; border: 1px solid #ccc; }
.viewer-ticks { display: flex; justify-content: space-between; width: 24em; font-size: 0.85em; color: #555; }
";

/// The viewer's HTML for a run whose data is `data` ([`crate::render::viewer::viewer_data`]).
pub fn viewer_section(data: &str) -> String {
    format!(
        "<h2>3D view</h2>\n<div class=\"viewer\" id=\"viewer\">\n\
         <div id=\"viewer-canvas\"></div>\n<div class=\"viewer-controls\">\
         <button type=\"button\" id=\"viewer-play\">play</button>\
         <input type=\"range\" id=\"viewer-slider\" min=\"0\" max=\"0\" value=\"0\" aria-label=\"frame\">\
         <span id=\"viewer-label\"></span>\
         <label>colour <select id=\"viewer-colour\"><option value=\"stress\">member stress</option>\
         <option value=\"ratio\">stress ratio</option><option value=\"plain\">plain</option></select></label>\
         <label><input type=\"checkbox\" id=\"viewer-contacts\" checked> contact forces</label>\
         <label><input type=\"checkbox\" id=\"viewer-broken\" checked> broken members</label>\
         <label><input type=\"checkbox\" id=\"viewer-obstacles\" checked> obstacles</label></div>\n\
         <div id=\"viewer-scale\"></div>\n<p class=\"note\" id=\"viewer-note\">The 3D view needs \
         JavaScript and WebGL; the frames below show the run.</p>\n</div>\n\
         <script>{THREE_JS}</script>\n<script type=\"application/json\" id=\"viewer-data\">{data}</script>\n\
         <script>{VIEWER_JS}</script>\n"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_inline_scripts_cannot_end_early_and_import_nothing() {
        for (name, js) in [("three", THREE_JS), ("viewer", VIEWER_JS)] {
            assert!(!js.contains("</script"), "{name} holds </script");
            assert!(!js.contains("import("), "{name} imports a module");
        }
        assert!(
            THREE_JS.contains("var THREE="),
            "a classic script defining THREE"
        );
    }
}
