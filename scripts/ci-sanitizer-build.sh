#!/usr/bin/env bash
# Shared by ci-sanitizers.sh and ci-fuzz.sh: ONE clang build (build-sanitizers/) with
# AddressSanitizer and UndefinedBehaviorSanitizer, instrumented for libFuzzer, holding the
# test suite, the program and the case-file fuzzer. One build instead of two keeps CI short.
# FRETBUZZ_SANITIZE=thread (with another FRETBUZZ_SANITIZER_BUILD) makes a ThreadSanitizer
# build instead, without the fuzzer (see thread-sanitizer.sh).
# Usage: scripts/ci-sanitizer-build.sh TARGET...
set -euo pipefail
cd "$(dirname "$0")/.."
build=${FRETBUZZ_SANITIZER_BUILD:-build-sanitizers}
sanitize=${FRETBUZZ_SANITIZE:-address,undefined}
if [ "$sanitize" = address,undefined ]; then
  # Line tables only: the sanitizers' reports still name file and line, and the build is shorter.
  flags="-O1 -gline-tables-only -fsanitize=address,undefined,fuzzer-no-link -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
  fuzz=ON
else
  flags="-O1 -g -fsanitize=$sanitize -fno-omit-frame-pointer"
  fuzz=OFF
fi
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
fi
# A folder configured with another compiler cannot switch: start it afresh.
if [ -f "$build/CMakeCache.txt" ] && ! grep -q '^CMAKE_CXX_COMPILER:.*clang++' "$build/CMakeCache.txt"; then
  rm -rf "$build"
fi
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Debug -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ "${launcher[@]}" \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_C_FLAGS="$flags" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=$sanitize" -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=$sanitize" \
  -DFRETBUZZ_BUILD_BENCH=OFF -DFRETBUZZ_BUILD_PYTHON=OFF -DFRETBUZZ_BUILD_FUZZ=$fuzz >/dev/null
cmake --build "$build" -j2 --target "$@"
