#!/bin/sh
# Two builds' CSV outputs side by side: each case run by both, then the relative L2 difference
# ||new - old|| / ||old|| of every column of every CSV file (time columns excluded), and the
# largest of them per case, and the contact steps of each run's summary, which must be the
# same. A change meant to move results only by round-off must keep every figure far below 1e-12.
# Usage: bench/compare_runs.sh [--all] <baseline fretbuzz> [this fretbuzz] [scratch directory]
#   e.g. bench/compare_runs.sh /tmp/base/build/cli/fretbuzz build/cli/fretbuzz
# Without --all: four cases at 48 kHz and at their own rate; with --all: every built-in case
# (`fretbuzz cases`) at its own rate, for 0.2 s or as long as its contacts need, and the
# fretted pop with a second plucker and a force gesture.
set -e
all=
if [ "${1:-}" = --all ]; then all=1; shift; fi
baseline=${1:?usage: compare_runs.sh [--all] baseline-fretbuzz [fretbuzz] [scratch]}
program=${2:-build/cli/fretbuzz}
scratch=${3:-$(mktemp -d)}
run_case() {  # name, then extra options
    name=$1
    shift
    tag=$(echo "$name $*" | tr -c 'a-z0-9.\n' '_')
    "$baseline" run "$name" "$@" -q --out "$scratch/$tag-old" 2>/dev/null
    "$program" run "$name" "$@" -q --out "$scratch/$tag-new" 2>/dev/null
    python3 - "$scratch/$tag-old" "$scratch/$tag-new" "$name $*" <<'EOF'
import csv, json, math, pathlib, sys
old, new, what = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2]), sys.argv[3]
worst = 0.0
summaries = [json.load(open(d / "summary.json")) for d in (old, new)]
for key in ("contact_steps", "finger_contact_steps"):
    if summaries[0].get(key) != summaries[1].get(key):
        print(f"{what}: {key} {summaries[0].get(key)} -> {summaries[1].get(key)}: different")
        sys.exit(1)
print(f"{what}: contact steps {summaries[0].get('contact_steps')} in both")
for path in sorted(old.glob("*.csv")):
    rows_old = list(csv.reader(open(path)))
    rows_new = list(csv.reader(open(new / path.name)))
    if len(rows_old) != len(rows_new) or rows_old[0] != rows_new[0]:
        print(f"{what}: {path.name}: different shapes")
        sys.exit(1)
    columns = {column: [float(r[c]) for r in rows_old[1:]] for c, column in enumerate(rows_old[0])}
    largest = max(math.sqrt(sum(v * v for v in x)) for name, x in columns.items() if not name.startswith("t_"))
    for c, column in enumerate(rows_old[0]):
        if column.startswith("t_"):
            continue
        x = columns[column]
        y = [float(r[c]) for r in rows_new[1:]]
        norm = math.sqrt(sum(v * v for v in x))
        diff = math.sqrt(sum((u - v) ** 2 for u, v in zip(x, y)))
        if norm < 1e-9 * largest:  # a quantity that is zero but for round-off (a lossless run's losses)
            print(f"  {path.name:24s} {column:28s} zero but for round-off (norm {norm:.1e}): left out")
            continue
        rel = diff / norm if norm > 0 else diff
        worst = max(worst, rel)
        print(f"  {path.name:24s} {column:28s} {rel:.3e}")
print(f"{what}: largest relative L2 difference {worst:.3e}")
EOF
}
if [ -n "$all" ]; then
    for name in $("$program" cases | cut -f1); do
        case $name in
            flat-obstacle) duration=1 ;;      # its first contact is at 0.75 s
            bass-fret5-lift) duration=0.6 ;;  # the finger lifts at 0.5 s
            *) duration=0.2 ;;
        esac
        run_case "$name" --duration $duration
    done
    # The fretted pop with a second pop and a force gesture beside it: two exact pluckers, the
    # finger and the exact crowns in one solve, and a gesture's load.
    "$program" export bass-fret5-pop "$scratch/played" >/dev/null
    cat >> "$scratch/played/bass-fret5-pop.toml" <<'TOML'

[[gesture]]
type = "pop"
position = 0.75
width = 0.008
time = 0.021
release_displacement = 2e-3
duration = 0.01
stiffness = 1e5

[[gesture]]
type = "force"
position = 0.3
force = [[0.0, 0.0], [0.022, 0.0], [0.024, 3.0], [0.026, 0.0]]
TOML
    run_case "$scratch/played/bass-fret5-pop.toml" --duration 0.05
    exit 0
fi
# At 48 kHz (the audio rate) and at each case's own rate.
for fs in 48000 native; do
    rate=
    [ "$fs" = native ] || rate="--fs $fs"
    run_case tanpura $rate --duration 1
    run_case sitar $rate --duration 1
    run_case bass-pop $rate --duration 0.2
    run_case flat-obstacle $rate --duration 1  # its first contact is at 0.75 s
done
