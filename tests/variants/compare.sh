#!/bin/sh
# The kernels built for each instruction-set level this processor runs (baseline x86-64, AVX2,
# AVX-512), run on the same inputs: each level's results must agree with the baseline's within
# kernel_variant's stated tolerance (1e-12 relative L2 per kernel). Skipped (77) where the
# processor runs the baseline level only: there is nothing to compare.
# Usage: compare.sh DIRECTORY (where kernel_variant_x86-64 and the others are)
set -eu
dir=$1
base="$dir/kernel_variant_x86-64"
levels=$("$base" --levels)
if [ "$levels" = "x86-64" ] || [ "$levels" = "single" ]; then echo "skipped: this processor runs one level only"; exit 77; fi
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
for level in $levels; do "$dir/kernel_variant_$level" > "$scratch/$level"; done
status=0
for level in $levels; do
    [ "$level" = x86-64 ] && continue
    echo "$level against x86-64:"
    "$base" --compare "$scratch/x86-64" "$scratch/$level" || status=1
done
exit $status
