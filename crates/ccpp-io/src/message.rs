//! One-line error messages for the user, shared by the command line and Python.
//!
//! Library errors often repeat their cause (a `Display` that includes the source, which is then
//! printed again), span several lines (YAML errors with a source snippet) or give advice meant
//! for programmers. [`one_line`] turns an error and its sources into one plain line: the
//! command line prints it after `error: `, Python raises it as `ccpp.CcppError` (before, Python
//! joined the causes as they were and showed a YAML error's eight-line snippet, the YAML
//! library's advice and its raw budget text).

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

/// The error and its sources as one line: each cause once, outermost first, joined by `: `.
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
    msg
}

#[cfg(test)]
mod tests {
    use super::*;

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
