//! Opening user files safely: only regular files are read, so a FIFO, a device or a folder
//! named as a map, image, landmark, georef, options or trace file is an error instead of a
//! read that never ends.

use std::fs::File;
use std::io;
use std::path::Path;

/// Opens `path` for reading if it is a regular file (following symlinks).
///
/// # Errors
/// The file does not exist, is not a regular file, or cannot be opened.
pub fn open_regular(path: &Path) -> io::Result<File> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "not a regular file",
        ));
    }
    File::open(path)
}

/// The largest text input read whole (a map YAML, planner options, zones, landmarks, georef,
/// waypoints, `run.json`): 64 MiB, far above any real one (the YAML readers stop at 250 000
/// nodes anyway), so that a huge or sparse file named by mistake is refused before it is read
/// into memory (a 3 GB options file took 3 GB and over a minute).
pub const MAX_TEXT_BYTES: u64 = 64 << 20;

fn too_large(len: u64) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!(
            "the file is {:.1} MiB, more than the {} MiB a text input may be",
            len as f64 / (1u64 << 20) as f64,
            MAX_TEXT_BYTES >> 20
        ),
    )
}

/// Reads a regular file's bytes, at most [`MAX_TEXT_BYTES`].
///
/// # Errors
/// As [`open_regular`], plus read errors and a file larger than [`MAX_TEXT_BYTES`].
pub fn read_bytes(path: &Path) -> io::Result<Vec<u8>> {
    let file = open_regular(path)?;
    let len = file.metadata()?.len();
    if len > MAX_TEXT_BYTES {
        return Err(too_large(len));
    }
    // A file that grows while it is read is cut just past the limit, then refused.
    let mut v = Vec::new();
    io::Read::read_to_end(&mut io::Read::take(file, MAX_TEXT_BYTES + 1), &mut v)?;
    if v.len() as u64 > MAX_TEXT_BYTES {
        return Err(too_large(v.len() as u64));
    }
    Ok(v)
}

/// Reads a regular file as UTF-8 text, at most [`MAX_TEXT_BYTES`], without a leading byte
/// order mark (editors on Windows write one; a `GeoJSON` zone, a JSON options file or a CSV
/// of landmarks saved so was refused at "line 1 column 1", while YAML parsers skip it).
///
/// # Errors
/// As [`read_bytes`], plus invalid UTF-8.
pub fn read_text(path: &Path) -> io::Result<String> {
    text_of(read_bytes(path)?).ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            "stream did not contain valid UTF-8",
        )
    })
}

