#!/bin/sh
# Whole `fretbuzz run` commands of strings on a bridge, with every output (strings.csv, each
# string's WAV, the bridge's): sitar-taraf (the main string buzzing on its jawari, 13 taraf
# strings) at its 400 kHz, the tanpura case's rate, for 10 s (issue 46: under 1 s per
# simulated second on one core; the stepping runs on one thread), and guitar-chord at its
# 192 kHz. A baseline build runs side by side when given (medians of paired runs, see
# paired_runs.py; ratios are against the first variant).
# Usage: bench/strings_runs.sh [baseline fretbuzz] [this fretbuzz] [repetitions] [duration s]
#   e.g. bench/strings_runs.sh "" build/cli/fretbuzz 3 10
set -e
for name in sitar-taraf guitar-chord; do
    run="run $name --duration ${4:-10} --quiet"
    set -- "${1:-}" "${2:-build/cli/fretbuzz}" "${3:-3}" "${4:-10}"
    echo "$name, $4 s, every output:"
    if [ -n "$1" ]; then
        python3 "$(dirname "$0")/paired_runs.py" --reps "$3" --simulated "$4" "baseline-$name=$1 $run" "$name=$2 $run"
    else
        python3 "$(dirname "$0")/paired_runs.py" --reps "$3" --simulated "$4" "$name=$2 $run"
    fi
    echo
done
