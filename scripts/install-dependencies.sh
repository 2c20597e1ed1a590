#!/bin/sh
# Installs what fretbuzz needs on Debian 12 (bookworm), from Debian's own packages.
# Runs apt-get as root, through sudo when not root. Safe to run again.
set -eu
packages="build-essential cmake pkg-config
  libfftw3-dev libgtest-dev libgmock-dev libbenchmark-dev
  libtomlplusplus-dev libcli11-dev nlohmann-json3-dev
  libsndfile1-dev libsoxr-dev libhdf5-dev nettle-dev
  pybind11-dev python3-dev python3-numpy python3-matplotlib python3-h5py
  ffmpeg chromium
  libeigen3-dev
  python3-pandas python3-tqdm python3-dask python3-distributed
  python3-pip python3-venv python3-setuptools python3-wheel
  python3-nbclient python3-nbformat python3-ipykernel
  doxygen help2man
  clang libclang-rt-14-dev
  lv2-dev liblilv-dev lilv-utils libsmf-dev
  freepats
  valgrind"
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
