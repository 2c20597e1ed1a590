#!/bin/sh
# Whole `fretbuzz run` commands at an audio rate with every output file (CSV, WAV, HDF5,
# summary): tanpura and sitar at 48 kHz (the modes below fs/2) for 10 s, and for 1 ms (what
# a run costs whatever its length: starting the process, reading the case, planning, creating
# and committing the files). A baseline build runs side by side with this one when given
# (medians of paired runs, see paired_runs.py; ratios are against the first variant).
# Usage: bench/audio_rate_runs.sh [baseline fretbuzz] [this fretbuzz] [repetitions] [duration s]
#   e.g. bench/audio_rate_runs.sh /tmp/base/build/cli/fretbuzz build/cli/fretbuzz 7
set -e
baseline=${1:-}
program=${2:-build/cli/fretbuzz}
reps=${3:-7}
duration=${4:-10}
here=$(dirname "$0")
for name in tanpura sitar; do
    for length in "$duration" 0.001; do
        set --
        [ -n "$baseline" ] && set -- "baseline-$name-${length}s=$baseline run $name --fs 48000 --duration $length -q"
        set -- "$@" "$name-${length}s=$program run $name --fs 48000 --duration $length -q"
        echo "$name, 48 kHz, $length s, every output:"
        python3 "$here/paired_runs.py" --reps "$reps" "$@"
        echo
    done
done
