"""The buzz map page of the set-up bench: buzz_map.html drawn from a map's map.json.

`fretbuzz setup` writes map.json (the instrument's geometry, the verdict of every note, the
comparison and the advice) and calls this module to draw the page through the Jinja2
template templates/buzz_map.html.j2, which lies in this package. By hand:

    python3 -m fretbuzz.setup_report DIR              # DIR/map.json -> DIR/buzz_map.html
    python3 -m fretbuzz.setup_report DIR --out page.html

Only the drawing is done here: the numbers (geometry, verdicts) all come from the library.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
from typing import Dict, List, Optional

__all__ = ["render", "side_view", "note_colour", "main"]

# A note is drawn green when none of its plucks buzzes audibly, red when all do.
_GREEN, _RED = (46, 160, 67), (208, 52, 44)


def note_colour(note: dict) -> str:
    """The colour of a note's cell: grey when it was not played, green to red with the share
    of its plucks that buzz audibly (pale green when nothing was even touched)."""
    if note["status"] == "frets out":
        return "rgb(120, 20, 20)"
    if note["status"] != "ok":
        return "rgb(170, 170, 170)"
    if note["touch_fraction"] == 0:
        return "rgb(196, 232, 196)"
    f = float(note["buzz_fraction"])
    r, g, b = (round(a + (c - a) * f) for a, c in zip(_GREEN, _RED))
    return f"rgb({r}, {g}, {b})"


def side_view(strings: List[dict], width: float = 900.0, height: float = 150.0) -> List[dict]:
    """Side views of the neck under each string, in SVG coordinates: x to scale along the
    string (nut left), heights exaggerated by a stated factor (the drawing's `exaggeration`)
    so that tenths of a millimetre show. The vertical range holds the string, the fret tops
    and the board; a body far below is drawn on the bottom edge."""
    views = []
    for s in strings:
        length = s["scale_length_m"]
        board_end = max(s["fret_x_m"])
        board = [z for x, z in zip(s["surface_x_m"], s["surface_z_m"]) if x <= board_end + 1e-9 and z is not None]
        heights = [z for z in s["fret_top_m"] if z is not None] + board + [s["nut_height_m"], s["saddle_height_m"]]
        low, high = min(heights), max(heights)
        span = max(high - low, 1e-4)
        exaggeration = (height - 20.0) / span / ((width - 20.0) / length)

        def X(x: float) -> float:
            return 10.0 + (width - 20.0) * x / length

        def Y(z: float) -> float:
            return min(height - 2.0, 10.0 + (height - 20.0) * (high - z) / span)

        surface = " ".join(f"{X(x):.1f},{Y(z):.1f}" for x, z in zip(s["surface_x_m"], s["surface_z_m"]) if z is not None)
        frets = [{"x": round(X(x), 1), "top": round(Y(t), 1), "base": round(Y(t - 1e-3), 1), "n": n}
                 for n, (x, t) in enumerate(zip(s["fret_x_m"], s["fret_top_m"])) if n > 0]
        views.append({"name": s["name"], "surface": surface, "frets": frets,
                      "string": [round(X(0.0), 1), round(Y(s["nut_height_m"]), 1), round(X(length), 1),
                                 round(Y(s["saddle_height_m"]), 1)],
                      "exaggeration": round(exaggeration), "width": width, "height": height})
    return views


def _cells(doc: dict, notes: List[dict], changes: Dict[tuple, str]) -> List[dict]:
    """The map as rows (string, attack) of cells (fret 0 .. N)."""
    rows = []
    frets = doc["frets"]
    for attack in [a["label"] for a in doc["attacks"]]:
        for s in doc["strings"]:
            by_fret = {n["fret"]: n for n in notes if n["string"] == s["name"] and n["strength"] == attack}
            if not by_fret:
                continue
            cells = []
            for k in range(frets + 1):
                n = by_fret.get(k)
                if n is None:
                    cells.append(None)
                    continue
                level = "" if n["buzz_dB"] is None else f"{n['buzz_dB']:.1f} dB"
                title = (f"{s['name']} fret {k}, {attack}: {n['status']}" if n["status"] != "ok" else
                         f"{s['name']} fret {k}, {attack}: {round(n['buzz_fraction'] * n['plucks'])}/{n['plucks']} plucks "
                         f"buzz audibly" + (f", median {level}" if level else "") +
                         (f", against fret {n['buzz_fret']}" if n["buzz_fret"] not in (None, "") else "") +
                         (f", clearance {n['clearance_mm']:.2f} mm" if n["clearance_mm"] is not None else ""))
                change = changes.get((s["name"], k, attack), "")
                cells.append({"colour": note_colour(n), "title": title + (f" ({change})" if change else ""),
                              "mark": "" if n["buzz_fret"] in (None, "") else n["buzz_fret"], "audio": n["audio"],
                              "change": change})
            rows.append({"string": s["name"], "attack": attack, "cells": cells})
    return rows


def render(directory: str, out: Optional[str] = None) -> str:
    """Draws DIR/map.json into buzz_map.html (or `out`); returns the path written."""
    from jinja2 import Environment, FileSystemLoader, select_autoescape
    with open(os.path.join(directory, "map.json"), encoding="utf-8") as f:
        doc = json.load(f)
    changes = {(c["string"], c["fret"], c["strength"]): c["change"] for c in doc.get("comparison", [])
               if c["change"] in ("better", "worse", "moved")}
    before = [c["before"] for c in doc.get("comparison", []) if c.get("before")]
    env = Environment(loader=FileSystemLoader(os.path.join(os.path.dirname(__file__), "templates")),
                      autoescape=select_autoescape(["html", "j2"]), trim_blocks=True, lstrip_blocks=True)
    page = env.get_template("buzz_map.html.j2").render(
        doc=doc, rows=_cells(doc, doc["notes"], changes), before_rows=_cells(doc, before, {}) if before else [],
        views=side_view(doc["strings"]), changed=[c for c in doc.get("comparison", []) if c["change"] in ("better", "worse", "moved")],
        mm=lambda v: "" if v is None else f"{1e3 * v:.2f}", isnan=lambda v: v is None or (isinstance(v, float) and math.isnan(v)))
    path = out or os.path.join(directory, "buzz_map.html")
    tmp = path + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(page)
    os.replace(tmp, path)
    return path


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python3 -m fretbuzz.setup_report",
                                     description="Draw a set-up bench map (map.json) as buzz_map.html.")
    parser.add_argument("dir", help="the --out folder of `fretbuzz setup` (holding map.json)")
    parser.add_argument("--out", help="where to write the page (default: DIR/buzz_map.html)")
    a = parser.parse_args(argv)
    try:
        render(a.dir, a.out)
    except ImportError as e:
        print(f"fretbuzz: buzz_map.html needs Jinja2 ({e}): apt-get install python3-jinja2", file=sys.stderr)
        return 1
    except (OSError, ValueError, KeyError) as e:
        print(f"fretbuzz: cannot draw {a.dir}/map.json: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
