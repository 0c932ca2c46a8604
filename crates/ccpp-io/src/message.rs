//! One-line error messages for the user, shared by the command line and Python.
//!
//! Library errors often repeat their cause (a `Display` that includes the source, which is then
//! printed again), span several lines (YAML errors with a source snippet) or give advice meant
//! for programmers. [`one_line`] turns an error and its sources into one plain line: the
//! command line prints it after `error: `, Python raises it as `ccpp.CcppError` (before, Python
//! joined the causes as they were and showed a YAML error's eight-line snippet, the YAML
//! library's advice and its raw budget text).

use std::fmt::Write as _;

/// Advice from the YAML library that a ccpp user cannot act on.
const LIBRARY_ADVICE: [&str; 2] = [
    ", set DuplicateKeyPolicy in Options if acceptable",
    " set DuplicateKeyPolicy in Options if acceptable",
];

/// Rewrites the YAML library's `budget breached: Kind { field: N }` as plain words.
fn plain_budget(text: &str) -> String {
    const KEY: &str = "budget breached: ";
    let Some(i) = text.find(KEY) else {
        return text.to_string();
    };
    let rest = &text[i + KEY.len()..];
    let end = rest.find('}').map_or(rest.len(), |e| e + 1);
    let kind: String = rest
        .chars()
        .take_while(char::is_ascii_alphanumeric)
        .collect();
    let number: String = rest[..end]
        .chars()
        .skip_while(|c| !c.is_ascii_digit())
        .take_while(char::is_ascii_digit)
        .collect();
    let mut what = String::new();
    for (k, c) in kind.chars().enumerate() {
        if c.is_ascii_uppercase() && k > 0 {
            what.push(' ');
        }
        what.push(c.to_ascii_lowercase());
    }
    let detail = if number.is_empty() {
        format!("too many {what}")
    } else {
        format!("{number} {what}")
    };
    format!(
        "{}the YAML is too large or too deeply nested ({detail}){}",
        &text[..i],
        &rest[end..]
    )
}

/// One cause's text on one line, without a nested `error:` prefix or library advice.
fn clean(text: &str) -> String {
    let first = text.lines().map(str::trim).find(|l| !l.is_empty());
    let mut s = first.unwrap_or("").to_string();
    while let Some(rest) = s.strip_prefix("error: ") {
        s = rest.to_string();
    }
    s = s.replace(": error: ", ": ");
    for advice in LIBRARY_ADVICE {
        s = s.replace(advice, "");
    }
    plain_budget(&s)
}

/// Whether `c` is one [`visible`] writes as an escape: a control character (line breaks, tab,
/// escape, bell, delete and the C1 controls), a bidirectional embedding, override or isolate
/// (U+202A..=U+202E, U+2066..=U+2069, which reorder the text after them), a line or paragraph
/// separator (U+2028, U+2029), or a noncharacter (U+FFFE, U+FFFF, which XML refuses). The
/// joiners and marks that ordinary names hold (U+200C zero-width non-joiner in Persian, U+200D
/// in emoji, U+200E/U+200F) are not: a map file named with one was refused.
pub fn hidden(c: char) -> bool {
    c.is_control()
        || matches!(
            c,
            '\u{2028}'..='\u{202e}' | '\u{2066}'..='\u{2069}' | '\u{fffe}' | '\u{ffff}'
        )
}

/// `text` with every character that would act on a terminal or hide in it ([`hidden`]:
/// escape sequences, carriage returns and line breaks, bidirectional overrides) written as
/// `\u{..}`, so that a name or value from a user's file is shown as it is and cannot set the
/// terminal's title, clear the screen, overwrite the line or start a forged `error:` line
/// (hostile pass: planner option keys, a map YAML's `mode`, a `GeoJSON` `type`, names in a run
/// folder, and a bench map named after a folder holding an escape reached stderr raw).
#[must_use]
pub fn visible(text: &str) -> String {
    if !text.chars().any(hidden) {
        return text.to_string();
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if hidden(c) {
            // (writing to a String cannot fail)
            let _ = write!(out, "\\u{{{:x}}}", u32::from(c));
        } else {
            out.push(c);
        }
    }
    out
}

/// The error and its sources as one line: each cause once, outermost first, joined by `: `;
/// characters a terminal would act on are made [`visible`].
pub fn one_line(e: &(dyn std::error::Error + 'static)) -> String {
    let mut msg = String::new();
    let mut cur = Some(e);
    while let Some(cause) = cur {
        cur = cause.source();
        let text = clean(&cause.to_string());
        if text.is_empty() || msg.contains(&text) {
            continue;
        }
        if text.starts_with(&msg) {
            // The cause repeats the context and adds to it.
            msg = text;
            continue;
        }
        if !msg.is_empty() {
            msg.push_str(": ");
        }
        msg.push_str(&text);
    }
    visible(&msg)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hidden_characters_are_written_as_escapes() {
        assert_eq!(visible("plain é ü 日本"), "plain é ü 日本");
        assert_eq!(
            visible("a\u{1b}]0;T\u{7}\u{1b}[2Jb\r\nerror: x\t\u{202e}y\u{2028}\u{fffe}"),
            "a\\u{1b}]0;T\\u{7}\\u{1b}[2Jb\\u{d}\\u{a}error: x\\u{9}\\u{202e}y\\u{2028}\\u{fffe}"
        );
        let e = E(
            "options c.yaml: ba_star.\u{1b}[31mEVIL: unknown field".into(),
            None,
        );
        assert_eq!(
            one_line(&e),
            "options c.yaml: ba_star.\\u{1b}[31mEVIL: unknown field"
        );
    }

    /// An error with a message and an optional source.
    #[derive(Debug)]
    struct E(String, Option<Box<E>>);

    impl std::fmt::Display for E {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            f.write_str(&self.0)
        }
    }

    impl std::error::Error for E {
        fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
            self.1.as_deref().map(|e| e as _)
        }
    }

    fn chain(texts: &[&str]) -> E {
        texts
            .iter()
            .rev()
            .fold(None, |inner, t| {
                Some(E((*t).to_string(), inner.map(Box::new)))
            })
            .expect("one text at least")
    }

    #[test]
    fn repeated_causes_are_printed_once() {
        let e = chain(&["cannot read /tmp: not a regular file", "not a regular file"]);
        assert_eq!(one_line(&e), "cannot read /tmp: not a regular file");
        let e = chain(&[
            "cannot write out/run.json",
            "cannot write out/run.json: No space left on device (os error 28)",
            "No space left on device (os error 28)",
        ]);
        assert_eq!(
            one_line(&e),
            "cannot write out/run.json: No space left on device (os error 28)"
        );
    }

    #[test]
    fn yaml_errors_lose_snippets_and_library_advice() {
        let text = "planner options dup.yaml: error: line 2 column 1: duplicate mapping key: \
                    ba_star, set DuplicateKeyPolicy in Options if acceptable\n --> <input>:2:1\n  |\n1 | x";
        assert_eq!(
            one_line(&chain(&[text])),
            "planner options dup.yaml: line 2 column 1: duplicate mapping key: ba_star"
        );
        let e = chain(&["planner options big.yaml: budget breached: Nodes { nodes: 250001 }"]);
        assert_eq!(
            one_line(&e),
            "planner options big.yaml: the YAML is too large or too deeply nested (250001 nodes)"
        );
    }
}
