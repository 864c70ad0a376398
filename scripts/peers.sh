#!/usr/bin/env bash
# Times `render` against Mesa's llvmpipe on the peers' standard scenes, interleaved in one run,
# and prints a Markdown table (the one in BENCHMARKS.md). Needs ../shared/peers set up once
# (../shared/peers/setup.sh). Usage: scripts/peers.sh [ROUNDS] [FRAMES]
set -euo pipefail
cd "$(dirname "$0")/.."
P=../shared/peers
PY=${PEERS_VENV:-$P/.venv}/bin/python
ROUNDS=${1:-3}
FRAMES=${2:-20}
mkdir -p out/scenes
cargo build --release -q --bin render
scenes="torus:10k torus:100k torus:1m torus:2m grid:1m confetti:100k huge:64"
for s in $scenes; do
  kind=${s%%:*}; n=${s##*:}; f=out/scenes/${kind}_${n}.obj
  [ -f "$f" ] || $PY $P/make_scenes.py "$kind" "$n" -o "$f" 2>/dev/null
done
median() { sort -n | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
printf '| scene | size | llvmpipe ms | parallax ms | ratio |\n|---|---|---:|---:|---:|\n'
for s in $scenes; do
  kind=${s%%:*}; n=${s##*:}; f=out/scenes/${kind}_${n}.obj
  for size in "640 480" "1920 1080"; do
    set -- $size
    lp=(); me=()
    for r in $(seq "$ROUNDS"); do
      lp+=("$($PY $P/llvmpipe_render.py --obj "$f" -W "$1" -H "$2" --threads 2 --frames "$FRAMES" --shading vertex --quiet 2>/dev/null | tail -1 | sed -n 's/.*median_ms=\([0-9.]*\).*/\1/p')")
      me+=("$(target/release/render --obj "$f" -W "$1" -H "$2" --threads 2 --frames "$FRAMES" --shading vertex 2>/dev/null | tail -1 | sed -n 's/.*median_ms=\([0-9.]*\).*/\1/p')")
    done
    a=$(printf '%s\n' "${lp[@]}" | median); b=$(printf '%s\n' "${me[@]}" | median)
    printf '| %s %s | %sx%s | %.2f | %.2f | %.2f |\n' "$kind" "$n" "$1" "$2" "$a" "$b" "$(echo "$b / $a" | bc -l)"
  done
done
