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

__all__ = ["render", "side_view", "note_colour", "clean_up_to_text", "shop_length", "main"]

INCH_MM = 25.4


def shop_length(mm: Optional[float], units: str = "mm", fine: bool = False, change: bool = False) -> str:
    """A length (given in mm) in the instrument file's units with mm beside: "2.40 mm",
    "6.0/64 in (2.40 mm)" (units "64ths"), "0.094 in (2.40 mm)" ("thousandths"). fine: a small
    length (relief, a fret's height) in thousandths wherever the file is in inches. change: signed."""
    if mm is None or (isinstance(mm, float) and math.isnan(mm)):
        return ""
    sign = "+" if change else ""
    metric = f"{mm:{sign}.2f} mm"
    if units == "mm":
        return metric
    if units == "64ths" and not fine:
        return f"{mm / INCH_MM * 64:{sign}.1f}/64 in ({metric})"
    return f"{mm / INCH_MM:{sign}.3f} in ({metric})"

# Viridis (matplotlib's perceptually uniform map, readable by colour-blind eyes and in grey):
# the colour of a cell is how much harder than the attack the note can be played and stay
# clean, from a quarter of it (dark) to three times it or more (yellow).
_VIRIDIS = ((68, 1, 84), (59, 82, 139), (33, 145, 140), (94, 201, 98), (253, 231, 37))
_LOWEST_UP_TO, _HIGHEST_UP_TO = 0.25, 3.0


def _viridis(t: float) -> str:
    t = min(max(t, 0.0), 1.0) * (len(_VIRIDIS) - 1)
    k = min(int(t), len(_VIRIDIS) - 2)
    f = t - k
    r, g, b = (round(a + (c - a) * f) for a, c in zip(_VIRIDIS[k], _VIRIDIS[k + 1]))
    return f"rgb({r}, {g}, {b})"


def plucks_text(n: dict) -> str:
    """How many of a note's plucks buzz, of those played: "3/25"."""
    return f"{round(n['buzz_fraction'] * n['plucks'])}/{n['plucks']}"


def change_text(before: dict, now: dict, reason: str) -> str:
    """How a note changed, by the rule that called it changed (Bench.compare's reason): what it
    was and what it is, as the page and the studio both say it."""
    if reason == "verdict":
        return f"{before['verdict']} \u2192 {now['verdict']}"
    if reason == "margin" and before.get("clean_up_to") is not None and now.get("clean_up_to") is not None:
        return f"clean up to {before['clean_up_to']:.2f}x \u2192 {now['clean_up_to']:.2f}x the attack"
    if reason == "loudness" and before.get("buzz_dB") is not None and now.get("buzz_dB") is not None:
        return f"{before['buzz_dB']:.1f} \u2192 {now['buzz_dB']:.1f} dB"
    if reason == "fret" and before.get("buzz_fret") is not None:
        return f"against fret {before['buzz_fret']} \u2192 {now.get('buzz_fret')}"
    return f"{plucks_text(before)} \u2192 {plucks_text(now)} plucks buzz"


def clean_up_to_text(note: dict) -> str:
    """How much harder than the attack the note stays clean: "1.4x", "3x+" (at least), "0" when
    it frets out, "" when unknown."""
    if note["status"] == "frets out":
        return "0"
    up_to = note.get("clean_up_to")
    if up_to is None or (isinstance(up_to, float) and math.isnan(up_to)):
        return ""
    if note.get("clean_up_to_at_least") or (isinstance(up_to, float) and math.isinf(up_to)):
        return f"{_HIGHEST_UP_TO:g}x+"
    return f"{up_to:.2g}x" if up_to < 1 else f"{up_to:.1f}x"


