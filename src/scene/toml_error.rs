//! The message of a scene's TOML error: `toml`'s own (line, column, the line drawn, what is
//! wrong), with an unknown key inside a generator (`rectangle = { ..., cell = [..] }`) naming
//! that generator: "rectangle: unknown key `cell`, expected one of ...".

/// The keys whose table is a generator of a body's geometry (docs/SCENES.md, *Bodies*).
pub const GENERATORS: &[&str] = &[
    "disk",
    "rectangle",
    "cylindrical_shell",
    "box_lattice",
    "mesh",
    "outline",
];

/// The message of `error`, raised reading scene `text`: `toml`'s, trimmed, with an unknown key
/// of a generator table named by its generator (see [`enclosing_generator`]).
pub fn scene_toml_message(text: &str, error: &toml::de::Error) -> String {
    let message = error.to_string().trim_end().to_string();
    let Some(span) = error.span() else {
        return message;
    };
    let what = error.message().trim_end();
    let Some(rest) = what.strip_prefix("unknown field ") else {
        return message;
    };
    let Some(generator) = enclosing_generator(text, span.start) else {
        return message;
    };
    let named = format!("{generator}: unknown key {rest}");
    match message.rfind(what) {
        Some(k) => format!("{}{named}{}", &message[..k], &message[k + what.len()..]),
        None => format!("{message}\n{named}"),
    }
}

/// The generator whose table holds byte `at` of `text`: the key before the innermost `{` still
/// open at `at` (an inline table, `rectangle = { ... }`), else the last segment of the table
/// header above (`[bodies.rectangle]`); `None` when that is not one of [`GENERATORS`]. Strings
/// and comments are skipped.
pub fn enclosing_generator(text: &str, at: usize) -> Option<&'static str> {
    let before = text.get(..at)?;
    let mut opens: Vec<usize> = Vec::new();
    let mut header: Option<usize> = None;
    let (mut in_string, mut comment) = (false, false);
    let bytes = before.as_bytes();
    for (k, &c) in bytes.iter().enumerate() {
        match c {
            b'\n' => comment = false,
            _ if comment => {}
            b'"' => in_string = !in_string,
            _ if in_string => {}
            b'#' => comment = true,
            b'{' => opens.push(k),
            b'}' => {
                opens.pop();
            }
            b'[' if opens.is_empty() && (k == 0 || bytes[k - 1] == b'\n') => header = Some(k),
            _ => {}
        }
    }
    let key = match opens.last() {
        Some(&open) => {
            let head = before[..open].trim_end().strip_suffix('=')?.trim_end();
            let start = head
                .rfind(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .map_or(0, |k| k + 1);
            &head[start..]
        }
        None => {
            let line = before[header?..].lines().next()?;
            let name = line.trim_matches(|c| c == '[' || c == ']').trim();
            name.rsplit('.').next()?.trim()
        }
    };
    GENERATORS.iter().copied().find(|g| *g == key)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_key_inside_an_inline_generator_names_it_and_others_do_not() {
        let text = "[[bodies]]\nname = \"b\"\nbox_lattice = { size = [1.0, 1.0, 1.0], cell = [3, 3, 3] }\nmaterial = \"m\"\n";
        let at = text.find("cell").unwrap();
        assert_eq!(enclosing_generator(text, at), Some("box_lattice"));
        assert_eq!(
            enclosing_generator(text, text.find("material").unwrap()),
            None
        );
        let nested = "mesh = { file = \"a{b}.obj\", spasing = 0.1 } # {\n";
        let at = nested.find("spasing").unwrap();
        assert_eq!(enclosing_generator(nested, at), Some("mesh"));
        let header = "[[bodies]]\nname = \"b\"\n[bodies.disk]\nradius = 1.0\nring = 3\n";
        let at = header.find("ring").unwrap();
        assert_eq!(enclosing_generator(header, at), Some("disk"));
        let other = "[output]\nmagnificaton = 2.0\n";
        assert_eq!(
            enclosing_generator(other, other.find("magn").unwrap()),
            None
        );
    }
}
