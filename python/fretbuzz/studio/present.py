"""What the studio's templates draw, from the library's numbers: a map's cells (colour, a
short text and a sentence for each note, so that no verdict rests on colour alone), the side
views of the neck, a note's contacts as plot coordinates, the set-up in mm.

Drawing only: every number comes from fretbuzz.Bench (the side views' coordinates from the
same function that draws buzz_map.html).
"""
from __future__ import annotations

import math
from typing import Any, Dict, List, Optional

from ..setup_report import change_text, clean_up_to_text, note_colour, plucks_text, shop_length, side_view, stopped_string

# How each change from the previous map is marked, in text as well as by the cell's outline.
CHANGE_MARKS = {"worse": ("\u25b2", "worse than before"), "better": ("\u25bc", "better than before"),
                "moved": ("\u2194", "buzzes against another fret than before")}


def verdict(n: dict) -> str:
    """A note's class: clean, marginal (its plucks cannot tell), buzzes, out (frets out),
    unplayed."""
    if n["status"] == "frets out":
        return "out"
    if n["status"] != "ok" or not n.get("verdict"):
        return "unplayed"
    return n["verdict"]


def sentence(n: dict) -> str:
    """The verdict in words (the cell's title and accessible name)."""
    where = f"{n['string']} string, {'open' if n['fret'] == 0 else 'fret ' + str(n['fret'])}, {n['strength']} attack"
    kind = verdict(n)
    if kind == "out":
        return f"{where}: frets out" + (f" against fret {n['buzz_fret']}" if n.get("buzz_fret") not in (None, "") else "")
    if kind == "unplayed":
        return f"{where}: {n['status']}"
    text = f"{where}: {kind}, {plucks_text(n)} plucks buzz"
    if n.get("buzz_dB") is not None and not (isinstance(n["buzz_dB"], float) and math.isnan(n["buzz_dB"])):
        text += f", median level {n['buzz_dB']:+.0f} dB over the masked threshold"
    if n.get("buzz_fret") not in (None, "") and n["buzz_fraction"] > 0:
        text += f", against {'the board' if n['buzz_fret'] == 'board' else 'fret ' + str(n['buzz_fret'])}"
    if n.get("first_touch_s") is not None:
        text += f", first touch at {n['first_touch_s'] * 1e3:.0f} ms"
    up_to = clean_up_to_text(n)
    if up_to:
        text += f"; clean up to {up_to} this attack"
    if n.get("clearance_mm") is not None:
        text += f", clearance {n['clearance_mm']:.2f} mm"
    return text


def _ink(colour: str) -> str:
    """Black or white text, whichever reads better on the cell's colour."""
    r, g, b = (int(c) for c in colour[4:-1].split(","))
    return "#000" if 0.299 * r + 0.587 * g + 0.114 * b > 140 else "#fff"


# How the player's report marks a cell, in text as well as by the mark.
HEARD_MARKS = {"buzz": ("\u2717", "you hear it buzz"), "clean": ("\u2713", "you hear it clean")}


def cell(n: Optional[dict], string: str, fret: int, strength: str, heard_as: str = "") -> dict:
    """One cell of the map: n is the note's verdict (with 'change' from the previous map) or
    None while it is still to be played; heard_as what the player's report says of it."""
    you = f"; {HEARD_MARKS[heard_as][1]}" if heard_as else ""
    if n is None:
        return {"string": string, "fret": fret, "strength": strength, "kind": "pending", "text": "\u2026",
                "label": f"{string} string, fret {fret}, {strength} attack: not played yet{you}", "colour": "",
                "ink": "", "change": "", "mark": "", "audio": "", "heard": heard_as,
                "heard_mark": HEARD_MARKS[heard_as][0] if heard_as else ""}
    kind = verdict(n)
    up_to = clean_up_to_text(n)
    text = {"out": "out", "unplayed": "\u2013"}.get(kind, (up_to or plucks_text(n)) + ("?" if kind == "marginal" else ""))
    label = sentence(n)
    change = n.get("change", "") if n.get("change") in CHANGE_MARKS else ""
    mark = CHANGE_MARKS[change][0] if change else ""
    if change:
        was = n.get("before")
        label += f" ({CHANGE_MARKS[change][1]}" + (f": {change_text(was, n, n.get('reason', ''))}" if was else "") + ")"
    colour = note_colour(n)
    return {"string": string, "fret": fret, "strength": strength, "kind": kind, "text": text, "label": label + you,
            "colour": colour, "ink": _ink(colour), "change": change, "mark": mark, "audio": n.get("audio") or "",
            "heard": heard_as, "heard_mark": HEARD_MARKS[heard_as][0] if heard_as else ""}


def map_rows(record, heard_as: Optional[dict] = None) -> List[dict]:
    """The map as rows (string, attack) of cells, frets 0 .. N, in the instrument's string order;
    heard_as: the player's report {(string, fret, attack): "buzz" or "clean"}, marked on its cells."""
    by_note = {(n["string"], n["fret"], n["strength"]): n for n in list(record.notes)}
    frets, heard_as = record.bench.frets, heard_as or {}
    return [{"string": s, "strength": a,
             "cells": [cell(by_note.get((s, k, a)), s, k, a, heard_as.get((s, k, a), "")) for k in range(frets + 1)]}
            for a in record.attacks for s in record.bench.strings]


