#!/bin/sh
# The AVX-512 variant of the kernels against the AVX2 one, bit for bit: kernel_variants run on
# this processor and under valgrind (which offers AVX2 but not AVX-512). Skipped (77) where this
# processor has no AVX-512 or valgrind is missing: there is then no second variant to compare.
set -eu
program=$1
here=$(${program} --level)
if [ "$here" != "x86-64-v4" ]; then echo "skipped: this processor runs the $here variant, no AVX-512 to compare"; exit 77; fi
if ! command -v valgrind >/dev/null 2>&1; then echo "skipped: valgrind is not installed"; exit 77; fi
there=$(valgrind -q "$program" --level)
if [ "$there" != "x86-64-v3" ]; then echo "skipped: under valgrind the processor runs $there, not x86-64-v3"; exit 77; fi
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
"$program" > "$dir/avx512"
valgrind -q --error-exitcode=1 "$program" > "$dir/avx2"
if ! diff "$dir/avx512" "$dir/avx2"; then
  echo "FAILED: the kernels above (< AVX-512, > AVX2) give other bits in the two variants"
  exit 1
fi
echo "the AVX-512 and AVX2 variants agree bit for bit on $(wc -l < "$dir/avx2") kernels"
