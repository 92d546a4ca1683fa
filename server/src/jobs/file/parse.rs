//! Reading a job file: JSON or TOML text into a [`JobFile`], refusing what would be costly or
//! unstorable before the parse (deep nesting, TOML's `nan` and `inf`), with errors that point at
//! the line and the field.

use kerf_solver::ErrorCode;

use super::check::check;
use super::{JobFile, MAX_NESTING};
use crate::error::{AppError, AppResult};

/// The two file formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// JSON.
    Json,
    /// TOML.
    Toml,
}

impl Format {
    /// The format a file name or media type says, else a guess from the first character.
    pub fn detect(name: Option<&str>, media_type: Option<&str>, text: &str) -> Self {
        let by_name = name.map(str::to_ascii_lowercase);
        if by_name.as_deref().is_some_and(|n| n.ends_with(".toml")) || media_type.is_some_and(|m| m.contains("toml")) {
            return Self::Toml;
        }
        if by_name.as_deref().is_some_and(|n| n.ends_with(".json")) || media_type.is_some_and(|m| m.contains("json")) {
            return Self::Json;
        }
        if text.trim_start().starts_with('{') { Self::Json } else { Self::Toml }
    }
}

/// 1-based line and column of byte `offset` in `text`.
fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

pub(super) fn file_error(path: &str, line: Option<(usize, usize)>, message: &str) -> AppError {
    let field = if path.is_empty() || path == "." || path == "?" { "file".to_owned() } else { path.to_owned() };
    let place = line.map(|(l, c)| format!("line {l}, column {c}: ")).unwrap_or_default();
    AppError::bad_request(ErrorCode::JobFile, field.clone(), format!("{place}{field}: {message}"))
}

/// Deepest bracket nesting, ignoring brackets inside strings (TOML's four kinds: basic and literal,
/// single-line and multi-line; JSON's are the basic kind) and inside TOML comments: a cheap guard
/// before parsing.
fn nesting(text: &str) -> usize {
    let (mut depth, mut deepest) = (0_usize, 0_usize);
    let mut rest = text;
    while let Some(c) = rest.chars().next() {
        let after = &rest[c.len_utf8()..];
        rest = match c {
            '#' => after.find('\n').map_or("", |end| &after[end..]),
            '"' | '\'' => {
                let triple = if c == '"' { "\"\"\"" } else { "\'\'\'" };
                if rest.starts_with(triple) {
                    string_end(&rest[3..], triple, c == '"')
                } else {
                    string_end(after, &rest[..1], c == '"')
                }
            }
            '[' | '{' => {
                depth += 1;
                deepest = deepest.max(depth);
                after
            }
            ']' | '}' => {
                depth = depth.saturating_sub(1);
                after
            }
            _ => after,
        };
    }
    deepest
}

/// What follows the string whose text starts `text` and ends with `quote` (a backslash escapes
/// the next character in basic strings). An unterminated string runs to the end.
fn string_end<'a>(text: &'a str, quote: &str, escapes: bool) -> &'a str {
    let mut index = 0;
    while index < text.len() {
        let rest = &text[index..];
        if escapes && rest.starts_with('\\') {
            index += 1 + rest[1..].chars().next().map_or(0, char::len_utf8);
        } else if rest.starts_with(quote) {
            // A multi-line string may end in up to two more quotes that belong to its text.
            let mut end = index + quote.len();
            while quote.len() == 3 && text[end..].starts_with(&quote[..1]) && end < index + 5 {
                end += 1;
            }
            return &text[end..];
        } else {
            index += rest.chars().next().map_or(1, char::len_utf8);
        }
    }
    ""
}

