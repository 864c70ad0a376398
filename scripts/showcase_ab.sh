#!/usr/bin/env bash
# Alternates two showcase binaries on the 120-frame tour alone, so the machine's drift hits
# both alike; per run prints the load, the tour line of the summary (median, p90, p99, max),
# the frames over 50 ms (from DIR/tour_times.csv) and the clouds' attraction line.
#
#   scripts/showcase_ab.sh OLD_BINARY NEW_BINARY WIDTH HEIGHT [ROUNDS] [OUT]
set -euo pipefail
old=$1 new=$2 w=$3 h=$4 rounds=${5:-3} out=${6:-/tmp/showcase_ab}
mkdir -p "$out"
for r in $(seq 1 "$rounds"); do
  for b in old new; do
    bin=$old; [ "$b" = new ] && bin=$new
    d="$out/$b-${w}x$h-r$r"
    load=$(cut -d' ' -f1 /proc/loadavg)
    "$bin" --headless "$d" --frames 120 --building-frames 0 --views-frames 0 \
      --world-frames 0 -W "$w" -H "$h" --no-save > "$d.log" 2>&1
    over=$(python3 -c "import csv,sys; print(sum(float(r['ms']) > 50 for r in csv.DictReader(open(sys.argv[1]))))" "$d/tour_times.csv")
    echo "$b ${w}x$h round $r, load $load: $(grep 'tour:' "$d.log" | sed 's/.*tour: //'), over 50 ms: $over; clouds $(grep 'clouds (' "$d.log" | sed 's/.*tour): //')"
  done
done
