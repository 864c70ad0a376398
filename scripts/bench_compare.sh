#!/usr/bin/env bash
# Times two builds of `bench` against each other on the same sweeps, interleaved so the
# machine's drift hits both alike, then summarises (scripts/bench_compare.py).
#
#   scripts/bench_compare.sh BEFORE_COMMIT AFTER_COMMIT OUT [ROUNDS] [SWEEPS...]
#
# Each commit is exported (git archive) and built in its own folder under OUT; each round
# runs every sweep with one binary then the other, the order alternating between rounds.
# Defaults: 2 rounds; sweeps billboards impostors scaling. BENCH_FLAGS (e.g. `--quick`)
# is passed to every run.
set -euo pipefail
before=$1 after=$2 out=$3 rounds=${4:-2}
shift $(( $# < 4 ? $# : 4 ))
sweeps=("$@")
[ ${#sweeps[@]} -eq 0 ] && sweeps=(billboards impostors scaling)
root=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$out"
for c in "$before" "$after"; do
    src=$out/src-$c
    if [ ! -x "$src/target/release/bench" ]; then
        rm -rf "$src" && mkdir -p "$src"
        git -C "$root" archive "$c" | tar -x -C "$src"
        (cd "$src" && cargo build --release -p demos --bin bench)
    fi
done
for r in $(seq 1 "$rounds"); do
    order=("$before" "$after")
    [ $((r % 2)) -eq 0 ] && order=("$after" "$before")
    for c in "${order[@]}"; do
        for s in "${sweeps[@]}"; do
            echo "round $r: $c $s"
            "$out/src-$c/target/release/bench" "$s" ${BENCH_FLAGS:-} --out "$out/$c-r$r" >"$out/$c-r$r-$s.log"
        done
    done
done
python3 "$root/scripts/bench_compare.py" "$out" "$before" "$after" "$rounds" "${sweeps[@]}"
