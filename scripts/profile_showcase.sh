#!/usr/bin/env bash
# Where the showcase's time goes: samples the headless tour with `perf record` (cpu-clock,
# user space) and sums the samples by engine stage and by ibr technique, from the symbols
# (the stage modules' functions are not inlined across the stage boundaries this groups by).
# Usage: scripts/profile_showcase.sh [SHOWCASE_BINARY] [FRAMES] [W] [H] [EXTRA SHOWCASE ARGS...]
# Prints a Markdown table: CPU seconds per group over the whole run (samples / 999 Hz, both
# threads, start-up included: the light field's capture and quantisation) and the share of
# all samples. Needs `perf` (perf_event_paranoid <= 2).
set -euo pipefail
BIN=${1:-${CARGO_TARGET_DIR:-target}/release/showcase}
FRAMES=${2:-60}; W=${3:-1280}; H=${4:-720}
shift $(( $# < 4 ? $# : 4 ))
OUT=$(mktemp -d)
perf record -q -F 999 -o "$OUT/perf.data" "$BIN" --headless "$OUT/frames" --frames "$FRAMES" \
  -W "$W" -H "$H" --no-save "$@" > "$OUT/run.txt" 2>&1
grep -E "frame time" "$OUT/run.txt" || true
perf report -i "$OUT/perf.data" --no-children --sort symbol --stdio -n 2>/dev/null \
  | grep -E '^ +[0-9.]+%' | python3 -c '
import re, sys
groups = [
    ("engine: vertex", r"engine::vertex::"),
    ("engine: clip, set up, bin", r"engine::(front|setup|clip|bin)::|Bins::"),
    ("engine: shade (GeneralShader)", r"GeneralShader"),
    ("engine: texture sampling", r"engine::texture::"),
    ("engine: raster (walk, depth, blend, Const/Color shading)", r"engine::raster::|engine::tile::TileBuf::(fill|touch|update|far)"),
    ("engine: resolve and tile load/clear", r"engine::tile::|engine::target::|engine::color::"),
    ("engine: image passes", r"engine::pass::|PackedPass|PixelPass"),
    ("engine: renderer glue", r"engine::renderer::"),
    ("ibr: light field (render and build)", r"ibr::lightfield::"),
    ("ibr: warp, LDI, portals", r"ibr::(warp|ldi|portal|images)"),
    ("ibr: impostors, clouds, billboards, layers", r"ibr::(impostor|cloud|billboard|layers|octahedral|sprites)"),
    ("ibr: metrics, other", r"ibr::"),
    ("demos", r"demos::"),
    ("kernel", r"\[k\]"),
]
tot = {}
for line in sys.stdin:
    m = re.match(r"\s+([0-9.]+)%\s+([0-9]+)\s+(.*)", line)
    if not m: continue
    pct, sym = float(m.group(2)), m.group(3)
    name = next((g for g, rx in groups if re.search(rx, sym)), "other (rayon, alloc, closures, libc)")
    tot[name] = tot.get(name, 0.0) + pct
all_ = sum(tot.values())
print("| where | CPU s | % of samples |\n|---|---:|---:|")
for g, _ in groups + [("other (rayon, alloc, closures, libc)", "")]:
    if g in tot: print(f"| {g} | {tot[g] / 999:.2f} | {100 * tot[g] / all_:.1f} |")
print(f"| all | {all_ / 999:.2f} | 100 |")
'
rm -rf "$OUT"
