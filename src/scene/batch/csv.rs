//! The CSV of `batch.csv` (RFC 4180: fields with a comma, quote or line break are quoted, quotes
//! doubled), written and read back.

/// One field as CSV.
pub fn field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// One record as a CSV line (with its `\n`).
pub fn record<S: AsRef<str>>(fields: &[S]) -> String {
    let mut line = fields
        .iter()
        .map(|f| field(f.as_ref()))
        .collect::<Vec<_>>()
        .join(",");
    line.push('\n');
    line
}

/// The records of CSV `text`; `Err` names the 1-based line of an unclosed quote.
pub fn records(text: &str) -> Result<Vec<Vec<String>>, String> {
    let mut out = Vec::new();
    let mut fields = Vec::new();
    let mut field = String::new();
    let mut quoted = false;
    let mut line = 1;
    let mut start_line = 1;
    let mut chars = text.chars().peekable();
    let mut any = false;
    while let Some(c) = chars.next() {
        any = true;
        if quoted {
            match c {
                '"' if chars.peek() == Some(&'"') => {
                    chars.next();
                    field.push('"');
                }
                '"' => quoted = false,
                c => {
                    if c == '\n' {
                        line += 1;
                    }
                    field.push(c);
                }
            }
            continue;
        }
        match c {
            '"' => {
                quoted = true;
                start_line = line;
            }
            ',' => fields.push(std::mem::take(&mut field)),
            '\r' => {}
            '\n' => {
                line += 1;
                fields.push(std::mem::take(&mut field));
                out.push(std::mem::take(&mut fields));
                any = false;
            }
            c => field.push(c),
        }
    }
    if quoted {
        return Err(format!("line {start_line}: a quoted field is not closed"));
    }
    if any {
        fields.push(field);
        out.push(fields);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_with_commas_quotes_and_line_breaks_come_back_as_written() {
        let rows = vec![
            vec![
                "a".to_string(),
                "[0.0, -1000.0]".into(),
                "say \"hi\"".into(),
            ],
            vec!["two\nlines".into(), String::new(), "x".into()],
        ];
        let text: String = rows.iter().map(|r| record(r)).collect();
        assert_eq!(
            text,
            "a,\"[0.0, -1000.0]\",\"say \"\"hi\"\"\"\n\"two\nlines\",,x\n"
        );
        assert_eq!(records(&text).unwrap(), rows);
        assert!(records("a,\"b\nc").unwrap_err().contains("line 1"));
    }
}
