#!/usr/bin/env bash
# Regenerates the figures in docs/figures from the commands the docs cite for them, as listed
# in docs/figures/figures.txt (one line per figure: the figure, the file its command writes,
# the POSIX cksum of the command's CSV and its size, then the command's arguments), and
# records the new checksums there. The test docs_figures_cli (agents/graspopt/tests/cli)
# reruns the commands and fails when a CSV no longer has its recorded checksum: the command
# draws something else than the figure shows. Regenerate, look at the figures, and update
# the numbers the docs give about them (README.md's caption of the mug scan, for one).
#
#   docs/figures/regenerate.sh                  every figure
#   docs/figures/regenerate.sh mug-bw-scan.png  the figures named
#
# The commands run with a release build (`cargo build --release -p graspopt`), or with the
# binary in $GRASPOPT if set: a debug build gives the same numbers, slower.
set -euo pipefail
cd "$(dirname "$0")/../.."
list=docs/figures/figures.txt
if [ -z "${GRASPOPT:-}" ]; then
    cargo build --release -p graspopt
    GRASPOPT=target/release/graspopt
fi
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
updated="$scratch/figures.txt"
found=0
while IFS= read -r line; do
    case "$line" in
    '' | '#'*)
        printf '%s\n' "$line" >>"$updated"
        continue
        ;;
    esac
    read -r figure written _ _ args <<<"$line"
    if [ $# -gt 0 ] && ! printf '%s\n' "$@" | grep -qxF "$figure"; then
        printf '%s\n' "$line" >>"$updated"
        continue
    fi
    found=$((found + 1))
    out="$scratch/${figure%.*}"
    echo "graspopt $args" >&2
    # The arguments are words without quotes or spaces in them.
    # shellcheck disable=SC2086
    "$GRASPOPT" $args --out "$out" >/dev/null
    cp "$out/$written" "docs/figures/$figure"
    read -r crc bytes _ < <(cksum "$out/${written%.*}.csv")
    printf '%-34s %-36s %10s %8s %s\n' "$figure" "$written" "$crc" "$bytes" "$args" >>"$updated"
done <"$list"
if [ $# -gt 0 ] && [ "$found" -ne $# ]; then
    echo "not every figure named is in $list" >&2
    exit 1
fi
cp "$updated" "$list"
echo "Regenerated $found figures; checksums in $list" >&2
