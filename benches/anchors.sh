#!/bin/sh
# Times velvet against the tools it is compared with, on generated libraries: the Khronos
# glTF-Validator and glTF-Transform (npm, versions pinned in benches/anchors/package.json).
# Run on a machine with nothing else running; each command runs RUNS times (default 5) and the
# median wall time and largest peak memory are printed.
#
#   sh benches/anchors.sh [WORK_DIR]
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
work=${1:-/tmp/velvet-anchors}
runs=${RUNS:-5}
velvet="$root/target/release/velvet"
corpus="$root/target/release/examples/corpus"
anchors="$root/benches/anchors"

(cd "$root" && cargo build --release --locked --quiet && cargo build --release --locked --quiet --example corpus)
[ -d "$anchors/node_modules" ] || (cd "$anchors" && npm install --no-audit --no-fund --silent)
mkdir -p "$work"
for n in 5000 20000 80000; do
    [ -f "$work/m$n/large.gltf" ] || "$corpus" "$work/m$n" "$n" 500 > /dev/null
done
[ -f "$work/lib/library.gltf" ] || "$corpus" --library "$work/lib" > /dev/null

# measure LABEL COMMAND...: median wall seconds and largest peak KiB over $runs runs. The wall
# time is read with nanosecond clocks around the command (time(1) prints hundredths only, a
# sixth of a 60 ms run); the peak memory comes from time(1).
measure() {
    label=$1
    shift
    i=0
    : > "$work/times"
    while [ $i -lt "$runs" ]; do
        rm -rf "$work/out" && mkdir -p "$work/out"
        # velvet validate exits 1 when it finds errors (the generated files have some); any
        # other failure means the figure would not measure the job, so the run stops.
        status=0
        start=$(date +%s%N)
        /usr/bin/time -f "%M" -o "$work/time1" "$@" > /dev/null 2> "$work/stderr" || status=$?
        end=$(date +%s%N)
        if [ "$status" -gt 1 ]; then
            echo "$label: exit status $status" >&2
            cat "$work/stderr" >&2
            exit 1
        fi
        echo "$(( (end - start) / 1000 )) $(tail -n 1 "$work/time1")" >> "$work/times"
        i=$((i + 1))
    done
    sort -n "$work/times" | awk -v label="$label" '
        { wall[NR] = $1 / 1e6; if ($2 > mem) mem = $2 }
        END { printf "| %s | %.3f s | %d MiB |\n", label, wall[int((NR + 1) / 2)], mem / 1024 }'
}

echo "| command | median wall | peak memory |"
echo "|---|---|---|"
for n in 5000 20000 80000; do
    measure "velvet validate, $n materials" "$velvet" validate --format json "$work/m$n/large.gltf"
done
measure "Khronos validator, 20000 materials" node "$anchors/validate.js" "$work/m20000/large.gltf"
measure "velvet validate, 500 small files" "$velvet" validate --format json "$work/m20000/small"
measure "Khronos validator, 500 small files" node "$anchors/validate.js" "$work/m20000/small"
measure "velvet migrate --fast, library" "$velvet" migrate -q --fast "$work/lib/library.gltf" --out-dir "$work/out"
measure "velvet migrate, library" "$velvet" migrate -q "$work/lib/library.gltf" --out-dir "$work/out"
measure "gltf-transform copy, library" "$anchors/node_modules/.bin/gltf-transform" copy "$work/lib/library.gltf" "$work/out/library.gltf"
