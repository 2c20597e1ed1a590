#!/usr/bin/env bash
# CI: a short libFuzzer run over the case-file parser (clang from Debian, with ASan and
# UBSan), seeded with the built-in cases. FRETBUZZ_FUZZ_SECONDS sets its length (120 s).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${FRETBUZZ_FUZZ_BUILD:-build-fuzz}
seconds=${FRETBUZZ_FUZZ_SECONDS:-120}
flags="-O1 -g -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined"
start=$(date +%s)
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
fi
CC=clang CXX=clang++ cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Debug "${launcher[@]}" \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_C_FLAGS="$flags" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DFRETBUZZ_BUILD_TESTS=OFF -DFRETBUZZ_BUILD_BENCH=OFF -DFRETBUZZ_BUILD_PYTHON=OFF -DFRETBUZZ_BUILD_FUZZ=ON >/dev/null
cmake --build "$build" -j2 --target case_file_fuzzer
corpus="$build/fuzz-corpus"
rm -rf "$corpus" && mkdir -p "$corpus"
cp cases/*.toml "$corpus"/
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
"$build"/tests/fuzz/case_file_fuzzer "$corpus" -max_total_time="$seconds" -max_len=16384 -timeout=10 \
  -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$build/"
echo "CI fuzz: $(( $(date +%s) - start )) s"
