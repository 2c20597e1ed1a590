"""Buzz maps: a fretboard drawing with each note coloured by its buzz level, drawn from the
table of a sweep whose runs are notes (a column giving each run's fret).

    notes = notes_from_table(fretbuzz.read_table("out/study/sweep"), "fret", "out/study/sweep", "out/study")
    write("out/study", notes, {"relief (mm)": 0.3}, scale_length=0.863, fret_count=20)

writes buzz_map.csv (one row per note) and buzz_map.html (the drawing, the fret each note
buzzes against, an audio player per note, the set-up parameters; with `compare`, the map
of another study beside it and the notes that changed marked). `fretbuzz setup` uses it.
"""
from __future__ import annotations

import csv
import html
import math
import os
from typing import Dict, List, Optional, Sequence

__all__ = ["notes_from_table", "write", "read_notes", "changed_notes", "CHANGE_DB"]

# A note changed between two set-ups when its buzz level moved by this much or more, or it
# buzzes against another fret (or starts or stops touching).
CHANGE_DB = 3.0

COLUMNS = ["fret", "strength_m", "status", "buzz_dB", "buzz_fret", "frets_touched", "first_contact_s",
           "last_contact_s", "contact_episodes", "contact_time_s", "contact_energy_loss_J", "peak_contact_force_N",
           "audio"]


def _number(value) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        return math.nan
    return v


def notes_from_table(table, fret_column: str, sweep_dir: str, page_dir: str = ".",
                     features_from_the_note: bool = False) -> List[dict]:
    """One note per run of a sweep table (pandas DataFrame). fret_column: the column of the
    fret each run plays; sweep_dir: the sweep's directory (its runs/NNNNNN/ audio is linked
    relative to page_dir, where the map goes). features_from_the_note: the obstacle's
    features are numbered from the stopped fret (the stand-in stopped note), not the nut."""
    if fret_column not in table.columns:
        raise KeyError(f"the sweep table has no column {fret_column!r} (the fret of each run)")
    notes = []
    for _, row in table.iterrows():
        fret = int(row[fret_column])
        offset = fret if features_from_the_note else 0
        touched = [int(f) + offset for f in str(row.get("features", "") or "").split()]
        main = _number(row.get("main_feature"))
        audio = ""
        folder = os.path.join(sweep_dir, "runs", f"{int(row['run']):06d}")
        if os.path.isdir(folder):
            wavs = sorted(n for n in os.listdir(folder) if n.endswith(".wav"))
            if wavs:
                audio = os.path.relpath(os.path.join(folder, wavs[0]), page_dir).replace(os.sep, "/")
        notes.append({
            "fret": fret,
            "strength_m": _number(row.get("strength_m", row.get("excitation.amplitude", math.nan))),
            "status": row["status"] if row["status"] == "ok" else f"failed: {row['error']}",
            "buzz_dB": _number(row.get("buzz_dB")),
            "buzz_fret": int(main) + offset if main and main > 0 else "",
            "frets_touched": " ".join(str(f) for f in touched),
            **{k: _number(row.get(k)) for k in COLUMNS[6:12]},
            "audio": audio,
        })
    return notes


