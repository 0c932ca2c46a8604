//! One-line error messages for the user: the error chain through
//! [`ccpp_io::message::one_line`] (shared with Python), and clap's errors.

/// The error chain as one line: each cause once, outermost first, joined by `: `
/// ([`ccpp_io::message::one_line`]).
pub fn one_line(e: &anyhow::Error) -> String {
    let e: &(dyn std::error::Error + 'static) = e.as_ref();
    ccpp_io::message::one_line(e)
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
    fn anyhow_contexts_are_printed_once() {
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
}
