#!/usr/bin/env python3
"""Where sitar-taraf's time goes: the whole case, its main string alone on the bridge, and its
taraf strings alone on it, side by side (bench/paired_runs.py, medians of paired runs).

The two parts are written from cases/bridges/sitar-taraf.toml into a scratch folder beside
copies of its one-string cases, each keeping its strings' columns of every bridge mode.

    bench/sitar_taraf_parts.py [--reps 3] [--duration 3] [--program build/cli/fretbuzz]
"""
import argparse
import shutil
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

HERE = Path(__file__).resolve().parent
BRIDGES = HERE.parent / "cases" / "bridges"


def toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return f'"{v}"'
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    return repr(v)


def write_part(case, keep, path):
    lines = [f'name = "{path.stem}"', "[run]"] + [f"{k} = {toml_value(v)}" for k, v in case["run"].items()]
    lines.append("[bridge]")
    for mode in case["bridge"]["mode"]:
        lines.append("[[bridge.mode]]")
        for k, v in mode.items():
            lines.append(f"{k} = {toml_value([v[s] for s in keep] if k == 'participation' else v)}")
    for s in keep:
        lines.append("[[string]]")
        lines += [f"{k} = {toml_value(v)}" for k, v in case["string"][s].items()]
    path.write_text("\n".join(lines) + "\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--reps", type=int, default=3)
    parser.add_argument("--duration", type=float, default=3.0)
    parser.add_argument("--program", default="build/cli/fretbuzz")
    args = parser.parse_args()
    case = tomllib.loads((BRIDGES / "sitar-taraf.toml").read_text())
    strings = range(len(case["string"]))
    with tempfile.TemporaryDirectory(prefix="sitar-taraf-parts-") as scratch:
        folder = Path(scratch)
        (folder / "bridges").mkdir()
        for s in case["string"]:
            shutil.copy(BRIDGES.parent / s["case"], folder / s["case"])
        write_part(case, [0], folder / "main-alone.toml")
        write_part(case, [s for s in strings if s != 0], folder / "taraf-alone.toml")
        run = f"run {{}} --duration {args.duration} --quiet"
        variants = [f"sitar-taraf={args.program} {run.format('sitar-taraf')}"]
        variants += [f"{part}={args.program} {run.format(folder / (part + '.toml'))}" for part in ("main-alone", "taraf-alone")]
        sys.exit(subprocess.run([sys.executable, str(HERE / "paired_runs.py"), "--reps", str(args.reps),
                                 "--simulated", str(args.duration)] + variants).returncode)


if __name__ == "__main__":
    main()
