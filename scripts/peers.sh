#!/usr/bin/env bash
# Times `render` against Mesa's llvmpipe on the peers' standard scenes, interleaved in one run,
# and prints a Markdown table (the one in BENCHMARKS.md). Needs ../shared/peers set up once
# (../shared/peers/setup.sh). Usage: scripts/peers.sh [ROUNDS] [FRAMES] [SCENES]
# SCENES: `all` (default), `vertex` (the vertex-colour scenes) or `textured` (the textured,
# lit torus of ../shared/peers/llvmpipe_textured.py: one 1024x1024 base-colour texture with
# trilinear mipmaps, one directional light; `render --shading textured --peer-light`). The
# textured table also gives each pair of images' PSNR over the frame (llvmpipe as reference).
set -euo pipefail
cd "$(dirname "$0")/.."
P=../shared/peers
PY=${PEERS_VENV:-$P/.venv}/bin/python
ROUNDS=${1:-3}
FRAMES=${2:-20}
WHICH=${3:-all}
mkdir -p out/scenes
# RENDER=path/to/render times that binary instead of building one (the target folder may be
# shared with other worktrees, whose builds would replace the binary mid-run).
if [ -z "${RENDER:-}" ]; then
  cargo build --release -q --bin render
  RENDER=${CARGO_TARGET_DIR:-target}/release/render
fi
median() { sort -n | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
ms() { tail -1 | sed -n 's/.*median_ms=\([0-9.]*\).*/\1/p'; }
scenes="torus:10k torus:100k torus:1m torus:2m grid:1m confetti:100k huge:64"
[ "$WHICH" = textured ] && scenes=""
for s in $scenes; do
  kind=${s%%:*}; n=${s##*:}; f=out/scenes/${kind}_${n}.obj
  [ -f "$f" ] || $PY $P/make_scenes.py "$kind" "$n" -o "$f" 2>/dev/null
done
[ -n "$scenes" ] && printf '| scene | size | llvmpipe ms | parallax ms | ratio |\n|---|---|---:|---:|---:|\n'
for s in $scenes; do
  kind=${s%%:*}; n=${s##*:}; f=out/scenes/${kind}_${n}.obj
  for size in "640 480" "1920 1080"; do
    set -- $size
    lp=(); me=()
    for r in $(seq "$ROUNDS"); do
      lp+=("$($PY $P/llvmpipe_render.py --obj "$f" -W "$1" -H "$2" --threads 2 --frames "$FRAMES" --shading vertex --quiet 2>/dev/null | tail -1 | sed -n 's/.*median_ms=\([0-9.]*\).*/\1/p')")
      me+=("$("$RENDER" --obj "$f" -W "$1" -H "$2" --threads 2 --frames "$FRAMES" --shading vertex 2>/dev/null | tail -1 | sed -n 's/.*median_ms=\([0-9.]*\).*/\1/p')")
    done
    a=$(printf '%s\n' "${lp[@]}" | median); b=$(printf '%s\n' "${me[@]}" | median)
    printf '| %s %s | %sx%s | %.2f | %.2f | %.2f |\n' "$kind" "$n" "$1" "$2" "$a" "$b" "$(echo "$b / $a" | bc -l)"
  done
done
[ "$WHICH" = vertex ] && exit 0

# Textured and lit: the peer writes the scene once (OBJ + MTL + PNG), then both draw it.
psnr() {
  $PY - "$1" "$2" <<'PYEOF'
import sys, numpy as np
from PIL import Image
a, b = (np.asarray(Image.open(p).convert("RGB"), dtype=np.float64) for p in sys.argv[1:3])
mse = ((a - b) ** 2).mean()
print(f"{10 * np.log10(255.0 ** 2 / mse):.1f}" if mse > 0 else "inf")
PYEOF
}
printf '\n| textured scene | size | llvmpipe ms | parallax ms | ratio | PSNR dB |\n|---|---|---:|---:|---:|---:|\n'
for n in 10k 100k; do
  d=out/scenes/tex_$n
  if [ ! -f "$d/scene.obj" ]; then
    # The peer's faces are wound clockwise as seen from the side their normals face; GL draws
    # them unculled and lights them by the normals as given, while `render` culls back faces
    # and flips the normals of the back faces it draws (two-sided lighting). Written
    # counter-clockwise, the same triangles are front faces for `render` too.
    $PY $P/llvmpipe_textured.py --triangles "$n" --write "$d" >/dev/null
    awk '$1 == "f" { print "f", $2, $4, $3; next } { print }' "$d/scene.obj" > "$d/ccw.obj"
    mv "$d/ccw.obj" "$d/scene.obj"
  fi
  for size in "1280 720" "1920 1080"; do
    set -- $size
    lp=(); me=()
    for r in $(seq "$ROUNDS"); do
      lp+=("$($PY $P/llvmpipe_textured.py --triangles "$n" -W "$1" -H "$2" --threads 2 --frames "$FRAMES" --png "$d/llvmpipe_$1.png" 2>/dev/null | ms)")
      me+=("$("$RENDER" --obj "$d/scene.obj" --shading textured --peer-light -W "$1" -H "$2" --threads 2 --frames "$FRAMES" --out "$d/parallax_$1.png" 2>/dev/null | ms)")
    done
    a=$(printf '%s\n' "${lp[@]}" | median); b=$(printf '%s\n' "${me[@]}" | median)
    printf '| torus %s | %sx%s | %.2f | %.2f | %.2f | %s |\n' "$n" "$1" "$2" "$a" "$b" "$(echo "$b / $a" | bc -l)" "$(psnr "$d/llvmpipe_$1.png" "$d/parallax_$1.png")"
  done
done