/// TOML has `nan` and `inf`, which no request accepts and JSON (the stored job) cannot hold:
/// the first one is refused with its line and field before anything else. Syntax errors are left
/// to the parse that follows.
fn reject_non_finite(text: &str) -> AppResult<()> {
    use toml::de::{DeTable, DeValue};

    fn walk(value: &toml::Spanned<DeValue<'_>>, path: String, first: &mut Option<(usize, String, String)>) {
        match value.get_ref() {
            DeValue::Float(float) => {
                let number: f64 = float.as_str().replace('_', "").parse().unwrap_or(f64::NAN);
                let start = value.span().start;
                if !number.is_finite() && first.as_ref().is_none_or(|(at, _, _)| start < *at) {
                    *first = Some((start, path, float.as_str().to_owned()));
                }
            }
            DeValue::Array(items) => {
                for (index, item) in items.iter().enumerate() {
                    walk(item, format!("{path}[{index}]"), first);
                }
            }
            DeValue::Table(table) => {
                for (key, item) in table {
                    let key = key.get_ref();
                    walk(item, if path.is_empty() { key.to_string() } else { format!("{path}.{key}") }, first);
                }
            }
            _ => {}
        }
    }

    let Ok(document) = DeTable::parse(text) else { return Ok(()) };
    let mut first = None;
    for (key, item) in document.get_ref() {
        walk(item, key.get_ref().to_string(), &mut first);
    }
    match first {
        Some((start, path, raw)) => {
            Err(file_error(&path, Some(line_column(text, start)), &format!("numbers must be finite (got {raw})")))
        }
        None => Ok(()),
    }
}

/// Parses and checks a job file. Errors are 400 with the field path and, where known, the line.
pub fn parse(text: &str, format: Format) -> AppResult<JobFile> {
    if nesting(text) > MAX_NESTING {
        return Err(file_error("file", None, &format!("nested deeper than {MAX_NESTING} levels")));
    }
    let job: JobFile = match format {
        Format::Json => {
            let mut deserializer = serde_json::Deserializer::from_str(text);
            let job = serde_path_to_error::deserialize(&mut deserializer).map_err(|error| {
                let path = error.path().to_string();
                let inner = error.into_inner();
                let line = (inner.line() > 0).then(|| (inner.line(), inner.column()));
                let message = inner.to_string();
                let message = message.split(" at line ").next().unwrap_or(&message).to_owned();
                file_error(&path, line, &message)
            })?;
            deserializer.end().map_err(|e| file_error("file", Some((e.line(), e.column())), "trailing characters"))?;
            job
        }
        Format::Toml => {
            reject_non_finite(text)?;
            let deserializer = toml::de::Deserializer::parse(text).map_err(|error| {
                let line = error.span().map(|span| line_column(text, span.start));
                file_error("file", line, error.message())
            })?;
            serde_path_to_error::deserialize(deserializer).map_err(|error| {
                let path = error.path().to_string();
                let inner = error.into_inner();
                let line = inner.span().map(|span| line_column(text, span.start));
                file_error(&path, line, inner.message())
            })?
        }
    };
    check(&job)?;
    Ok(job)
}

#[cfg(test)]
mod tests {
    use super::*;

    const TOML_JOB: &str = r#"
name = "tube"
[[tools]]
number = 7
kind = "ball"
radius = 3

[[operations]]
operation = "deburr"
tool = 7
edge = "outer"
cut_amount = 0.2
workpiece = { kind = "tube", origin = [0, 0, 0], inner_radius = 15, outer_radius = 25 }
hole = { shape = "round", radius = 5 }
"#;

    fn path_and_detail(error: AppError) -> (String, String) {
        let problem = error.problem();
        (problem.errors[0].path.clone(), problem.detail)
    }

    #[test]
    fn toml_and_json_give_the_same_job() {
        let from_toml = parse(TOML_JOB, Format::Toml).unwrap();
        let json = serde_json::to_string(&from_toml).unwrap();
        assert_eq!(parse(&json, Format::Json).unwrap(), from_toml);
        assert_eq!(from_toml.operations[0].name(), "deburr");
    }

