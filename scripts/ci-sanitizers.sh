#!/usr/bin/env bash
# CI: the test suite under AddressSanitizer and UndefinedBehaviorSanitizer (clang; the
# build is shared with ci-fuzz.sh). Under ASan a run is several times slower, so the long
# end-to-end runs (3 s of bass-pop at 4 MHz, convergence studies, sweeps, estimation from
# recordings, the report in a browser) are left out by the filter below; every unit test
# and the short end-to-end runs (bad input, the output directory, signals, full disk,
# hostile files) run. FRETBUZZ_SANITIZER_FILTER overrides the filter.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${FRETBUZZ_SANITIZER_BUILD:-build-sanitizers}
start=$(date +%s)
scripts/ci-sanitizer-build.sh fretbuzz_tests fretbuzz_cli case_file_fuzzer
built=$(date +%s)
# Left out too: the set-up bench's searches and statistics (advice, dress, verdicts over seeds,
# the calibration's round trip, the finger model against its stand-in) and the pitch studies,
# each playing hundreds of notes through the paths the short setup and finger tests cover: two
# thirds of the filtered suite's time, and CI ran within 15 minutes of its limit.
long_searches="SetupAdvice.*:SetupDress.*:SetupVerdicts.*:SetupHeldStops.*:SetupCalibration.ARoundTrip*"
long_searches="$long_searches:SetupNotes.TheFingerModel*:Finger.AStoppedNotesPitch*:Subnormals.ALongSitar*"
long_searches="$long_searches:Frets/StoppedNote.*:EstimationGrid.*"
filter=${FRETBUZZ_SANITIZER_FILTER:-"-LongRun.*:Convergence*:PaperObservations.*:RealRecording.*:DenseAgreement.*:CrossCheck.*:Sweep*:EstimateCommand.*:ModalEstimation.*:ReportCommand.*:HtmlReport.*:PlotCommand.*:$long_searches"}
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# Six shards, two at a time (one per core; the tests are independent: ctest runs them two at a
# time too): with only two, one shard ran far longer than the other.
shards=6
export build filter shards
status=0
rm -f "$build"/shard-*.log
seq 0 $((shards - 1)) | xargs -P 2 -I{} sh -c \
  'GTEST_TOTAL_SHARDS=$shards GTEST_SHARD_INDEX={} "$build"/tests/fretbuzz_tests --gtest_filter="$filter" --gtest_brief=1 >"$build/shard-{}.log" 2>&1' ||
  status=1
# (xargs starts no more shards once one is killed, by AddressSanitizer's abort for one)
for shard in $(seq 0 $((shards - 1))); do cat "$build/shard-$shard.log" 2>/dev/null || echo "shard $shard: not run"; done
echo "CI sanitizers: build $(( built - start )) s, tests $(( $(date +%s) - built )) s"
exit "$status"
