#!/bin/sh
# Two builds' CSV outputs side by side: each case run by both, then the relative L2 difference
# ||new - old|| / ||old|| of every column of every CSV file (time columns excluded), and the
# largest of them per case. A change meant to move results only by round-off must keep
# every figure far below 1e-12.
# Usage: bench/compare_runs.sh <baseline fretbuzz> [this fretbuzz] [scratch directory]
#   e.g. bench/compare_runs.sh /tmp/base/build/cli/fretbuzz build/cli/fretbuzz
set -e
baseline=${1:?usage: compare_runs.sh baseline-fretbuzz [fretbuzz] [scratch]}
program=${2:-build/cli/fretbuzz}
scratch=${3:-$(mktemp -d)}
run_case() {  # name, then extra options
    name=$1
    shift
    tag=$(echo "$name $*" | tr -c 'a-z0-9.\n' '_')
    "$baseline" run "$name" "$@" -q --out "$scratch/$tag-old" 2>/dev/null
    "$program" run "$name" "$@" -q --out "$scratch/$tag-new" 2>/dev/null
    python3 - "$scratch/$tag-old" "$scratch/$tag-new" "$name $*" <<'EOF'
import csv, math, pathlib, sys
old, new, what = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2]), sys.argv[3]
worst = 0.0
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
# At 48 kHz (the audio rate) and at each case's own rate.
for fs in 48000 native; do
    rate=
    [ "$fs" = native ] || rate="--fs $fs"
    run_case tanpura $rate --duration 1
    run_case sitar $rate --duration 1
    run_case bass-pop $rate --duration 0.2
    run_case flat-obstacle $rate --duration 1  # its first contact is at 0.75 s
done
