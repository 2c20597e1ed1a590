#!/usr/bin/env bash
# CI: a short libFuzzer run over the case-file parser (clang from Debian, with ASan and
# UBSan), seeded with the built-in cases. FRETBUZZ_FUZZ_SECONDS sets its length (120 s).
# Reuses the build of ci-sanitizers.sh when it ran first.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${FRETBUZZ_SANITIZER_BUILD:-build-sanitizers}
seconds=${FRETBUZZ_FUZZ_SECONDS:-120}
start=$(date +%s)
scripts/ci-sanitizer-build.sh case_file_fuzzer
corpus="$build/fuzz-corpus"
rm -rf "$corpus" && mkdir -p "$corpus"
cp cases/*.toml "$corpus"/
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
"$build"/tests/fuzz/case_file_fuzzer "$corpus" -max_total_time="$seconds" -max_len=16384 -timeout=10 \
  -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$build/"
echo "CI fuzz: $(( $(date +%s) - start )) s"
