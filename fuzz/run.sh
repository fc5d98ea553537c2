#!/usr/bin/env bash
# Builds and runs the fuzz targets for a bounded time, without cargo-fuzz (only a nightly
# toolchain: `cargo +nightly`). Same flags and layout as `cargo fuzz run`.
#
#   fuzz/run.sh TARGET [SECONDS]     one target (default 60 s)
#   fuzz/run.sh all [SECONDS]        every target, one after the other, SECONDS each
#   fuzz/run.sh list                 the targets
#
# Corpus: fuzz/corpus/<target> (valid messages rewritten there as seed-* on every run).
# Crashes: fuzz/artifacts/<target>/crash-* (libFuzzer's log next to them: fuzz.log).
# Exits non-zero if any target crashed (panic, failed check, sanitizer report, timeout,
# out of memory) or did not build.
#
# Environment:
#   CARGO_TARGET_DIR   build directory (default fuzz/target, as cargo-fuzz)
#   FUZZ_SANITIZER     address | none | auto (default: address if this toolchain can link it)
#   FUZZ_SEEDS         0: do not seed the corpus
#   FUZZ_TIMEOUT       seconds one input may take before it counts as a crash (default 10)
#   FUZZ_ARGS          extra libFuzzer arguments (e.g. "-jobs=2 -workers=2" or "-max_len=65536")
#   RUSTFLAGS          appended to the instrumentation flags
set -euo pipefail

FUZZ_DIR=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
MANIFEST="$FUZZ_DIR/Cargo.toml"
TARGET_DIR=${CARGO_TARGET_DIR:-$FUZZ_DIR/target}
TOOLCHAIN=${FUZZ_TOOLCHAIN:-+nightly}

usage() {
    sed -n '2,20p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//' >&2
    exit 2
}

targets() {
    # The [[bin]] names of the manifest: what `cargo fuzz list` prints.
    awk '/^\[\[bin\]\]/ { bin = 1; next }
         /^\[/ { bin = 0 }
         bin && /^name *=/ { gsub(/^name *= *"|" *$/, ""); print }' "$MANIFEST"
}

[[ $# -ge 1 ]] || usage
WHAT=$1
SECONDS_EACH=${2:-60}
[[ $SECONDS_EACH =~ ^[0-9]+$ ]] || usage
if [[ $WHAT == list ]]; then
    targets
    exit 0
fi
if [[ $WHAT == all ]]; then
    mapfile -t TARGETS < <(targets)
else
    targets | grep -qx -- "$WHAT" || { echo "unknown target '$WHAT'; targets:" >&2; targets >&2; exit 2; }
    TARGETS=("$WHAT")
fi

cargo "$TOOLCHAIN" --version >/dev/null 2>&1 || {
    echo "run.sh: no nightly toolchain (cargo $TOOLCHAIN); rustup toolchain install nightly" >&2
    exit 2
}
TRIPLE=$(rustc "$TOOLCHAIN" -vV | sed -n 's/^host: //p')

# --- sanitizer -----------------------------------------------------------------------------
SANITIZER=${FUZZ_SANITIZER:-auto}
if [[ $SANITIZER == auto ]]; then
    probe=$(mktemp -d)
    printf 'fn main() { println!("{}", std::hint::black_box(vec![1u8; 8])[3]); }\n' >"$probe/p.rs"
    if rustc "$TOOLCHAIN" -Zsanitizer=address --target "$TRIPLE" -o "$probe/p" "$probe/p.rs" \
        >/dev/null 2>&1 && "$probe/p" >/dev/null 2>&1; then
        SANITIZER=address
    else
        SANITIZER=none
        echo "run.sh: AddressSanitizer does not work with this toolchain: fuzzing without it" >&2
    fi
    rm -rf "$probe"
fi

# --- build (the flags of `cargo fuzz build`, release with debug assertions) -----------------
# Exactly cargo-fuzz 0.13's flags, in its order, so both can share a target directory
# without rebuilding each other's work.
FLAGS="-Cpasses=sancov-module \
-Cllvm-args=-sanitizer-coverage-level=4 \
-Cllvm-args=-sanitizer-coverage-inline-8bit-counters \
-Cllvm-args=-sanitizer-coverage-pc-table \
-Cllvm-args=-sanitizer-coverage-trace-compares \
--cfg fuzzing \
-Cllvm-args=-simplifycfg-branch-fold-threshold=0"
case $SANITIZER in
    address) FLAGS+=" -Zsanitizer=address" ;;
    none) ;;
    *) echo "run.sh: FUZZ_SANITIZER must be address, none or auto" >&2; exit 2 ;;
esac
if [[ $TRIPLE == *-linux-* ]]; then
    FLAGS+=" -Cllvm-args=-sanitizer-coverage-stack-depth"
