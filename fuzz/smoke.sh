#!/usr/bin/env bash
# Builds the fuzz targets (libFuzzer via libfuzzer-sys, on the stable toolchain: no cargo-fuzz,
# no nightly) and runs each one for a short while from its committed corpus. Exits non-zero
# on the first crash, panic or timeout; the failing input is left in fuzz/artifacts/.
#
#   bash fuzz/smoke.sh              # every target, FUZZ_RUNS (default 50000) runs each
#   FUZZ_RUNS=1000000 FUZZ_SECS=3600 bash fuzz/smoke.sh config replay
#
# The mutations are seeded (FUZZ_SEED, default 1) and counted in runs, so CI explores the same
# inputs every time: a red CI means a real regression, not a lucky draw. FUZZ_SECS (default 30)
# caps each target's time. Long campaigns: pick another seed and more runs.
# New inputs found go to a temporary folder, so the committed corpus is not changed.
set -euo pipefail
cd "$(dirname "$0")"
SECS="${FUZZ_SECS:-30}"
RUNS="${FUZZ_RUNS:-50000}"
SEED="${FUZZ_SEED:-1}"
TARGETS=("$@")
if [ ${#TARGETS[@]} -eq 0 ]; then
  TARGETS=(map_yaml map_image config georef landmarks replay)
fi
HOST="$(rustc -vV | sed -n 's/^host: //p')"
# What `cargo fuzz build --sanitizer none` passes, all stable flags. `--target` keeps the
# instrumentation away from build scripts and proc macros.
export RUSTFLAGS="-Cpasses=sancov-module -Cllvm-args=-sanitizer-coverage-level=4 \
-Cllvm-args=-sanitizer-coverage-inline-8bit-counters -Cllvm-args=-sanitizer-coverage-pc-table \
-Cllvm-args=-sanitizer-coverage-trace-compares --cfg fuzzing"
echo "== building fuzz targets (${HOST})"
cargo build --release --locked --target "$HOST" --bins
mkdir -p artifacts
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
for t in "${TARGETS[@]}"; do
  mkdir -p "$work/$t"
  echo "== fuzz $t: ${RUNS} runs, seed ${SEED}, at most ${SECS}s"
  if ! "target/$HOST/release/$t" -seed="$SEED" -runs="$RUNS" -max_total_time="$SECS" -timeout=10 -rss_limit_mb=2048 \
    -max_len=8192 -print_final_stats=1 -artifact_prefix="artifacts/$t-" \
    "$work/$t" "corpus/$t" >"$work/$t.log" 2>&1; then
    tail -n 40 "$work/$t.log"
    echo "fuzz target $t failed; the input is in fuzz/artifacts/"
    exit 1
  fi
  grep -E '^(Done|stat::number_of_executed_units)' "$work/$t.log" || true
done
echo "fuzz smoke: ${#TARGETS[@]} targets, no crash"