def read_notes(directory: str) -> List[dict]:
    """The notes of an earlier study (its buzz_map.csv)."""
    with open(os.path.join(directory, "buzz_map.csv"), newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    for r in rows:
        r["fret"] = int(r["fret"])
        r["buzz_fret"] = int(r["buzz_fret"]) if r["buzz_fret"] else ""
        for k in ("strength_m", "buzz_dB", *COLUMNS[6:12]):
            r[k] = _number(r[k]) if r[k] != "" else math.nan
    return rows


def _key(note: dict):
    return note["fret"], round(note["strength_m"], 12) if math.isfinite(note["strength_m"]) else None


def changed_notes(notes: Sequence[dict], other: Sequence[dict]) -> Dict[tuple, str]:
    """The notes (fret, strength) that changed between two studies, with why."""
    before = {_key(n): n for n in other}
    changed = {}
    for n in notes:
        o = before.get(_key(n))
        if o is None:
            continue
        a, b = n["buzz_dB"], o["buzz_dB"]
        if n["buzz_fret"] != o["buzz_fret"]:
            changed[_key(n)] = f"buzzes against fret {o['buzz_fret'] or 'none'} -> {n['buzz_fret'] or 'none'}"
        elif math.isfinite(a) and math.isfinite(b) and abs(a - b) >= CHANGE_DB:
            changed[_key(n)] = f"buzz {b:+.1f} dB -> {a:+.1f} dB"
    return changed


# The colour scale of the buzz level (dB of contact-generated high-frequency energy
# relative to the note's own): green at QUIET_DB and below, red at LOUD_DB and above.
QUIET_DB, LOUD_DB = -40.0, 0.0


def _colour(note: dict) -> str:
    """A failed run grey; no contact pale green; then green to red with the buzz level."""
    if note["status"] != "ok":
        return "#999999"
    db = note["buzz_dB"]
    if not math.isfinite(db):
        return "#b5e3b5"
    s = min(max((db - QUIET_DB) / (LOUD_DB - QUIET_DB), 0.0), 1.0)
    return f"hsl({120 * (1 - s):.0f}, 75%, 42%)"


def _fmt(v, digits=3) -> str:
    if isinstance(v, float):
        return "" if not math.isfinite(v) else f"{v:.{digits}g}"
    return str(v)


def _svg(notes: Sequence[dict], scale_length: float, fret_count: int, changed: Dict[tuple, str]) -> str:
    strengths = sorted({_key(n)[1] for n in notes}, key=lambda s: (s is None, s))
    width, left, row_h = 900.0, 30.0, 34.0
    last = scale_length * (1 - 2 ** (-fret_count / 12))
    span = last * 1.04

    def x_of(pos: float) -> float:
        return left + (width - 2 * left) * pos / span

    height = 40 + row_h * len(strengths)
    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0f}" height="{height:.0f}" '
             f'font-family="sans-serif" font-size="11">',
             f'<rect x="{left:.1f}" y="20" width="{x_of(span) - left:.1f}" height="{row_h * len(strengths):.1f}" '
             f'fill="#e8d7b9" stroke="#8b6b3e"/>',
             f'<line x1="{left:.1f}" y1="20" x2="{left:.1f}" y2="{height - 20:.0f}" stroke="#333" stroke-width="5"/>']
    for n in range(1, fret_count + 1):
        x = x_of(scale_length * (1 - 2 ** (-n / 12)))
        parts.append(f'<line x1="{x:.1f}" y1="20" x2="{x:.1f}" y2="{height - 20:.0f}" stroke="#888" stroke-width="2"/>')
        parts.append(f'<text x="{x:.1f}" y="14" text-anchor="middle">{n}</text>')
    for n in (3, 5, 7, 9, 12, 15, 17, 19, 21):
        if n <= fret_count:
            x = 0.5 * (x_of(scale_length * (1 - 2 ** (-n / 12))) + x_of(scale_length * (1 - 2 ** (-(n - 1) / 12))))
            parts.append(f'<circle cx="{x:.1f}" cy="{height - 10:.0f}" r="3" fill="#8b6b3e"/>')
    for row, strength in enumerate(strengths):
        y = 20 + row_h * (row + 0.5)
        parts.append(f'<line x1="{left:.1f}" y1="{y:.1f}" x2="{x_of(span):.1f}" y2="{y:.1f}" stroke="#555"/>')
        for note in (n for n in notes if _key(n)[1] == strength):
            k = note["fret"]
            x = left - 14 if k == 0 else 0.5 * (x_of(scale_length * (1 - 2 ** (-k / 12))) +
                                                 x_of(scale_length * (1 - 2 ** (-(k - 1) / 12))))
            title = (f"fret {k}, strength {_fmt(note['strength_m'])} m: " +
                     (f"buzz {_fmt(note['buzz_dB'])} dB against fret {note['buzz_fret']}" if note["buzz_fret"] != ""
                      else "no contact" if note["status"] == "ok" else note["status"]))
            if _key(note) in changed:
                title += f" (changed: {changed[_key(note)]})"
                parts.append(f'<circle cx="{x:.1f}" cy="{y:.1f}" r="14" fill="none" stroke="#1040ff" stroke-width="3"/>')
            parts.append(f'<circle cx="{x:.1f}" cy="{y:.1f}" r="10" fill="{_colour(note)}" stroke="#222">'
                         f'<title>{html.escape(title)}</title></circle>')
            parts.append(f'<text x="{x:.1f}" y="{y + 4:.1f}" text-anchor="middle" fill="white">'
                         f'{note["buzz_fret"]}</text>')
    parts.append("</svg>")
    return "\n".join(parts)


