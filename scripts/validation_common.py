"""Helpers shared by the validation scripts: find the fretbuzz binary, run it, read its CSVs,
write modified case files, and time the whole script. Run with /usr/bin/python3 (numpy, matplotlib)."""
import atexit
import csv
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
FIGURES = ROOT / "docs" / "figures"
CASES = ROOT / "cases"
_START = time.perf_counter()


def report_run_time():
    print(f"[{Path(sys.argv[0]).name}] run time: {time.perf_counter() - _START:.1f} s")


atexit.register(report_run_time)


def fretbuzz_binary():
    """$FRETBUZZ if set, else the first build found in the usual build folders."""
    if os.environ.get("FRETBUZZ"):
        return os.environ["FRETBUZZ"]
    for build in ("build-valid", "build", "build-release"):
        candidate = ROOT / build / "cli" / "fretbuzz"
        if candidate.exists():
            return str(candidate)
    sys.exit("fretbuzz binary not found: build it or set FRETBUZZ=/path/to/fretbuzz")


def fretbuzz(*args, capture=False):
    command = [fretbuzz_binary(), *map(str, args)]
    print("$", " ".join(command), flush=True)
    result = subprocess.run(command, check=True, text=True, capture_output=capture)
    return result.stdout if capture else None


def scratch_dir(name):
    path = Path(tempfile.mkdtemp(prefix=f"fretbuzz-{name}-"))
    atexit.register(shutil.rmtree, path, True)
    return path


def read_csv(path):
    """Header and float columns of a fretbuzz CSV."""
    with open(path) as f:
        rows = list(csv.reader(f))
    header = rows[0]
    data = np.array([[float(v) for v in r] for r in rows[1:]])
    return header, data


def case_variant(name, directory, obstacle_csv=None, obstacle_none=False):
    """Copies a built-in case and its data files to `directory`, optionally replacing the
    obstacle table or removing the obstacle; returns the new case file."""
    source = (CASES / f"{name}.toml").read_text()
    shutil.copytree(CASES / "data", directory / "data", dirs_exist_ok=True)
    lines = []
    in_obstacle = False
    for line in source.splitlines():
        if line.startswith("["):
            in_obstacle = line.strip() == "[obstacle]"
        if in_obstacle and obstacle_none and line.startswith(("type", "file")):
            line = 'type = "none"' if line.startswith("type") else ""
        if in_obstacle and obstacle_csv and line.startswith("file"):
            line = f'file = "{obstacle_csv}"'
        lines.append(line)
    path = directory / f"{name}-variant.toml"
    path.write_text("\n".join(lines) + "\n")
    return path


def fret_points(obstacle_csv=CASES / "data" / "bass_fretted_obstacle.csv"):
    """Indices (rows of the table) and x of the frets: grid points above both neighbours."""
    _, table = read_csv(obstacle_csv)
    g = table[:, 1]
    idx = [i for i in range(1, len(g) - 1) if g[i] > g[i - 1] and g[i] > g[i + 1]]
    return table, idx


def savefig(fig, name):
    FIGURES.mkdir(parents=True, exist_ok=True)
    path = FIGURES / name
    fig.savefig(path, dpi=90)
    print(f"wrote {path.relative_to(ROOT)} ({path.stat().st_size // 1024} KB)")


def processor():
    """The processor's name from lscpu, to print beside every timing."""
    for line in subprocess.run(["lscpu"], text=True, capture_output=True).stdout.splitlines():
        if line.startswith("Model name:"):
            return line.split(":", 1)[1].strip()
    return platform.processor() or "unknown processor"


def relative_l2(a, b):
    """||a - b|| / ||b|| over their common length."""
    n = min(len(a), len(b))
    return float(np.linalg.norm(a[:n] - b[:n]) / np.linalg.norm(b[:n]))
