#!/bin/sh
# Times velvet against the tools it is compared with, on generated libraries: the Khronos
# glTF-Validator and glTF-Transform (npm, versions pinned in benches/anchors/package.json).
# Run on a machine with nothing else running. Each command runs once to warm up (not counted),
# then RUNS times in a row (default 7), as hyperfine does; with ORDER=rounds the commands run
# in rounds instead, each round running every command once, each velvet command right before
# the one it is compared with. For each command the median wall time, the fastest and slowest
# run and the largest peak memory are printed, then each comparison's ratio of medians, then
# the ratio of each output format's median to --format json's on the minified library and on
# its migrated output (one line of JSON each: every finding's column is counted along the whole
# text), then the share of the processor time the runs asked for that the host held back ("steal" in
# /proc/stat: on a virtual machine, the time its processors waited for the host's; near 0 on
# a quiet host).
#
#   sh benches/anchors.sh [WORK_DIR]
#   ORDER=rounds RUNS=9 sh benches/anchors.sh [WORK_DIR]
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
work=${1:-/tmp/velvet-anchors}
runs=${RUNS:-7}
order=${ORDER:-repeat}
case $order in
repeat | rounds) ;;
*)
    echo "ORDER is repeat or rounds, not $order" >&2
    exit 2
    ;;
esac
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
[ -f "$work/min/library.gltf" ] || "$corpus" --minified-library "$work/min" > /dev/null
# A valid document whose weight is in its data (67 MB of meshes, skins and keyframes).
[ -f "$work/data/data.gltf" ] || "$corpus" --data-library "$work/data" > /dev/null
# The minified library migrated (a fuzz and a note on each of its 20,000 materials); migrate
# keeps the layout, so it is one line too.
[ -f "$work/min-migrated/library.gltf" ] ||
    "$velvet" migrate -q --fast "$work/min/library.gltf" --out-dir "$work/min-migrated" > /dev/null

# The commands, by number: label, then the command line.
count=26
# validate's output formats on the minified library (10-13) and its migrated output (14-17);
# the data library (18-20); the findings-heavy 20,000-material document in the formats other
# than json (21-23; json is 2); migrate's other speed path (24); validate on the library that
# migrate converts, nearly clean (two fixable hints, two data errors), beside the reference
# (25-26).
formats="json text github sarif"
format_of() {
    n=$(( ($1 - 10) % 4 ))
    set -- $formats
    shift "$n"
    echo "$1"
}
command_of() {
    case $1 in
    1) echo "velvet validate, 5000 materials" ;;
    2) echo "velvet validate, 20000 materials" ;;
    3) echo "Khronos validator, 20000 materials" ;;
    4) echo "velvet validate, 80000 materials" ;;
    5) echo "velvet validate, 500 small files" ;;
    6) echo "Khronos validator, 500 small files" ;;
    7) echo "velvet migrate --fast, library" ;;
    8) echo "gltf-transform copy, library" ;;
    9) echo "velvet migrate, library" ;;
    1[0-3]) echo "velvet validate --format $(format_of "$1"), minified library" ;;
    1[4-7]) echo "velvet validate --format $(format_of "$1"), minified library migrated" ;;
    18) echo "velvet validate, data library" ;;
    19) echo "Khronos validator, data library" ;;
    20) echo "velvet validate --no-data, data library" ;;
    21) echo "velvet validate --format text, 20000 materials" ;;
    22) echo "velvet validate --format github, 20000 materials" ;;
    23) echo "velvet validate --format sarif, 20000 materials" ;;
    24) echo "velvet migrate --roughness identity, library" ;;
    25) echo "velvet validate, library" ;;
    26) echo "Khronos validator, library" ;;
    esac
}
# timed COMMAND...: runs it under time(1), which writes its peak memory (KiB) to time1.
timed() {
    /usr/bin/time -f "%M" -o "$work/time1" "$@"
}
run_command() {
    case $1 in
    1) timed "$velvet" validate --format json "$work/m5000/large.gltf" ;;
    2) timed "$velvet" validate --format json "$work/m20000/large.gltf" ;;
    3) timed node "$anchors/validate.js" "$work/m20000/large.gltf" ;;
    4) timed "$velvet" validate --format json "$work/m80000/large.gltf" ;;
    5) timed "$velvet" validate --format json "$work/m20000/small" ;;
    6) timed node "$anchors/validate.js" "$work/m20000/small" ;;
    7) timed "$velvet" migrate -q --fast "$work/lib/library.gltf" --out-dir "$work/out" ;;
    8) timed "$anchors/node_modules/.bin/gltf-transform" copy "$work/lib/library.gltf" "$work/out/library.gltf" ;;
    9) timed "$velvet" migrate -q "$work/lib/library.gltf" --out-dir "$work/out" ;;
    1[0-3]) timed "$velvet" validate --format "$(format_of "$1")" "$work/min/library.gltf" ;;
    1[4-7]) timed "$velvet" validate --format "$(format_of "$1")" "$work/min-migrated/library.gltf" ;;
    18) timed "$velvet" validate --format json "$work/data/data.gltf" ;;
    19) timed node "$anchors/validate.js" "$work/data/data.gltf" ;;
    20) timed "$velvet" validate --format json --no-data "$work/data/data.gltf" ;;
    21) timed "$velvet" validate --format text "$work/m20000/large.gltf" ;;
    22) timed "$velvet" validate --format github "$work/m20000/large.gltf" ;;
    23) timed "$velvet" validate --format sarif "$work/m20000/large.gltf" ;;
    24) timed "$velvet" migrate -q --roughness identity "$work/lib/library.gltf" --out-dir "$work/out" ;;
    25) timed "$velvet" validate --format json "$work/lib/library.gltf" ;;
    26) timed node "$anchors/validate.js" "$work/lib/library.gltf" ;;
    esac
}

