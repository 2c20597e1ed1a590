#!/bin/sh
# `pip install` of the package into a fresh virtual environment (with the system's numpy,
# matplotlib, h5py), then the package tests run from outside the source tree against the
# installed copy. Usage: pip_install_test.sh PYTHON SOURCE_DIR WORK_DIR [PREBUILT_CORE]
set -eu
python=$1 source=$2 work=$3
[ $# -ge 4 ] && export FRETBUZZ_PREBUILT_CORE=$4
rm -rf "$work"
"$python" -m venv --system-site-packages "$work/venv"
"$work/venv/bin/python" -m pip install --quiet --no-build-isolation --no-index "$source"
mkdir -p "$work/elsewhere"
cp "$source/python/tests/test_package.py" "$work/elsewhere/"
cd "$work/elsewhere"
"$work/venv/bin/python" - <<'PY'
import os, fretbuzz
where = os.path.dirname(fretbuzz.__file__)
assert where.startswith(os.path.realpath(os.path.join(os.getcwd(), "..", "venv"))) or "/venv/" in where, where
assert os.path.isfile(os.path.join(where, "_core.pyi")) and os.path.isfile(os.path.join(where, "py.typed"))
print("fretbuzz", fretbuzz.__version__, "from", where)
PY
"$work/venv/bin/python" -m unittest -v test_package
