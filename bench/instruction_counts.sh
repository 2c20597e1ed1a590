#!/bin/sh
# Two builds' benchmarks side by side in instructions executed (valgrind's callgrind), a count
# that the shared machine's load does not move: where two builds' timings differ by less than
# the noise, this says which one does more work. It is not a time (a division or a cache miss
# counts as one instruction), so quote it beside the timings, not instead of them.
# Usage: bench/instruction_counts.sh <baseline fretbuzz_bench> [this fretbuzz_bench] [filter]
#   e.g. bench/instruction_counts.sh /tmp/base/build/bench/fretbuzz_bench build/bench/fretbuzz_bench '^Fast/flat-obstacle/'
# The filter picks Google Benchmark runs (default: the flat obstacle's whole 4 s run); both
# builds run the same benchmark (about two minutes each under valgrind for the default). Needs
# valgrind (Debian package valgrind).
set -e
baseline=${1:?usage: instruction_counts.sh baseline-fretbuzz_bench [fretbuzz_bench] [filter]}
program=${2:-build/bench/fretbuzz_bench}
filter=${3:-'^Fast/flat-obstacle/'}
command -v valgrind > /dev/null || { echo "instruction_counts.sh: valgrind is not installed (apt-get install valgrind)" >&2; exit 2; }
count() {
    valgrind --tool=callgrind --callgrind-out-file=/dev/null "$1" --benchmark_filter="$filter" 2>&1 |
        sed -n 's/.*Collected : \([0-9]*\).*/\1/p'
}
old=$(count "$baseline")
new=$(count "$program")
[ -n "$old" ] && [ -n "$new" ] || { echo "instruction_counts.sh: no count (does the filter match a benchmark?)" >&2; exit 1; }
python3 -c "import sys; o, n = int(sys.argv[1]), int(sys.argv[2]); print(f'{sys.argv[3]}: {o:,} -> {n:,} instructions ({n / o:.3f}x)')" "$old" "$new" "$filter"
