#!/usr/bin/env bash
# The tests that run work on threads beside the run (the audio files' thread, the CSV and
# HDF5 writers) under ThreadSanitizer (clang, build-tsan/, made by ci-sanitizer-build.sh). Not
# part of CI, which keeps to 25 minutes: run it after changing any of those threads.
# FRETBUZZ_TSAN_FILTER overrides the test filter.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${FRETBUZZ_TSAN_BUILD:-build-tsan}
FRETBUZZ_SANITIZE=thread FRETBUZZ_SANITIZER_BUILD="$build" scripts/ci-sanitizer-build.sh fretbuzz_tests
filter=${FRETBUZZ_TSAN_FILTER:-"AudioBand.*:CsvOutputs.*:WriteQueue.*:LongRun.*"}
export TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1
"$build"/tests/fretbuzz_tests --gtest_filter="$filter" --gtest_brief=1
