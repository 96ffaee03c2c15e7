//! Issue 32, case 10 ("the contact module's rooms"): the settle loop's shared types live in
//! their own files (`body_part`, `problem`), so no contact module but `mod.rs` names the loop,
//! and the modules the loop drives (detection, evaluation, the report, self-contact, the
//! solvers) form no import circle with it or with each other.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Each module of `src/contact` (top-level files) and the sibling modules it imports.
fn contact_imports() -> BTreeMap<String, BTreeSet<String>> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/contact");
    let mut graph = BTreeMap::new();
    for entry in std::fs::read_dir(&dir).expect("src/contact is readable") {
        let path = entry.expect("a directory entry").path();
        let Some(name) = path.file_stem().and_then(|s| s.to_str()).map(str::to_owned) else {
            continue;
        };
        let text = if path.is_dir() {
            let mut all = String::new();
            for file in std::fs::read_dir(&path).expect("a module folder is readable") {
                let file = file.expect("a directory entry").path();
                if file.extension().is_some_and(|e| e == "rs") {
                    all += &std::fs::read_to_string(&file).expect("a source file is readable");
                }
            }
            all
        } else if path.extension().is_some_and(|e| e == "rs") {
            std::fs::read_to_string(&path).expect("a source file is readable")
        } else {
            continue;
        };
        let mut deps = BTreeSet::new();
        for prefix in ["crate::contact::", "super::"] {
            for (at, _) in text.match_indices(prefix) {
                let rest = &text[at + prefix.len()..];
                let module: String = rest
                    .chars()
                    .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                    .collect();
                if rest[module.len()..].starts_with("::") && module != name {
                    deps.insert(module);
                }
            }
        }
        graph.insert(name, deps);
    }
    graph
}

/// Whether `to` is reachable from `from` in `graph`.
fn reaches(graph: &BTreeMap<String, BTreeSet<String>>, from: &str, to: &str) -> bool {
    let mut seen = BTreeSet::new();
    let mut stack = vec![from.to_owned()];
    while let Some(m) = stack.pop() {
        for d in graph.get(&m).into_iter().flatten() {
            if d == to {
                return true;
            }
            if seen.insert(d.clone()) {
                stack.push(d.clone());
            }
        }
    }
    false
}

#[test]
fn only_the_module_root_names_the_settle_loop() {
    let graph = contact_imports();
    assert!(graph.contains_key("settle") && graph.contains_key("problem"));
    let naming: Vec<_> = graph
        .iter()
        .filter(|(m, deps)| *m != "mod" && deps.contains("settle"))
        .map(|(m, _)| m.clone())
        .collect();
    assert!(
        naming.is_empty(),
        "these modules import the settle loop: {naming:?}"
    );
}

#[test]
fn the_loop_and_the_modules_it_drives_form_no_import_circle() {
    let graph = contact_imports();
    let rooms = [
        "settle",
        "problem",
        "body_part",
        "detect",
        "evaluate",
        "report",
        "self_contact",
        "self_watch",
        "start",
        "coupled",
        "condensed",
        "increments",
    ];
    for m in rooms {
        assert!(graph.contains_key(m), "src/contact has no module {m}");
        assert!(
            !reaches(&graph, m, m),
            "{m} imports a module that imports it back (an import circle)"
        );
    }
}
