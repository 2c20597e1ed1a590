#!/usr/bin/env bash
# The tests that run work on threads beside the run (the audio files' thread, the CSV and
# HDF5 writers) under ThreadSanitizer (clang, build-tsan/). Not part of
# CI, which keeps to 25 minutes: run it after changing any of those threads.
# FRETBUZZ_TSAN_FILTER overrides the test filter.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${FRETBUZZ_TSAN_BUILD:-build-tsan}
flags="-O1 -g -fsanitize=thread -fno-omit-frame-pointer"
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
fi
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Debug -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ "${launcher[@]}" \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_C_FLAGS="$flags" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=thread" -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=thread" \
  -DFRETBUZZ_BUILD_BENCH=OFF -DFRETBUZZ_BUILD_PYTHON=OFF >/dev/null
cmake --build "$build" -j2 --target fretbuzz_tests
filter=${FRETBUZZ_TSAN_FILTER:-"AudioBand.*:CsvOutputs.*:WriteQueue.*:LongRun.*"}
export TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1
"$build"/tests/fretbuzz_tests --gtest_filter="$filter" --gtest_brief=1
