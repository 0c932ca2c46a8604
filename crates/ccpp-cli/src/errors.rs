//! One-line error messages for the user.
//!
//! Library errors often repeat their cause (a `Display` that includes the source, which
//! `anyhow` then prints again), span several lines (YAML errors with a source snippet) or give
//! advice meant for programmers. [`one_line`] turns an error chain into one plain line.

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

/// The error chain as one line: each cause once, outermost first, joined by `: `.
pub fn one_line(e: &anyhow::Error) -> String {
    let mut msg = String::new();
    for cause in e.chain() {
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

/// A clap error as one line (without clap's `error:` prefix) and a hint line.
pub fn clap_lines(e: &clap::Error) -> (String, String) {
    let text = e.to_string();
    let mut lines = text.lines();
    let mut first = Vec::new();
    for l in lines.by_ref() {
        if l.trim().is_empty() {
            break;
        }
        first.push(l.trim());
    }
    let mut line = first.join(" ");
    while let Some(rest) = line.strip_prefix("error: ") {
        line = rest.to_string();
    }
    let rest: Vec<&str> = lines.map(str::trim).collect();
    // The subcommand: from clap's usage line, else the first argument naming one.
    let from_args = || {
        let sub = std::env::args().nth(1).filter(|a| {
            use clap::CommandFactory as _;
            crate::args::Cli::command()
                .get_subcommands()
                .any(|c| c.get_name() == a)
        });
        sub.map_or_else(|| "ccpp".to_string(), |s| format!("ccpp {s}"))
    };
    let command = rest
        .iter()
        .find_map(|l| l.strip_prefix("Usage: "))
        .map_or_else(from_args, |u| {
            u.split_whitespace()
                .take_while(|w| !w.starts_with(['-', '<', '[']))
                .collect::<Vec<_>>()
                .join(" ")
        });
    let hint = match rest.iter().find_map(|l| l.strip_prefix("tip: ")) {
        Some(tip) => format!("hint: {tip}; see `{command} --help`"),
        None => format!("hint: see `{command} --help`"),
    };
    (line, hint)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn repeated_causes_are_printed_once() {
        let io = std::io::Error::other("not a regular file");
        let e = anyhow::Error::new(io).context("cannot read /tmp: not a regular file");
        assert_eq!(one_line(&e), "cannot read /tmp: not a regular file");
        let e = anyhow::anyhow!("No space left on device (os error 28)")
            .context("cannot write out/run.json: No space left on device (os error 28)")
            .context("cannot write out/run.json");
        assert_eq!(
            one_line(&e),
            "cannot write out/run.json: No space left on device (os error 28)"
        );
    }

    #[test]
    fn yaml_errors_lose_snippets_and_library_advice() {
        let text = "planner options dup.yaml: error: line 2 column 1: duplicate mapping key: \
                    ba_star, set DuplicateKeyPolicy in Options if acceptable\n --> <input>:2:1\n  |\n1 | x";
        let e = anyhow::anyhow!("{text}");
        assert_eq!(
            one_line(&e),
            "planner options dup.yaml: line 2 column 1: duplicate mapping key: ba_star"
        );
        let e =
            anyhow::anyhow!("planner options big.yaml: budget breached: Nodes {{ nodes: 250001 }}");
        assert_eq!(
            one_line(&e),
            "planner options big.yaml: the YAML is too large or too deeply nested (250001 nodes)"
        );
    }
}
