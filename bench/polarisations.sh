#!/bin/sh
# Two polarisations against one, side by side (medians of paired runs, see paired_runs.py):
# the bass pop at 4 MHz with one polarisation, with two at 30 degrees without friction, and
# bass-pop-30 (two polarisations, 30 degrees, friction 0.3 at the frets).
# Usage: bench/polarisations.sh [build/cli/fretbuzz] [duration s] [repetitions]
set -e
program=${1:-build/cli/fretbuzz}
duration=${2:-1.0}
reps=${3:-5}
here=$(dirname "$0")
exec python3 "$here/paired_runs.py" --reps "$reps" \
    "one-polarisation=$program run bass-pop --duration $duration -q" \
    "two-30deg-no-friction=$program run bass-pop --polarisations 2 --angle 30 --duration $duration -q" \
    "bass-pop-30-friction=$program run bass-pop-30 --duration $duration -q"