def note_colour(note: dict) -> str:
    """The colour of a note's cell: grey when it was not played, dark purple when it frets out,
    else viridis by clean_up_to (log scale: a quarter of the attack dark, three times it yellow);
    a note judged without clean_up_to by its verdict."""
    if note["status"] == "frets out":
        return "rgb(40, 0, 50)"
    if note["status"] != "ok":
        return "rgb(170, 170, 170)"
    up_to = note.get("clean_up_to")
    if up_to is None or (isinstance(up_to, float) and math.isnan(up_to)):
        up_to = {"clean": _HIGHEST_UP_TO, "marginal": 1.0}.get(note.get("verdict"), _LOWEST_UP_TO)
    if note.get("clean_up_to_at_least"):
        up_to = _HIGHEST_UP_TO
    t = math.log(max(float(up_to), _LOWEST_UP_TO) / _LOWEST_UP_TO) / math.log(_HIGHEST_UP_TO / _LOWEST_UP_TO)
    return _viridis(t)


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
        # What a luthier measures, written where it is measured: the string's height over the
        # fret line at the nut, and its gap over fret 1, fret 12 and the last fret.
        last = len(s["fret_x_m"]) - 1
        at = [("nut", 0, s["nut_height_m"] - s["fret_top_m"][0])]
        at += [(f"fret {k}", k, s["gap_m"][k]) for k in sorted({1, 12, last}) if 0 < k <= last and s["gap_m"][k] is not None]
        gaps = [{"label": where, "x": round(X(s["fret_x_m"][k]), 1), "mm": 1e3 * gap,
                 "text": f"{1e3 * gap:.2f} mm / {1e3 * gap / INCH_MM:.3f} in"} for where, k, gap in at]
        views.append({"name": s["name"], "surface": surface, "frets": frets, "gaps": gaps,
                      "string": [round(X(0.0), 1), round(Y(s["nut_height_m"]), 1), round(X(length), 1),
                                 round(Y(s["saddle_height_m"]), 1)],
                      "exaggeration": round(exaggeration), "width": width, "height": height})
    return views


def stopped_string(view: dict, fret: int) -> Optional[List[float]]:
    """The note stopped at `fret` on a side view: its string from that fret's top to the saddle
    (None for the open string, drawn already)."""
    if fret <= 0:
        return None
    top = next((f for f in view["frets"] if f["n"] == fret), None)
    return None if top is None else [top["x"], top["top"], view["string"][2], view["string"][3]]


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
                level = "" if n["buzz_dB"] is None else f"{n['buzz_dB']:+.0f} dB over the masked threshold"
                up_to = clean_up_to_text(n)
                title = (f"{s['name']} fret {k}, {attack}: {n['status']}" if n["status"] != "ok" else
                         f"{s['name']} fret {k}, {attack}: {n['verdict']}, {plucks_text(n)} plucks buzz" +
                         (f", median {level}" if level else "") +
                         (f", against fret {n['buzz_fret']}" if n["buzz_fret"] not in (None, "") else "") +
                         (f", first touch at {n['first_touch_s'] * 1e3:.0f} ms" if n.get("first_touch_s") is not None
                          else "") +
                         (f"; clean up to {up_to} this attack" if up_to else "") +
                         (f", clearance {n['clearance_mm']:.2f} mm" if n["clearance_mm"] is not None else ""))
                change = changes.get((s["name"], k, attack), "")
                kind = "out" if n["status"] == "frets out" else n.get("verdict") or "unplayed"
                cells.append({"colour": note_colour(n), "title": title + (f" ({change})" if change else ""),
                              "mark": up_to + ("?" if n.get("verdict") == "marginal" else ""), "audio": n["audio"],
                              "change": change, "kind": kind, "string": s["name"], "fret": k})
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
    units = doc.get("units", "mm")
    dress = doc.get("dress")
    page = env.get_template("buzz_map.html.j2").render(
        doc=doc, rows=_cells(doc, doc["notes"], changes), before_rows=_cells(doc, before, {}) if before else [],
        dress_rows=_cells(doc, dress["after"], {}) if dress else [], units=units,
        shop=lambda mm, fine=False, change=False: shop_length(mm, units, fine, change),
        views=side_view(doc["strings"]), changed=[c for c in doc.get("comparison", []) if c["change"] in ("better", "worse", "moved")],
        change_text=change_text, mm=lambda v: "" if v is None else f"{1e3 * v:.2f}", isnan=lambda v: v is None or (isinstance(v, float) and math.isnan(v)))
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