/// `bytes` as text without a leading byte order mark, as [`read_text`] reads a file; `None`
/// when they are not valid UTF-8 (a caller that tells a binary file apart from a file too
/// large, both `InvalidData` from [`read_text`], reads the bytes and asks this).
pub fn text_of(bytes: Vec<u8>) -> Option<String> {
    let mut text = String::from_utf8(bytes).ok()?;
    if text.starts_with('\u{feff}') {
        text.drain(..'\u{feff}'.len_utf8());
    }
    Some(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn huge_files_are_refused_before_they_are_read() {
        let d = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
        let p = d.path().join("big.yaml");
        let f = File::create(&p).unwrap_or_else(|e| panic!("{e}"));
        f.set_len(3 << 30).unwrap_or_else(|e| panic!("{e}")); // sparse: no disk used
        let e = read_text(&p).err().map(|e| e.to_string());
        assert_eq!(
            e.as_deref(),
            Some("the file is 3072.0 MiB, more than the 64 MiB a text input may be")
        );
        f.set_len(MAX_TEXT_BYTES).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(
            read_bytes(&p).map(|b| b.len() as u64).ok(),
            Some(MAX_TEXT_BYTES)
        );
    }

    /// A leading byte order mark is no part of the text (JSON and CSV readers refused it);
    /// one elsewhere is kept.
    #[test]
    fn a_leading_byte_order_mark_is_skipped() {
        let d = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
        let p = d.path().join("t.json");
        std::fs::write(&p, "\u{feff}{\"a\": \"\u{feff}\"}").unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(read_text(&p).ok().as_deref(), Some("{\"a\": \"\u{feff}\"}"));
    }

    #[test]
    fn a_number_the_parser_cannot_read_is_shown() {
        let text = "image: m.png\nresolution: 1e400\norigin: [abc, 0, 0]\n";
        let big = yaml_words("invalid floating point at line 2, column 13", text);
        assert_eq!(
            big,
            "`1e400` is beyond the range of a number (at most about 1.8e308) at line 2, column 13"
        );
        let word = yaml_words("line 3 column 10: invalid floating point", text);
        assert_eq!(word, "line 3 column 10: `abc` is not a number");
        // a place outside the text leaves the message as it came
        let off = yaml_words("invalid floating point at line 9, column 1", text);
        assert_eq!(off, "invalid floating point at line 9, column 1");
    }

    #[test]
    fn folders_are_refused() {
        let d = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
        let e = read_text(d.path()).err().map(|e| e.to_string());
        assert_eq!(e.as_deref(), Some("not a regular file"));
    }
}

/// A YAML parser message in the user's words: the parser's advice to its programmer (a second
/// document "detected; use `from_str_multiple` ...") becomes what the file holds.
/// A number the parser could not read is shown as written in `text`: "invalid floating point at
/// line 2, column 13" says which value, and whether it is not a number (`abc`, `1.2.3`) or one
/// beyond the range of a float (`1e400`, which `.inf` is not: that one reads as infinite).
pub fn yaml_words(message: &str, text: &str) -> String {
    const MULTI: &str =
        "multiple YAML documents detected; use from_str_multiple or from_str_multiple_with_options";
    float_words(message, text)
        .replace(
            MULTI,
            "holds a second YAML document (after a `---` line); ccpp reads files of one document",
        )
        // (the parser's own words for `.nan` or `.inf` where a zone file's numbers are read:
        // "rejected by the configured policy" named a setting the user cannot see)
        .replace(
            " rejected by the configured policy",
            " where a finite number is needed",
        )
}

/// The parser's "invalid floating point" with the value found at the line and column the
/// message names (see [`yaml_words`]); any other message as it is.
fn float_words(message: &str, text: &str) -> String {
    const BAD: &str = "invalid floating point";
    if !message.contains(BAD) {
        return message.to_owned();
    }
    // The number after `word` in the message ("line 2, column 13" or "line 2 column 13").
    let number_after = |word: &str| {
        let at = message.find(word)? + word.len();
        let digits: String = message[at..]
            .chars()
            .take_while(char::is_ascii_digit)
            .collect();
        digits.parse::<usize>().ok()
    };
    let (Some(line), Some(col)) = (number_after("line "), number_after("column ")) else {
        return message.to_owned();
    };
    let token: String = text
        .lines()
        .nth(line.saturating_sub(1))
        .map(|l| {
            l.chars()
                .skip(col.saturating_sub(1))
                .take_while(|c| !c.is_whitespace() && !matches!(c, ',' | ']' | '}' | '#'))
                .take(40)
                .collect()
        })
        .unwrap_or_default();
    if token.is_empty() {
        return message.to_owned();
    }
    let why = match token.trim_start_matches('+').parse::<f64>() {
        Ok(v) if v.is_infinite() => "is beyond the range of a number (at most about 1.8e308)",
        _ => "is not a number",
    };
    message.replacen(
        BAD,
        &format!("`{}` {why}", crate::message::visible(&token)),
        1,
    )
}

/// A JSON list where the typed value has a mapping (a section or a struct), named by its
/// path: serde fills a struct from a list by position, so `{"bcd": [0.2]}` set bcd's first
/// option (`lane_spacing_m`) without naming it, `[{}, ...]` filled the planners' sections by
/// their order, and a new field would shift every later one; YAML refuses both shapes
/// (`expected mapping start`). Hostile pass, stop 69.
fn json_list_for_mapping<T: serde::Serialize>(text: &str, typed: &T) -> Option<String> {
    use serde_json::Value;
    fn walk(raw: &Value, typed: &Value, path: &str) -> Option<String> {
        match (raw, typed) {
            (Value::Array(_), Value::Object(_)) => Some(if path.is_empty() {
                "the file is a list where a mapping (a JSON object) of sections is expected"
                    .to_string()
            } else {
                format!("{path}: a list where a mapping (a JSON object) of fields is expected")
            }),
            (Value::Object(r), Value::Object(t)) => r.iter().find_map(|(k, rv)| {
                let p = if path.is_empty() {
                    crate::message::visible(k)
                } else {
                    format!("{path}.{}", crate::message::visible(k))
                };
                t.get(k).and_then(|tv| walk(rv, tv, &p))
            }),
            (Value::Array(r), Value::Array(t)) => r
                .iter()
                .zip(t)
                .enumerate()
                .find_map(|(i, (rv, tv))| walk(rv, tv, &format!("{path}[{i}]"))),
            _ => None,
        }
    }
    let raw: Value = serde_json::from_str(text).ok()?;
    let typed = serde_json::to_value(typed).ok()?;
    walk(&raw, &typed, "")
}

/// Deserializes YAML, or JSON when `json`, and on an error names the field it is in: the text
/// is parsed as `serde_saphyr::from_str` / `serde_json::from_str` parse it, and only a failed
/// parse is read again to find the error's path (`bcd.turn_cost_m: line 1 column 21: invalid
/// floating point` where the parser alone says `line 1 column 21: invalid floating point`).
/// An error at the document's root keeps the parser's message as it is. YAML is typed as JSON
/// is: a quoted scalar that the typed reading took as a number or a boolean is refused,
/// naming its path (found by walking the untyped reading beside the typed value).
///
/// # Errors
/// The parser's message, with the field's path in front when there is one.
pub fn parse_yaml_or_json<T: serde::de::DeserializeOwned + serde::Serialize>(
    text: &str,
    json: bool,
) -> Result<T, String> {
    // (JSON's messages quote values and keys raw; YAML's escape them: made visible, so that
    // a key holding a line break cannot cut the message, nor an escape act on the terminal)
    let first = if json {
        serde_json::from_str::<T>(text).map_err(|e| crate::message::visible(&e.to_string()))
    } else {
        serde_saphyr::from_str::<T>(text).map_err(|e| yaml_words(&e.to_string(), text))
    };
    let message = match first {
        Ok(v) => {
            let problem = if json {
                json_list_for_mapping(text, &v)
            } else {
                quoted_scalar_problem(text, &v)
            };
            match problem {
                None => return Ok(v),
                Some(problem) => return Err(problem),
            }
        }
        Err(m) => m,
    };
    let path = if json {
        let mut de = serde_json::Deserializer::from_str(text);
        serde_path_to_error::deserialize::<_, T>(&mut de)
            .err()
            .map(|e| crate::message::visible(&e.path().to_string()))
    } else {
        // Kept from inside: a deserialization that stops at its error leaves events unread,
        // which the reader then reports instead.
        let mut found = None;
        let outcome = serde_saphyr::with_deserializer_from_str(text, |de| {
            found = serde_path_to_error::deserialize::<_, T>(de)
                .err()
                .map(|e| crate::message::visible(&e.path().to_string()));
            Ok(())
        });
        // Only the path is wanted; the first parse's message is the one reported.
        drop(outcome);
        found
    };
    Err(match path {
        Some(p) if !p.is_empty() && p != "." && !message.starts_with(&format!("{p}:")) => {
            format!("{p}: {message}")
        }
        _ => message,
    })
}

/// A quoted YAML scalar that the typed reading `typed` took as a number or a boolean (`"3"` as
/// `3`, `"no"` as `false`), which JSON refuses and a quoted value does not mean. The text read
/// untyped (a quoted scalar stays text there; `.inf` passes) is walked beside `typed` written
/// out as JSON: the first text, in key order, that the typed value holds as a number or a
/// boolean is named with its path. Other differences (a bare number read into a text field,
/// defaults filled in, keys the types name otherwise) are not looked at.
fn quoted_scalar_problem<T: serde::Serialize>(text: &str, typed: &T) -> Option<String> {
    let mut options = serde_saphyr::Options::default();
    options.non_finite_float_policy = serde_saphyr::NonFiniteFloatPolicy::PassThrough;
    let untyped: serde_json::Value = serde_saphyr::from_str_with_options(text, options).ok()?;
    let typed = serde_json::to_value(typed).ok()?;
    quoted_in(&untyped, &typed, "")
}

/// [`quoted_scalar_problem`]'s walk at `path`.
fn quoted_in(untyped: &serde_json::Value, typed: &serde_json::Value, path: &str) -> Option<String> {
    use serde_json::Value;
    match (untyped, typed) {
        (Value::String(s), _) => {
            let wanted = match typed {
                Value::Bool(_) => "a boolean",
                Value::Number(_) => "a number",
                // A quoted `.inf` or `.nan` the typed reading took as a float (JSON writes
                // it null).
                Value::Null
                    if matches!(
                        s.trim_start_matches(['+', '-'])
                            .to_ascii_lowercase()
                            .as_str(),
                        ".inf" | ".nan"
                    ) =>
                {
                    "a number"
                }
                _ => return None,
            };
            Some(format!(
                "{path}: invalid type: string {s:?}, expected {wanted}; a quoted value is text in YAML: write numbers and booleans without quotes"
            ))
        }
        (Value::Object(u), Value::Object(t)) => u.iter().find_map(|(k, v)| {
            let inner = if path.is_empty() {
                k.clone()
            } else {
                format!("{path}.{k}")
            };
            quoted_in(v, t.get(k)?, &inner)
        }),
        (Value::Array(u), Value::Array(t)) => u
            .iter()
            .zip(t)
            .enumerate()
            .find_map(|(i, (v, w))| quoted_in(v, w, &format!("{path}[{i}]"))),
        _ => None,
    }
}

#[cfg(test)]
mod parse_tests {
    use super::parse_yaml_or_json;

    #[derive(Debug, serde::Deserialize, serde::Serialize, PartialEq)]
    #[serde(deny_unknown_fields)]
    struct Inner {
        rounds: u32,
        #[serde(default)]
        cost: f64,
    }

    #[derive(Debug, serde::Deserialize, serde::Serialize, PartialEq)]
    #[serde(deny_unknown_fields)]
    struct Outer {
        bcd: Inner,
    }

    #[derive(Debug, serde::Deserialize, serde::Serialize)]
    struct Flags {
        #[serde(default)]
        on: bool,
        #[serde(default)]
        name: String,
        #[serde(default)]
        limit: Option<f64>,
    }

    #[test]
    fn errors_name_the_field_and_good_text_parses_as_before() {
        let ok: Outer = parse_yaml_or_json("bcd: { rounds: 3 }", false).unwrap();
        assert_eq!(ok.bcd.rounds, 3);
        let ok: Outer = parse_yaml_or_json(r#"{"bcd": {"rounds": 3}}"#, true).unwrap();
        assert_eq!(ok.bcd.rounds, 3);
        for (text, json) in [
            ("bcd: { rounds: -2 }", false),
            ("bcd:\n  rounds: 1\n  cost: abc\n", false),
            (r#"{"bcd": {"rounds": -2}}"#, true),
            (r#"{"bcd": {"rounds": 1, "cost": "x"}}"#, true),
        ] {
            let e = parse_yaml_or_json::<Outer>(text, json).unwrap_err();
            assert!(
                e.starts_with("bcd.rounds: ") || e.starts_with("bcd.cost: "),
                "{text}: {e}"
            );
        }
        // A quoted number or boolean is text, as in JSON ("3" was read as 3, "no" as false).
        for (text, path) in [
            ("bcd: { rounds: \"3\" }", "bcd.rounds"),
            ("bcd: { rounds: 3, cost: '0.5' }", "bcd.cost"),
        ] {
            let e = parse_yaml_or_json::<Outer>(text, false).unwrap_err();
            assert!(
                e.starts_with(&format!("{path}: invalid type: string")) && e.contains("quoted"),
                "{text}: {e}"
            );
        }
        // Also beside `.inf` (which an untyped reading refused by default) and after a bare
        // number read into a text field (where reading the untyped text as the type stopped).
        for text in [
            "on: \"no\"",
            "limit: \"2\"",
            "limit: .inf\non: \"no\"",
            "name: 123\non: \"no\"",
            "limit: \".inf\"",
            "limit: \"-.NaN\"",
        ] {
            let e = parse_yaml_or_json::<Flags>(text, false).unwrap_err();
            assert!(e.contains("a quoted value is text"), "{text}: {e}");
        }
        // Plain scalars read as before: YAML 1.1 booleans, a number as a name, `.inf`.
        let f: Flags = parse_yaml_or_json("on: yes\nname: 123\nlimit: .inf", false).unwrap();
        assert!(f.on && f.name == "123" && f.limit == Some(f64::INFINITY));
        // Unknown fields and root errors keep the parser's words.
        let e = parse_yaml_or_json::<Outer>("bcd: { rounds: 1, turns: 2 }", false).unwrap_err();
        assert!(e.contains("unknown field `turns`"), "{e}");
        let e = parse_yaml_or_json::<Outer>("[1, 2]", false).unwrap_err();
        assert!(!e.starts_with('.'), "{e}");
    }
}
