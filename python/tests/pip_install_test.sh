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
# The distribution's metadata: licence, authors, the extras for sweeps and Dask.
from importlib.metadata import metadata
m = metadata("fretbuzz")
assert m["License"] == "MIT", m["License"]
assert "fretbuzz maintainers" in (m["Author"] or "") + (m["Author-email"] or ""), m.items()
assert "License :: OSI Approved :: MIT License" in m.get_all("Classifier"), m.get_all("Classifier")
extras = m.get_all("Provides-Extra")
requires = {r.replace(" ", "").replace('"', "'") for r in m.get_all("Requires-Dist")}
assert {"sweeps", "dask"} <= set(extras), extras
for needed in ("pandas;extra=='sweeps'", "dask;extra=='dask'", "distributed;extra=='dask'"):
    assert needed in requires, requires
print("fretbuzz", fretbuzz.__version__, "from", where)
PY
"$work/venv/bin/python" -m unittest -v test_package
# The notebook, in this environment: its kernel is the environment's python (which alone
# has the package), and its plot shows inline.
"$work/venv/bin/python" "$source/examples/notebook/run_notebook.py" "$source/examples/notebook/first_steps.ipynb"
