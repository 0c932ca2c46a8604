//! Checks that two `trace.jsonl` files (either form: runs or one line per pose) decode to the
//! same poses (bit for bit) and events: `cargo run --release -p ccpp-io --example trace_same --
//! A B [A2 B2 ...]`. Prints the counts and exits 1 at the first difference.

use std::path::Path;

use ccpp_core::trace::Record;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 || args.len() & 1 == 1 {
        eprintln!("usage: trace_same A B [A2 B2 ...]");
        std::process::exit(2);
    }
    for pair in args.chunks(2) {
        let read = |p: &str| match ccpp_io::trace::read_trace(Path::new(p), None) {
            Ok(t) => t,
            Err(e) => {
                eprintln!("error: {e}");
                std::process::exit(1);
            }
        };
        let (a, b) = (read(&pair[0]), read(&pair[1]));
        let key = |r: Record| match r {
            Record::Pose { t, pose } => format!(
                "{t} {:x} {:x} {:x}",
                pose[0].to_bits(),
                pose[1].to_bits(),
                pose[2].to_bits()
            ),
            r @ Record::Event { .. } => serde_json::to_string(&r).unwrap_or_default(),
        };
        let mut ra = a.records().map(key);
        let mut rb = b.records().map(key);
        let mut k = 0usize;
        loop {
            match (ra.next(), rb.next()) {
                (None, None) => break,
                (x, y) if x == y => k += 1,
                (x, y) => {
                    eprintln!(
                        "{} vs {}: record {k} differs: {x:?} / {y:?}",
                        pair[0], pair[1]
                    );
                    std::process::exit(1);
                }
            }
        }
        println!(
            "same: {} and {}: {} poses, {} events ({} and {} stored pieces)",
            pair[0],
            pair[1],
            a.pose_count(),
            a.event_count(),
            a.piece_count(),
            b.piece_count()
        );
    }
}
