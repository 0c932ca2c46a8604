//! Reading a run's `trace.jsonl` back (`ccpp replay`, bench plots): one
//! [`Record`](ccpp_core::trace::Record) per line as JSON, blank lines skipped.
//!
//! ```
//! let t = ccpp_io::trace::parse_trace_jsonl("{\"t\":0,\"pose\":[1.0,2.0,0.0]}\n\n").unwrap();
//! assert_eq!(t.records.len(), 1);
//! let e = ccpp_io::trace::parse_trace_jsonl("{\"t\":0,\"pose\":[1.0,2.0,0.0]}\n{\n").unwrap_err();
//! assert_eq!(e.line, 2);
//! ```

use ccpp_core::trace::{Record, Trace};

/// A line of a trace that is not a trace record.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
#[error("line {line}: not a trace record ({message})")]
pub struct TraceLineError {
    /// 1-based line number.
    pub line: usize,
    /// The JSON parser's message.
    pub message: String,
}

/// Parses the text of a `trace.jsonl`.
///
/// # Errors
/// [`TraceLineError`] naming the first line that is not a JSON trace record.
pub fn parse_trace_jsonl(text: &str) -> Result<Trace, TraceLineError> {
    let mut records = Vec::new();
    for (k, line) in text.lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let r: Record = serde_json::from_str(line).map_err(|e| TraceLineError {
            line: k + 1,
            message: e.to_string(),
        })?;
        records.push(r);
    }
    Ok(Trace { records })
}
