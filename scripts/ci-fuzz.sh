#!/usr/bin/env bash
# CI: short libFuzzer runs (clang from Debian, with ASan and UBSan) over the case-file parser,
# seeded with the built-in cases, over the strings-case reader, seeded with the built-in
# strings cases and the cases their strings name, over the MIDI file reader, seeded with
# tests/fuzz/midi-seeds, and over the recording reader of `estimate`, seeded with
# tests/fuzz/recordings (with a dictionary of chunk tags). FRETBUZZ_FUZZ_SECONDS sets each
# run's length (60 s).
# Reuses the build of ci-sanitizers.sh when it ran first.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${FRETBUZZ_SANITIZER_BUILD:-build-sanitizers}
seconds=${FRETBUZZ_FUZZ_SECONDS:-60}
start=$(date +%s)
scripts/ci-sanitizer-build.sh case_file_fuzzer strings_case_fuzzer midi_file_fuzzer recording_fuzzer
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
fuzz() {  # fuzzer, seed files, longest input, further libFuzzer options
  local corpus="$build/fuzz-corpus-$1"
  rm -rf "$corpus" && mkdir -p "$corpus"
  cp $2 "$corpus"/
  "$build"/tests/fuzz/"$1" "$corpus" -max_total_time="$seconds" -max_len="$3" -timeout=10 \
    -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$build/$1-" "${@:4}"
}
fuzz case_file_fuzzer "cases/*.toml" 16384
fuzz strings_case_fuzzer "cases/bridges/*.toml" 16384
fuzz midi_file_fuzzer "tests/fuzz/midi-seeds/*.mid" 8192
fuzz recording_fuzzer "tests/fuzz/recordings/*" 8192 -dict=tests/fuzz/recording.dict
echo "CI fuzz: $(( $(date +%s) - start )) s"