def _table(notes: Sequence[dict], changed: Dict[tuple, str]) -> str:
    head = ("<tr><th>fret</th><th>strength (m)</th><th>buzz (dB)</th><th>buzzes against</th><th>frets touched</th>"
            "<th>first contact (s)</th><th>contact episodes</th><th>time in contact (s)</th>"
            "<th>peak force (N)</th><th>audio</th><th>changed</th></tr>")
    rows = []
    for n in notes:
        audio = f'<audio controls preload="none" src="{html.escape(n["audio"])}"></audio>' if n["audio"] else ""
        status = "" if n["status"] == "ok" else f' title="{html.escape(n["status"])}" class="failed"'
        rows.append(f'<tr{status}><td>{n["fret"]}</td><td>{_fmt(n["strength_m"])}</td>'
                    f'<td style="background:{_colour(n)};color:white">{_fmt(n["buzz_dB"])}</td>'
                    f'<td>{n["buzz_fret"]}</td><td>{html.escape(n["frets_touched"])}</td>'
                    f'<td>{_fmt(n["first_contact_s"])}</td><td>{_fmt(n["contact_episodes"])}</td>'
                    f'<td>{_fmt(n["contact_time_s"])}</td><td>{_fmt(n["peak_contact_force_N"])}</td>'
                    f'<td>{audio}</td><td>{html.escape(changed.get(_key(n), ""))}</td></tr>')
    return "<table>" + head + "".join(rows) + "</table>"


def _parameters(parameters: Dict[str, object]) -> str:
    return "<table>" + "".join(f"<tr><th>{html.escape(str(k))}</th><td>{html.escape(_fmt(v, 4))}</td></tr>"
                               for k, v in parameters.items()) + "</table>"


def write(out: str, notes: Sequence[dict], parameters: Dict[str, object], scale_length: float, fret_count: int,
          compare: Optional[str] = None) -> None:
    """buzz_map.csv and buzz_map.html in `out`; with `compare` (an earlier study's
    directory) its map beside this one, the changed notes ringed and listed."""
    with open(os.path.join(out, "buzz_map.csv"), "w", newline="", encoding="utf-8") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS)
        w.writeheader()
        for n in notes:
            w.writerow({k: _fmt(n[k], 17) if isinstance(n[k], float) else n[k] for k in COLUMNS})
    import json
    with open(os.path.join(out, "setup.json"), "w", encoding="utf-8") as f:
        json.dump(parameters, f, indent=1)
    other = read_notes(compare) if compare else None
    changed = changed_notes(notes, other) if other is not None else {}
    style = ("body{font-family:sans-serif;margin:2em} table{border-collapse:collapse;margin:1em 0} "
             "td,th{border:1px solid #ccc;padding:2px 6px;font-size:12px} .failed{background:#fdd} "
             ".maps{display:flex;gap:2em;flex-wrap:wrap}")
    body = [f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>Buzz map</title><style>{style}</style></head><body>",
            "<h1>Buzz map</h1>",
            f"<p>Each note is drawn where it is fretted (the open string left of the nut), coloured by its buzz "
            f"level: the high-frequency energy the contacts add to the signal, relative to that of the same note "
            f"without the neck, in dB (pale green: no contact; green {QUIET_DB:g} dB and below; red {LOUD_DB:g} dB "
            f"and above; grey: the run failed). The number in a note is the fret it buzzes against most (largest "
            f"contact impulse). One line per plucking strength.</p>",
            "<div class='maps'>"]
    body.append(f"<div><h2>This set-up</h2>{_svg(notes, scale_length, fret_count, changed)}"
                f"<h3>Set-up</h3>{_parameters(parameters)}</div>")
    if other is not None:
        other_parameters = {}
        try:
            with open(os.path.join(compare, "setup.json"), encoding="utf-8") as f:
                other_parameters = json.load(f)
        except OSError:
            pass
        body.append(f"<div><h2>Compared with {html.escape(compare)}</h2>"
                    f"{_svg(other, scale_length, fret_count, changed)}<h3>Set-up</h3>{_parameters(other_parameters)}</div>")
    body.append("</div>")
    if other is not None:
        body.append(f"<h2>Notes that changed ({len(changed)})</h2><p>A note changed when its buzz level moved by "
                    f"{CHANGE_DB:g} dB or more or it buzzes against another fret; ringed in blue on both maps.</p>")
        body.append("<ul>" + "".join(f"<li>fret {k[0]}, strength {_fmt(k[1])} m: {html.escape(why)}</li>"
                                     for k, why in changed.items()) + "</ul>")
    body.append("<h2>Notes</h2>" + _table(notes, changed))
    body.append("</body></html>")
    tmp = os.path.join(out, "buzz_map.html.tmp")
    with open(tmp, "w", encoding="utf-8") as f:
        f.write("\n".join(body))
    os.replace(tmp, os.path.join(out, "buzz_map.html"))
