#!/bin/sh
# Remeasures every figure of docs/performance.md's table, one command per target,
# each run once, its raw output under a heading that names the target. No baseline: to say
# what a change gained, run the same command of two builds side by side (docs/performance.md).
# Usage: bench/targets.sh [build dir] [repetitions]
#   e.g. nice -n 19 sh bench/targets.sh build 5
# Repetitions: of each contact-step row (--contact N), of each Google Benchmark set
# (at least 2, so that a median is reported) and of the paired CLI runs. The real-time
# benchmark always takes the median of its own 5 repetitions.
set -e
build=${1:-build}
reps=${2:-5}
bench_reps=$reps
[ "$bench_reps" -lt 2 ] && bench_reps=2
bench="$build/bench/fretbuzz_bench"
realtime="$build/bench/fretbuzz_bench_realtime"
plain=--benchmark_color=false
here=$(dirname "$0")
for program in "$bench" "$realtime" "$build/cli/fretbuzz"; do
    [ -x "$program" ] || { echo "targets.sh: $program not found (build it first)" >&2; exit 2; }
done

heading() {
    echo
    echo "=== $1"
    echo "--- $2"
}

heading "Whole run and contact window against the dense transcription (bass pop, flat obstacle)" \
    "fretbuzz_bench --benchmark_filter='^(Fast|Straightforward|Window|Dense)/' --benchmark_repetitions=$bench_reps"
"$bench" --benchmark_filter='^(Fast|Straightforward|Window|Dense)/' --benchmark_repetitions="$bench_reps" \
    --benchmark_report_aggregates_only=true "$plain"

heading "Outputs: 3 s bass pop with every output <= 0.5 s, and <= 1.2x the run with none" \
    "fretbuzz_bench --benchmark_filter='(Outputs|None)/bass-pop-3s' --benchmark_repetitions=$bench_reps"
"$bench" --benchmark_filter='(Outputs|None)/bass-pop-3s' --benchmark_repetitions="$bench_reps" \
    --benchmark_report_aggregates_only=true "$plain"

heading "Contact steps: bass-pop contact window <= 2.5 us per step" \
    "fretbuzz_bench --contact $reps \"bass-pop, 4 MHz, 862 modes, window\""
"$bench" --contact "$reps" "bass-pop, 4 MHz, 862 modes, window"

heading "Contact steps: flat-obstacle onset step <= 15 us" \
    "fretbuzz_bench --contact $reps onset"
"$bench" --contact "$reps" onset

heading "Audio rates: 120-mode sitar bridge at 48 kHz, stepping only, <= 0.01 s per simulated second" \
    "fretbuzz_bench --contact $reps \"sitar bridge\""
"$bench" --contact "$reps" "sitar bridge"

heading "Audio rates: tanpura and sitar, 48 kHz, 10 s CLI run with every output, <= 0.05 s per simulated second" \
    "sh bench/audio_rate_runs.sh \"\" $build/cli/fretbuzz $reps"
sh "$here/audio_rate_runs.sh" "" "$build/cli/fretbuzz" "$reps"

heading "Strings on a bridge: sitar-taraf, 400 kHz, 10 s with every output, < 1 s per simulated second (and its parts)" \
    "sh bench/strings_runs.sh \"\" $build/cli/fretbuzz $reps 10; bench/sitar_taraf_parts.py --reps $reps"
sh "$here/strings_runs.sh" "" "$build/cli/fretbuzz" "$reps" 10
python3 "$here/sitar_taraf_parts.py" --reps "$reps" --program "$build/cli/fretbuzz"

heading "A fretted note: fretted pop within 2x of the open pop" \
    "fretbuzz_bench --benchmark_filter=Played --benchmark_repetitions=$bench_reps"
"$bench" --benchmark_filter=Played --benchmark_repetitions="$bench_reps" --benchmark_report_aggregates_only=true "$plain"

heading "Real time: tanpura and sitar >= 50x, bass fret 5 >= 10x, worst 256-sample block < 25 %" \
    "fretbuzz_bench_realtime --benchmark_filter='^(tanpura|sitar|bass_fret5)/(engine|stopped_string)'"
"$realtime" --benchmark_filter='^(tanpura|sitar|bass_fret5)/(engine|stopped_string)' "$plain"

heading "Floors: one step's pass alone for a fretted pop (the 2x target) and a voice at 8x (the 50x target)" \
    "fretbuzz_bench --contact $reps finger; fretbuzz_bench --contact $reps \"x (the\""
"$bench" --contact "$reps" finger
"$bench" --contact "$reps" "x (the"

heading "Real time: tanpura and sitar at 1x (the modes below 24 kHz)" \
    "fretbuzz_bench_realtime --benchmark_filter='^(tanpura|sitar)_M1/engine'"
"$realtime" --benchmark_filter='^(tanpura|sitar)_M1/engine' "$plain"

heading "Real time: six voices (a guitar chord) in real time on one core" \
    "fretbuzz_bench_realtime --benchmark_filter='^guitar_chord_6_voices(_M4)?/(engine|stopped_string)'"
"$realtime" --benchmark_filter='^guitar_chord_6_voices(_M4)?/(engine|stopped_string)' "$plain"