# measure N [RECORD]: runs command N once and adds its wall time (microseconds, read with
# nanosecond clocks around the command: time(1) prints hundredths, a sixth of a 60 ms run) and
# its peak memory to RECORD (default: the command's record).
measure() {
    rm -rf "$work/out" && mkdir -p "$work/out"
    # velvet validate exits 1 when it finds errors (the generated files have some); any other
    # failure means the figure would not measure the job, so the run stops.
    status=0
    start=$(date +%s%N)
    run_command "$1" > /dev/null 2> "$work/stderr" || status=$?
    end=$(date +%s%N)
    if [ "$status" -gt 1 ]; then
        echo "$(command_of "$1"): exit status $status" >&2
        cat "$work/stderr" >&2
        exit 1
    fi
    echo "$(( (end - start) / 1000 )) $(tail -n 1 "$work/time1")" >> "${2:-$work/times.$1}"
}

# The processor time the host took (steal) and the time the processors wanted (busy: steal
# included, idle and waiting for the disk not), so far, in ticks.
cpu_ticks() {
    awk '/^cpu / { print $9, $2 + $3 + $4 + $7 + $8 + $9 }' /proc/stat
}

i=1
while [ $i -le $count ]; do
    : > "$work/times.$i"
    i=$((i + 1))
done
set -- $(cpu_ticks)
steal_before=$1 busy_before=$2
if [ "$order" = rounds ]; then
    round=0
    while [ $round -lt "$runs" ]; do
        i=1
        while [ $i -le $count ]; do
            measure $i
            i=$((i + 1))
        done
        round=$((round + 1))
    done
else
    i=1
    while [ $i -le $count ]; do
        measure $i "$work/warm-up"
        round=0
        while [ $round -lt "$runs" ]; do
            measure $i
            round=$((round + 1))
        done
        i=$((i + 1))
    done
fi
set -- $(cpu_ticks)
steal_ticks=$(($1 - steal_before)) busy_ticks=$(($2 - busy_before))

# median N: the median wall time (seconds) of command N.
median() {
    sort -n "$work/times.$1" | awk '{ wall[NR] = $1 / 1e6 } END { printf "%.3f", wall[int((NR + 1) / 2)] }'
}

echo "| command | median wall | fastest – slowest | peak memory |"
echo "|---|---|---|---|"
i=1
while [ $i -le $count ]; do
    sort -n "$work/times.$i" | awk -v label="$(command_of $i)" -v wall="$(median $i)" '
        { if (NR == 1) low = $1 / 1e6; high = $1 / 1e6; if ($2 > mem) mem = $2 }
        END { printf "| %s | %s s | %.3f – %.3f s | %d MiB |\n", label, wall, low, high, mem / 1024 }'
    i=$((i + 1))
done
echo
echo "| comparison | velvet | the other tool | velvet is faster by |"
echo "|---|---|---|---|"
for pair in "2 3" "25 26" "5 6" "7 8" "24 8" "18 19"; do
    set -- $pair
    awk -v label="$(command_of "$1") / $(command_of "$2")" -v a="$(median "$1")" -v b="$(median "$2")" \
        'BEGIN { printf "| %s | %s s | %s s | %.1f× |\n", label, a, b, b / a }'
done
echo
echo "| validate output format | minified library | × json | minified library migrated | × json |"
echo "|---|---|---|---|---|"
for offset in 0 1 2 3; do
    a=$((10 + offset)) b=$((14 + offset))
    awk -v label="$(format_of $a)" -v a="$(median $a)" -v a0="$(median 10)" -v b="$(median $b)" -v b0="$(median 14)" \
        'BEGIN { printf "| %s | %s s | %.2f× | %s s | %.2f× |\n", label, a, a / a0, b, b / b0 }'
done
echo
# The findings-heavy document (13,333 errors, 10,291 warnings, 17,000 fixes tried) in every
# format, against --format text.
echo "| validate output format, 20000 materials | median | × text |"
echo "|---|---|---|"
for n in 21 2 22 23; do
    label=$(command_of "$n" | sed 's/.*--format \([a-z]*\).*/\1/')
    [ "$n" = 2 ] && label=json
    awk -v label="$label" -v a="$(median $n)" -v t="$(median 21)" \
        'BEGIN { printf "| %s | %s s | %.2f× |\n", label, a, a / t }'
done
echo
awk -v s="$steal_ticks" -v t="$busy_ticks" -v rounds="$runs" \
    -v order="$order" \
    'BEGIN { printf "%d runs a command (order: %s); the host held back %.1f %% of the processor time they asked for (steal)\n", rounds, order, (t > 0 ? 100 * s / t : 0) }'
