#!/usr/bin/env bash
# Long fuzzing runs of every parser of a user's bytes (libFuzzer through cargo-fuzz), two
# targets at a time.
#
#   fuzz/run.sh                    # every target, 10 million executions each
#   RUNS=100000 fuzz/run.sh obj    # one target, fewer executions
#   MAX_LEN=65536 fuzz/run.sh      # longer inputs (default 16384 bytes)
#
# A target stops on a crash, an input taking over 1 s, or over 1 GiB of memory; the input
# is saved under fuzz/artifacts/<target>/ and the summary line says CRASH. New inputs
# collect in fuzz/scratch/<target>/ (kept between runs, so a rerun resumes from them); at
# the end those that reach new code are merged into fuzz/corpus/<target>/, which the test
# suite replays (tests/tests/fuzz_corpus.rs). The repository keeps a sample of it: the
# seeds, the regressions, and up to KEEP (default 300) inputs of at most 2 KiB, chosen by
# name (their hashes), so the replay stays seconds long and the repository small. Works on stable Rust: RUSTC_BOOTSTRAP lets
# cargo-fuzz pass its flags, and `-s none` skips the sanitizers (they need a nightly
# standard library). Extra seeds come from ../shared/assets when it is there; they are
# read, never merged into the repository's corpus.
set -uo pipefail
cd "$(dirname "$0")"
RUNS=${RUNS:-10000000}
MAX_LEN=${MAX_LEN:-16384} # bytes; longer inputs mostly repeat statements and run slowly
KEEP=${KEEP:-300}
TARGETS=("$@")
[ ${#TARGETS[@]} -eq 0 ] && TARGETS=(obj gltf glb image float_image transforms)
command -v cargo-fuzz >/dev/null || cargo install cargo-fuzz --locked || exit 1
export RUSTC_BOOTSTRAP=1
cargo fuzz build -s none || exit 1

shared_seeds() {
    local t=$1 out=$2 assets=../../shared/assets
    [ -d "$assets" ] || return 0
    case $t in
        obj) find "$assets" -iname '*.obj' -size -2M ;;
        gltf) find "$assets" -iname '*.gltf' -size -2M ;;
        glb) find "$assets" -iname '*.glb' -size -2M ;;
        image) find "$assets" \( -iname '*.png' -o -iname '*.jpg' -o -iname '*.jpeg' \) -size -512k ;;
        float_image) find "$assets" \( -iname '*.pfm' -o -iname '*.exr' \) -size -2M ;;
        transforms) find "$assets" -iname 'transforms*.json' -size -2M ;;
    esac | head -50 | while read -r f; do cp "$f" "$out/shared-$(basename "$f")"; done
}

# Keeps seeds, regressions and the first KEEP small inputs (by name) of a corpus folder.
prune() {
    local dir=$1
    find "$dir" -type f ! -name 'seed-*' ! -name 'regress-*' -size +2k -delete
    find "$dir" -type f ! -name 'seed-*' ! -name 'regress-*' -printf '%f\n' | sort |
        tail -n +$((KEEP + 1)) | while read -r f; do rm -f "$dir/$f"; done
}

run_one() {
    local t=$1 scratch=scratch/$1 log=logs/$1.log status
    mkdir -p logs "artifacts/$t" "$scratch"
    shared_seeds "$t" "$scratch"
    cargo fuzz run -s none "$t" "$scratch" "corpus/$t" -- \
        -runs="$RUNS" -timeout=1 -rss_limit_mb=1024 -max_len="$MAX_LEN" \
        -artifact_prefix="artifacts/$t/" -print_final_stats=1 >"$log" 2>&1
    status=$?
    # Keep only inputs that reach new code (libFuzzer's merge); the shared assets
    # themselves stay out of the repository.
    rm -f "$scratch"/shared-*
    cargo fuzz run -s none "$t" "corpus/$t" "$scratch" -- -merge=1 >>"$log" 2>&1
    prune "corpus/$t"
    local runs secs
    runs=$(grep -E '^stat::number_of_executed_units' "$log" | tail -1 | awk '{print $2}')
    secs=$(grep -E '^Done [0-9]+ runs in' "$log" | tail -1 | awk '{print $5}')
    if [ "$status" -eq 0 ]; then
        echo "$t: ok, ${runs:-?} executions in ${secs:-?} s"
    else
        echo "$t: CRASH after ${runs:-?} executions (exit $status): see $log and artifacts/$t/"
    fi
}

# Two at a time: the next target starts as soon as one finishes.
for t in "${TARGETS[@]}"; do
    while [ "$(jobs -rp | wc -l)" -ge 2 ]; do wait -n || true; done
    run_one "$t" &
done
wait