def summary(record) -> Dict[str, int]:
    """How many notes buzz (marginal ones apart), and how many changed against the previous map
    (new: not in it, played at another attack)."""
    notes = list(record.notes)
    out = {"played": len(notes), "buzzing": sum(1 for n in notes if verdict(n) in ("buzzes", "out")),
           "marginal": sum(1 for n in notes if verdict(n) == "marginal")}
    for change in (*CHANGE_MARKS, "new"):
        out[change] = sum(1 for n in notes if n.get("change") == change)
    return out


def neck_views(bench, width: float = 900.0, height: float = 200.0) -> List[dict]:
    """The side view of the neck under each string, from the library's geometry."""
    strings = [{k: (v.tolist() if hasattr(v, "tolist") else v) for k, v in s.items()} for s in bench.instrument.geometry()]
    for s in strings:
        # The board under the frets only: the body, some 10 mm below, would flatten the relief.
        x = s["fret_x_m"]
        end = x[-1] + 0.25 * (x[-1] - x[-2])
        kept = [(xs, zs) for xs, zs in zip(s["surface_x_m"], s["surface_z_m"]) if xs <= end]
        s["surface_x_m"], s["surface_z_m"] = [p[0] for p in kept], [p[1] for p in kept]
    views = side_view(strings, width, height)
    for view, s in zip(views, strings):
        view["relief_mm"] = 1e3 * s["relief_gap_m"]
        view["relief_fret"] = s["relief_fret"]
        view["action12_mm"] = None if s["action12_m"] is None else 1e3 * s["action12_m"]
    return views


def note_view(bench, string: str, fret: int) -> dict:
    """The side view of one string with the note stopped at `fret` drawn over its frets (its
    string from that fret's top to the saddle; the open string for fret 0)."""
    view = next(v for v in neck_views(bench) if v["name"] == string)
    view["stopped"] = stopped_string(view, fret)
    view["fret"] = fret
    return view


def shop(bench):
    """A Jinja filter: a length in mm in the instrument file's units, mm beside."""
    units = bench.instrument.units
    return lambda mm, fine=False, change=False: shop_length(mm, units, fine, change)


def setup_rows(bench) -> List[dict]:
    """The set-up string by string, in mm: what the controls change, as it now is."""
    rows = []
    for s in bench.instrument.geometry():
        rows.append({"name": s["name"], "nut_gap_mm": 1e3 * s["nut_gap_m"],
                     "action12_mm": None if s["action12_m"] is None else 1e3 * s["action12_m"],
                     "saddle_mm": 1e3 * s["saddle_height_m"], "relief_mm": 1e3 * s["relief_gap_m"],
                     "relief_fret": s["relief_fret"]})
    return rows


def contacts_plot(played: dict, duration_s: float, frets: int, width: float = 560.0, height: float = 220.0) -> dict:
    """A note's contacts over time as plot coordinates: x the time, y the fret that took the
    push (the board below the last fret), each dot's area the peak force."""
    rows = played["contacts"].to_dict("records")
    left, right, top, bottom = 44.0, width - 10.0, 10.0, height - 30.0
    lanes = frets + 1  # frets 1 .. N, and the board
    peak = max((r["peak_force_n"] for r in rows), default=0.0) or 1.0

    def lane(fret: Any) -> int:
        return frets + 1 if fret in ("board", None) or (isinstance(fret, float) and math.isnan(fret)) else int(fret)

    def Y(k: float) -> float:
        return top + (bottom - top) * (k - 0.5) / lanes

    dots = [{"x": round(left + (right - left) * min(r["time_s"] / duration_s, 1.0), 1), "y": round(Y(lane(r["fret"])), 1),
             "r": round(2.0 + 7.0 * math.sqrt(r["peak_force_n"] / peak), 1),
             "title": f"{1e3 * r['time_s']:.1f} ms: {'the board' if lane(r['fret']) > frets else 'fret ' + str(int(r['fret']))}, "
                      f"peak {r['peak_force_n']:.2f} N, impulse {1e6 * r['impulse_n_s']:.1f} \u00b5N s"} for r in rows]
    ticks_x = [{"x": round(left + (right - left) * t / 4, 1), "label": f"{1e3 * duration_s * t / 4:.0f}"} for t in range(5)]
    # The frets that took a push are labelled first, then every few others where there is room.
    touched = sorted({lane(r["fret"]) for r in rows})
    ticks_y: List[dict] = []
    for k in touched + [frets + 1] + list(range(1, frets + 1, 4)):
        if all(abs(Y(k) - t["y"]) >= 10 for t in ticks_y):
            ticks_y.append({"y": round(Y(k), 1), "label": "board" if k > frets else str(k), "touched": k in touched})
    return {"width": width, "height": height, "left": left, "right": right, "top": top, "bottom": bottom,
            "dots": dots, "ticks_x": ticks_x, "ticks_y": ticks_y, "rows": rows, "peak_n": peak if rows else 0.0}
