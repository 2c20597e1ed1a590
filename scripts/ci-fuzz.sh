#!/usr/bin/env bash
# CI: short libFuzzer runs (clang from Debian, with ASan and UBSan) over the case-file
# parser, seeded with the built-in cases, and over the recording reader of `estimate`,
# seeded with tests/fuzz/recordings/. FRETBUZZ_FUZZ_SECONDS sets the first's length
# (120 s), FRETBUZZ_RECORDING_FUZZ_SECONDS the second's (60 s).
# Reuses the build of ci-sanitizers.sh when it ran first.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${FRETBUZZ_SANITIZER_BUILD:-build-sanitizers}
seconds=${FRETBUZZ_FUZZ_SECONDS:-120}
recording_seconds=${FRETBUZZ_RECORDING_FUZZ_SECONDS:-60}
start=$(date +%s)
scripts/ci-sanitizer-build.sh case_file_fuzzer recording_fuzzer
corpus="$build/fuzz-corpus"
rm -rf "$corpus" && mkdir -p "$corpus"
cp cases/*.toml "$corpus"/
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
"$build"/tests/fuzz/case_file_fuzzer "$corpus" -max_total_time="$seconds" -max_len=16384 -timeout=10 \
  -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$build/"
corpus="$build/fuzz-recordings"
rm -rf "$corpus" && mkdir -p "$corpus"
cp tests/fuzz/recordings/* "$corpus"/
"$build"/tests/fuzz/recording_fuzzer "$corpus" -dict=tests/fuzz/recording.dict -max_total_time="$recording_seconds" \
  -max_len=8192 -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$build/recording-"
echo "CI fuzz: $(( $(date +%s) - start )) s"