    #[test]
    fn errors_point_at_line_and_field() {
        let bad = TOML_JOB.replace("radius = 5", "radius = \"five\"");
        let (path, detail) = path_and_detail(parse(&bad, Format::Toml).unwrap_err());
        assert_eq!(path, "operations[0].hole.radius");
        assert!(detail.starts_with("line 14,"), "{detail}");

        let unknown = TOML_JOB.replace("edge = \"outer\"", "edge = \"outer\"\ncolour = 1");
        let (path, detail) = path_and_detail(parse(&unknown, Format::Toml).unwrap_err());
        assert_eq!(path, "operations[0].colour");
        assert!(detail.contains("line"), "{detail}");

        let broken = "name = \"x\"\noperations = [ {";
        let (path, detail) = path_and_detail(parse(broken, Format::Toml).unwrap_err());
        assert_eq!(path, "file");
        assert!(detail.starts_with("line 2,"), "{detail}");

        let json = "{\"operations\": [{\"operation\": \"deburr\",\n \"tool\": \"x\"}]}";
        let (path, detail) = path_and_detail(parse(json, Format::Json).unwrap_err());
        assert_eq!(path, "operations[0].tool");
        assert!(detail.starts_with("line 2,"), "{detail}");

        let (path, _) = path_and_detail(parse("{\"operations\": []}", Format::Json).unwrap_err());
        assert_eq!(path, "operations");
        let deep = format!("x = {}{}", "[".repeat(200), "]".repeat(200));
        assert!(parse(&deep, Format::Toml).is_err());
        let twice =
            TOML_JOB.replace("[[operations]]", "[[tools]]\nnumber = 7\nkind = \"ball\"\nradius = 2\n\n[[operations]]");
        let (path, _) = path_and_detail(parse(&twice, Format::Toml).unwrap_err());
        assert_eq!(path, "tools[1].number");
    }

    #[test]
    fn operation_key_anywhere_in_the_table() {
        let reordered = TOML_JOB
            .replace("operation = \"deburr\"\n", "")
            .replace("cut_amount = 0.2", "cut_amount = 0.2\noperation = \"deburr\"");
        assert_eq!(parse(&reordered, Format::Toml).unwrap(), parse(TOML_JOB, Format::Toml).unwrap());
        let missing = TOML_JOB.replace("operation = \"deburr\"\n", "");
        let (path, detail) = path_and_detail(parse(&missing, Format::Toml).unwrap_err());
        assert_eq!(path, "operations[0]");
        assert!(detail.contains("missing field `operation`"), "{detail}");
    }

    #[test]
    fn non_finite_numbers_point_at_line_and_field() {
        let bad = TOML_JOB.replace("cut_amount = 0.2", "cut_amount = -inf");
        let (path, detail) = path_and_detail(parse(&bad, Format::Toml).unwrap_err());
        assert_eq!(path, "operations[0].cut_amount");
        assert!(detail.starts_with("line 12,") && detail.contains("-inf"), "{detail}");
        let bad = TOML_JOB.replace("origin = [0, 0, 0]", "origin = [0, nan, 0]");
        let (path, _) = path_and_detail(parse(&bad, Format::Toml).unwrap_err());
        assert_eq!(path, "operations[0].workpiece.origin[1]");
        let fine = TOML_JOB.replace("cut_amount = 0.2", "cut_amount = 2_0.0e-2");
        assert!(parse(&fine, Format::Toml).is_ok());
    }

    #[test]
    fn format_detection() {
        assert_eq!(Format::detect(Some("a.TOML"), None, "{"), Format::Toml);
        assert_eq!(Format::detect(None, Some("application/json"), "x = 1"), Format::Json);
        assert_eq!(Format::detect(None, None, "  {\"a\": 1}"), Format::Json);
        assert_eq!(Format::detect(None, None, "a = 1"), Format::Toml);
    }

    #[test]
    fn nesting_counts_brackets_outside_comments_and_strings() {
        assert_eq!(nesting("a = [[1], [2]]\n[[operations]]\nb = { c = [3] }"), 2);
        let brackets = "[".repeat(100);
        // A comment, basic, literal and multi-line strings full of brackets do not count.
        let quiet = format!(
            "# {brackets}\nname = \"{brackets}\\\" {brackets}\" # {brackets}\nx = '{brackets}'\n\
             y = \"\"\"\n{brackets}\"\"\"\"\nz = '''{brackets}\n'''\n[[operations]]\nw = [1] # ]]]]\n"
        );
        assert_eq!(nesting(&quiet), 2, "{quiet}");
        // The same brackets outside them do.
        assert_eq!(nesting(&format!("a = {brackets}")), 100);
        // A job file with brackets in a comment and its name is read.
        let job = format!(
            "# {brackets}\n{}",
            TOML_JOB.replace("name = \"tube\"", &format!("name = \"tube {}\"", "[".repeat(40)))
        );
        assert_eq!(parse(&job, Format::Toml).unwrap().operations.len(), 1);
    }
}