fi
FLAGS+=" -Cdebug-assertions -Ccodegen-units=1"
[[ -n ${RUSTFLAGS:-} ]] && FLAGS+=" $RUSTFLAGS"

BIN_ARGS=()
for t in "${TARGETS[@]}"; do BIN_ARGS+=(--bin "$t"); done

echo "== build (${#TARGETS[@]} target(s), sanitizer: $SANITIZER, $TARGET_DIR)"
build_start=$(date +%s)
# --target: the flags then apply to the targets only, not to build scripts and proc macros.
RUSTFLAGS=$FLAGS CARGO_TARGET_DIR=$TARGET_DIR CARGO_FUZZ=1 CARGO_FUZZ_MANIFEST=$MANIFEST \
    cargo "$TOOLCHAIN" build --manifest-path "$MANIFEST" --release \
    --config 'profile.release.debug="line-tables-only"' --target "$TRIPLE" "${BIN_ARGS[@]}"
echo "== build took $(($(date +%s) - build_start)) s"
BIN_DIR=$TARGET_DIR/$TRIPLE/release

# --- seeds ---------------------------------------------------------------------------------
# Rewritten on every run, so they follow the current messages and wire version.
if [[ ${FUZZ_SEEDS:-1} != 0 ]]; then
    echo "== seeding fuzz/corpus with valid messages (examples/gen_seeds.rs)"
    # Uninstrumented, on the host: a plain debug build in the same target directory.
    if ! env -u RUSTFLAGS CARGO_TARGET_DIR=$TARGET_DIR cargo "$TOOLCHAIN" run --quiet \
        --manifest-path "$MANIFEST" --example gen_seeds -- "$FUZZ_DIR/corpus"; then
        echo "run.sh: seeding failed (fuzzing from the corpus as it is)" >&2
    fi
fi

# --- run -----------------------------------------------------------------------------------
export ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_odr_violation=0
read -r -a EXTRA <<<"${FUZZ_ARGS:-}"
failed=()
summary=()
run_start=$(date +%s)
for t in "${TARGETS[@]}"; do
    corpus=$FUZZ_DIR/corpus/$t
    artifacts=$FUZZ_DIR/artifacts/$t
    mkdir -p "$corpus" "$artifacts"
    log=$artifacts/fuzz.log
    marker=$artifacts/.started
    touch "$marker"
    echo "== $t: ${SECONDS_EACH}s"
    start=$(date +%s.%N)
    set +e
    "$BIN_DIR/$t" -artifact_prefix="$artifacts/" -max_total_time="$SECONDS_EACH" \
        -timeout="${FUZZ_TIMEOUT:-10}" -print_final_stats=1 "${EXTRA[@]}" "$corpus" >"$log" 2>&1
    rc=$?
    set -e
    took=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
    execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
    if [[ -z $execs ]]; then # killed before the final stats: the last status line
        execs=$(grep -oE '^#[0-9]+' "$log" | tail -n 1 | tr -d '#')
    fi
    cov=$(grep -oE 'cov: [0-9]+' "$log" | tail -n 1 | cut -d' ' -f2)
    units=$(grep -oE 'corp: [0-9]+' "$log" | tail -n 1 | cut -d' ' -f2)
    line=$(printf '%-24s execs %-10s cov %-6s corpus %-6s %6ss' "$t" "${execs:-?}" "${cov:-?}" "${units:-?}" "$took")
    if [[ $rc == 0 ]]; then
        summary+=("$line  ok")
        echo "$line  ok"
    else
        failed+=("$t")
        summary+=("$line  CRASH (exit $rc)")
        echo "$line  CRASH (exit $rc), log: $log"
        # The panic or sanitizer report, and the input.
        grep -m1 -B2 -A12 -E "panicked at|ERROR: (AddressSanitizer|libFuzzer)|==ERROR|SUMMARY" "$log" || tail -n 40 "$log"
        # This run's inputs only (earlier crashes stay in the directory).
        find "$artifacts" -maxdepth 1 -type f -newer "$marker" \
            \( -name 'crash-*' -o -name 'timeout-*' -o -name 'oom-*' -o -name 'leak-*' \) |
        while read -r crash; do
            echo "-- input $crash ($(wc -c <"$crash") bytes), hex:"
            od -An -tx1 -v "$crash" | tr -d ' \n' | fold -w 128
            echo
            echo "-- replay: $BIN_DIR/$t $crash"
        done
    fi
done

echo
echo "== summary (run: $(($(date +%s) - run_start)) s, ${SECONDS_EACH}s per target, sanitizer: $SANITIZER)"
printf '%s\n' "${summary[@]}"
if [[ ${#failed[@]} -gt 0 ]]; then
    echo "FAILED: ${failed[*]}" >&2
    exit 1
fi
