#!/bin/sh
# Installs what fretbuzz needs on Debian 12 (bookworm), from Debian's own packages.
# Runs apt-get as root, through sudo when not root. Safe to run again.
#   install-dependencies.sh         what building the program and running it need (the main job:
#                                   the run, its plots and its report)
#   install-dependencies.sh --all   also what the tests, sanitizers, fuzzing, benchmarks, the
#                                   Python package, the LV2 plugin, the set-up studio and the API
#                                   docs need (the test command uses this; libmp3lame-dev: what
#                                   `pkg-config --static --libs sndfile` names, for the static
#                                   consumer test)
set -eu
build_and_run="build-essential cmake pkg-config
  libfftw3-dev libtomlplusplus-dev libcli11-dev nlohmann-json3-dev
  libsndfile1-dev libsoxr-dev libhdf5-dev nettle-dev libsmf-dev libeigen3-dev
  python3-numpy python3-matplotlib python3-h5py python3-jinja2"
everything_else="libgtest-dev libgmock-dev libbenchmark-dev ccache libmp3lame-dev
  pybind11-dev python3-dev
  ffmpeg chromium chromium-driver python3-selenium
  python3-pandas python3-tqdm python3-dask python3-distributed
  python3-fastapi python3-uvicorn python3-httpx python3-tomli-w
  python3-pip python3-venv python3-setuptools python3-wheel
  python3-nbclient python3-nbformat python3-ipykernel
  doxygen help2man
  clang libclang-rt-14-dev
  lv2-dev liblilv-dev lilv-utils
  freepats
  valgrind"
case "${1:-}" in
  "") packages="$build_and_run" ;;
  --all) packages="$build_and_run $everything_else" ;;
  *) echo "usage: $0 [--all]" >&2; exit 2 ;;
esac
missing=""
for p in $packages; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
[ -z "$missing" ] && exit 0
if [ "$(id -u)" -eq 0 ]; then as_root=""; else as_root="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$as_root apt-get update -qq
# shellcheck disable=SC2086
$as_root apt-get install -y -qq --no-install-recommends $missing
