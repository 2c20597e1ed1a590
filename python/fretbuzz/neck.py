"""Neck set-up studies: which notes of a string buzz, on which fret, how loud.

`fretbuzz setup CASE --out DIR` (python3 -m fretbuzz.neck) plays every fret of the string
of a case with a fretboard obstacle ([obstacle] type = "fretboard"; e.g. the built-in
bass-neck) at one or more plucking strengths, as one sweep, and draws the buzz map
(fretbuzz.buzzmap) from its table.

Two models of the stopped note (docs/sweeps.md compares them). With `--finger`
(fingered_study_spec) the note of fret k is the whole string resting on fret k, a finger
pressing it just behind the fret and a pick pulling it and letting go: faithful, but about
80 times the CPU time. By default (study_spec) the note of fret k is the string clamped on
the top of fret k, i.e. a shorter string from fret k to the bridge over the frets beyond it. Its case
is the open-string case rewritten in that frame (the fret positions of 12-TET from the
scale length S' = S 2^(-k/12) are exactly x_(k+n) - x_k; the string at rest runs from fret
k's top to the bridge, so every fret top is measured from that line). The fret tops are
exact; between frets the fingerboard's relief is interpolated linearly (micrometres, a
millimetre below the fret tops); the body past the board keeps its smallest gap. The
pluck and observation points keep their distance to the bridge. The last fret cannot be
stopped this way (no fret beyond it in the fretboard model): frets 0 .. N-1 are played.
"""
from __future__ import annotations

import argparse
import math
import os
import sys
import tomllib
from typing import Dict, List, Optional, Sequence

from . import _core
from ._core import InputError

__all__ = ["Neck", "study_spec", "main"]


class Neck:
    """The set-up of a fretboard obstacle in the case file's terms (lengths in m)."""

    def __init__(self, case_text: str, case_name: str):
        doc = tomllib.loads(case_text)
        obstacle = doc.get("obstacle", {})
        if obstacle.get("type") != "fretboard":
            raise InputError(f"{case_name}: a set-up study needs [obstacle] type = \"fretboard\" "
                             f"(e.g. the built-in bass-neck), not {obstacle.get('type')!r}")
        self.measured_modes = "table" in doc.get("modes", {}) or "measured" in doc.get("modes", {})
        self.case_name = case_name
        self.L = float(doc["string"]["L"])
        self.modes = int(doc["string"]["modes"])
        self.S = float(obstacle.get("scale_length", self.L))
        frets = obstacle["frets"]
        self.N = int(frets["count"])
        self.fret_height = float(frets["height"])
        self.action_nut = float(obstacle["action_nut"])
        self.action_last = float(obstacle["action_last_fret"])
        self.relief = obstacle.get("relief", 0.0)
        self.board_end = float(obstacle.get("board_end", self.fret_x(self.N)))
        self.body = obstacle.get("body_height")
        # Individual fret heights (obstacle.frets.height_offsets); `--raise` sets them too.
        self.raised: Dict[int, float] = {int(n): float(h) for n, h in frets.get("height_offsets", {}).items()}
        self.wave_speed = math.sqrt(float(doc["string"]["T"]) / float(doc["string"]["mu"]))
        self.T = float(doc["string"]["T"])
        excitation = doc["excitation"]
        self.pluck_width = float(excitation.get("width", 0.0))
        self.pluck_x = float(excitation["position"])
        self.amplitude = float(excitation["amplitude"])
        self.observe = [float(x) for x in doc.get("observe", {}).get("x", [])]

    def fret_x(self, n: int) -> float:
        return self.S * (1.0 - 2.0 ** (-n / 12.0))

    def _relief_depth(self, x: float) -> float:
        """As NeckRelief::depth_at: a bow 4 d s (1 - s), or linear through measured points."""
        last = self.fret_x(self.N)
        if x <= 0.0 or x >= last:
            return 0.0
        if not isinstance(self.relief, list):
            s = x / last
            return 4.0 * float(self.relief) * s * (1.0 - s)
        points = [(0.0, 0.0)] + [(float(a), float(b)) for a, b in self.relief] + [(last, 0.0)]
        for (x0, d0), (x1, d1) in zip(points, points[1:]):
            if x0 <= x <= x1:
                return d0 + (d1 - d0) * (x - x0) / (x1 - x0)
        return 0.0

    def fret_line(self, n: int) -> float:
        """Height of the fret line at fret n below the open string at rest (negative, m)."""
        x = self.fret_x(n)
        action = self.action_nut + (self.action_last - self.action_nut) * x / self.fret_x(self.N)
        return -action - self._relief_depth(x)

    def fret_top(self, n: int) -> float:
        """Height of fret n's top below the open string at rest (negative, m), its offset included."""
        return self.fret_line(n) + self.raised.get(n, 0.0)

    def note(self, k: int) -> Dict[str, object]:
        """The case-file values of the note stopped at fret k (k = 0: the open string), clamped
        on fret k's top (the stand-in)."""
        if self.measured_modes:
            raise InputError(f"{self.case_name}: [modes] table/measured fix the frequencies of one string length; "
                             f"the clamped stand-in shortens the string, so give models ([modes.frequency], "
                             f"[modes.damping]), or play the notes with a finger (--finger)")
        if not 0 <= k < self.N:
            raise InputError(f"--frets: fret {k} is not in [0, {self.N - 1}] (the last fret, {self.N}, "
                             f"has no fret beyond it to buzz against in this stand-in)")
        xk = self.fret_x(k)
        length = self.L - xk
        # The string at rest: from fret k's top (the nut's line for the open string) to the bridge.
        rest_k = self.fret_top(k) if k > 0 else 0.0

        def rest(x: float) -> float:
            return rest_k * (self.L - x) / length

        count = self.N - k
        # The fret line through the frets beyond k, seen from the stopped string; the
        # individual fret heights stay offsets from it, renumbered from the stopped fret.
        tops = [self.fret_line(k + n) - rest(self.fret_x(k + n)) for n in range(1, count + 1)]
        xs = [self.fret_x(k + n) - xk for n in range(1, count + 1)]
        action_nut = self.action_nut if k == 0 else 0.0
        action_last = -tops[-1]
        relief = [[x, -top - (action_nut + (action_last - action_nut) * x / xs[-1])]
                  for x, top in zip(xs[:-1], tops[:-1])]
        dx = self.L / (self.modes + 1)
        values: Dict[str, object] = {
            "string.L": length,
            "string.modes": max(1, round(length / dx) - 1),
            "obstacle.scale_length": self.S * 2.0 ** (-k / 12.0),
            "obstacle.frets.count": count,
            "obstacle.action_nut": action_nut,
            "obstacle.action_last_fret": action_last,
            "obstacle.relief": relief if relief else 0.0,
            "obstacle.board_end": self.board_end - xk,
            "excitation.position": self.pluck_x - xk,
            "obstacle.frets.height_offsets": {n - k: h for n, h in sorted(self.raised.items()) if n > k},
        }
        if self.body is not None:
            values["obstacle.body_height"] = float(self.body) - rest(self.board_end)
        if self.observe:
            values["observe.x"] = [x - xk for x in self.observe]
        if self.pluck_x <= xk or any(x <= xk for x in self.observe):
            raise InputError(f"--frets: fret {k} (x = {xk:.4g} m) is beyond the pluck or an observation point; "
                             f"play frets below it")
        return values

    def check_fingered(self, k: int) -> None:
        """Fret k can be played with a finger: a fret of the neck, below the pluck and the
        observation points (the finger sits just behind it)."""
        if not 0 <= k <= self.N:
            raise InputError(f"--frets: fret {k} is not in [0, {self.N}]")
        if k > 0 and (self.pluck_x <= self.fret_x(k) or any(x <= self.fret_x(k) for x in self.observe)):
            raise InputError(f"--frets: fret {k} (x = {self.fret_x(k):.4g} m) is beyond the pluck or an observation "
                             f"point; play frets below it")

    def parameters(self) -> Dict[str, object]:
        """The set-up as the buzz map shows it."""
        p: Dict[str, object] = {"case": self.case_name, "scale length (m)": self.S, "frets": self.N,
                                "fret height (mm)": 1e3 * self.fret_height,
                                "action at the nut (mm)": 1e3 * self.action_nut,
                                "action at the last fret (mm)": 1e3 * self.action_last,
                                "relief (mm)": (f"{1e3 * self.relief:g} (bow)" if not isinstance(self.relief, list)
                                                else ", ".join(f"{1e3 * d:g} at {x:g} m" for x, d in self.relief))}
        for n, h in sorted(self.raised.items()):
            p[f"fret {n} raised (mm)"] = 1e3 * h
        return p

    def setup_values(self) -> Dict[str, object]:
        """The set-up as case-file keys (what a fingered study writes into the whole case)."""
        values: Dict[str, object] = {"obstacle.action_nut": self.action_nut,
                                     "obstacle.action_last_fret": self.action_last}
        if not isinstance(self.relief, list):
            values["obstacle.relief"] = float(self.relief)
        for n, h in sorted(self.raised.items()):
            values[f"obstacle.frets.height_offsets.{n}"] = h
        return values


def _toml(value: object) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{k} = {_toml(v)}" for k, v in value.items()) + " }" if value else "{}"
    if isinstance(value, tuple):
        value = list(value)
    return "[" + ", ".join(_toml(v) for v in value) + "]"


def study_spec(neck: Neck, case: str, frets: Sequence[int], strengths: Sequence[float],
               fixed: Optional[Dict[str, object]] = None) -> str:
    """The sweep spec of a set-up study: one run per (fret, strength), zipped."""
    notes = [(k, a) for k in frets for a in strengths]
    values = {k: neck.note(k) for k in frets}
    lines = ["# A neck set-up study written by `fretbuzz setup` (stand-in stopped notes: see",
             "# the fretbuzz.neck module).", "[sweep]", f"case = {_toml(case)}", 'combine = "zip"', "audio = true", ""]
    if fixed:
        lines.append("[set]")
        lines += [f"{_toml(key)} = {_toml(value)}" for key, value in fixed.items()]
        lines.append("")
    lines += ["[[parameter]]", 'key = "fret"', "label = true", f"values = {_toml([k for k, _ in notes])}", ""]
    lines += ["[[parameter]]", 'key = "excitation.amplitude"', f"values = {_toml([float(a) for _, a in notes])}", ""]
    for key in values[frets[0]]:
        lines += ["[[parameter]]", f"key = {_toml(key)}", f"values = {_toml([values[k][key] for k, _ in notes])}", ""]
    return "\n".join(lines)


# Fretted notes: the finger lands first (the default `fret = k` finger: 0 to 5 N over 5 ms),
# then the pick pulls the string away from the neck and lets go.
FINGER_SETTLES_S = 6e-3
PULL_PERIODS = 2        # the pull lasts whole periods of the note: it leaves no swing of its own
RELEASE_S = 1e-4


def pick_gesture(neck: Neck, k: int, amplitude: float) -> Dict[str, object]:
    """The pick of a fretted note: a force over the pluck's width, ramped up over whole periods
    of the stopped string's fundamental (a linear ramp of m periods leaves an oscillator at rest
    on its new equilibrium), to the force whose static deflection at the pluck point is
    `amplitude`, F = A T L' / (a (L' - a)) on the stopped length L', then let go."""
    length = neck.L - (neck.fret_x(k) if k else 0.0)
    a = neck.pluck_x - (neck.fret_x(k) if k else 0.0)
    force = amplitude * neck.T * length / (a * (length - a))
    end = FINGER_SETTLES_S + PULL_PERIODS * 2.0 * length / neck.wave_speed
    profile = [[0.0, 0.0], [FINGER_SETTLES_S, 0.0], [end, force], [end + RELEASE_S, 0.0]]
    return {"type": "force", "position": neck.pluck_x, "width": neck.pluck_width, "direction": "up",
            "force": profile}


def pressed_shape(neck: Neck, k: int) -> Dict[str, object]:
    """The string at rest pressed on fret k: straight from the nut to fret k's top (at the grid
    point that carries it) and on to the bridge, so the finger lands on a string already
    resting on the fret and sends no wave of its own down the note. The open string: at rest.
    (A fret with a crown wider than a grid point is taken at its centre.)"""
    if k == 0:
        return {"type": "sine", "mode": 1, "amplitude": 0.0}
    dx = neck.L / (neck.modes + 1)
    at = [round(neck.fret_x(n) / dx) * dx for n in range(neck.N + 1)]  # the grid points of the frets
    # The lowest triangle on fret k that clears every fret top (a high fret holds it up: the
    # finger then presses it home); 1 pm up, so that round-off never puts it into a fret.
    apex = max([neck.fret_top(k)] + [neck.fret_top(n) * at[k] / at[n] for n in range(1, k)] +
               [neck.fret_top(n) * (neck.L - at[k]) / (neck.L - at[n]) for n in range(k + 1, neck.N + 1)])
    return {"type": "triangle", "position": at[k], "amplitude": apex + 1e-12}


def fingered_study_spec(neck: Neck, case: str, frets: Sequence[int], strengths: Sequence[float],
                        fixed: Optional[Dict[str, object]] = None) -> str:
    """The sweep spec of a set-up study with fretted notes: the whole neck, the string resting
    on fret k (pressed_shape), a finger pressing it just behind fret k (`[[finger]] fret = k`,
    the case files' default finger; none for the open string), then a pick (pick_gesture) pulling it by the static
    amplitude `strength` and letting go. The set-up is written into the case's own keys. One run
    per (fret, strength), zipped."""
    notes = [(k, a) for k in frets for a in strengths]
    lines = ["# A neck set-up study written by `fretbuzz setup --finger` (fretted notes: see the",
             "# fretbuzz.neck module).", "[sweep]", f"case = {_toml(case)}", 'combine = "zip"', "audio = true", "",
             "[set]"]
    lines += [f"{_toml(key)} = {_toml(value)}" for key, value in {**neck.setup_values(), **(fixed or {})}.items()]
    lines += ["", "[[parameter]]", 'key = "fret"', "label = true", f"values = {_toml([k for k, _ in notes])}", ""]
    lines += ["[[parameter]]", 'key = "strength_m"', "label = true",
              f"values = {_toml([float(a) for _, a in notes])}", ""]
    fingers = ", ".join(f"[{{ fret = {k} }}]" if k else "[]" for k, _ in notes)
    lines += ["[[parameter]]", 'key = "finger"', f"values = [{fingers}]", ""]
    shapes = ", ".join(_toml(pressed_shape(neck, k)) for k, _ in notes)
    lines += ["[[parameter]]", 'key = "excitation"', f"values = [{shapes}]", ""]
    picks = ", ".join(f"[{_toml(pick_gesture(neck, k, a))}]" for k, a in notes)
    lines += ["[[parameter]]", 'key = "gesture"', f"values = [{picks}]", ""]
    return "\n".join(lines)


def pluck_ends(neck: Neck, frets: Sequence[int]) -> float:
    """When the last pick of a fretted study lets go (s)."""
    return max(pick_gesture(neck, k, 1.0)["force"][-1][0] for k in frets)


def _frets(text: str, neck: Neck, fingered: bool = False) -> List[int]:
    frets: List[int] = []
    for part in text.split(","):
        try:
            if "-" in part:
                a, b = (int(v) for v in part.split("-"))
                frets += list(range(a, b + 1))
            else:
                frets.append(int(part))
        except ValueError:
            raise InputError(f"--frets {text!r}: give frets as 0-19 or 0,3,5") from None
    if not frets:
        raise InputError("--frets: empty")
    for k in frets:
        neck.check_fingered(k) if fingered else neck.note(k)  # in range, pluck beyond it
    return frets


def _numbers(text: str, name: str) -> List[float]:
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        raise InputError(f"{name} {text!r}: give numbers separated by commas") from None
    if not values or not all(math.isfinite(v) and v > 0 for v in values):
        raise InputError(f"{name} {text!r}: every value must be a number > 0")
    return values


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="fretbuzz setup", description="Neck set-up study: the buzz map of a string.")
    parser.add_argument("case", help="a case with a fretboard obstacle (built-in bass-neck, or a .toml file)")
    parser.add_argument("--out", required=True)
    parser.add_argument("--frets", help="frets to play, e.g. 0-19 (default: 0 to the second-last fret)")
    parser.add_argument("--strength", help="pluck amplitudes in m, e.g. 1e-3,2e-3 (default: the case's)")
    parser.add_argument("--relief", type=float, help="neck relief: bow depth at mid-span, m")
    parser.add_argument("--action-nut", type=float, help="action at the nut, m")
    parser.add_argument("--action-last-fret", type=float, help="action at the last fret, m")
    parser.add_argument("--raise", dest="raised", action="append", default=[], metavar="FRET:M",
                        help="raise one fret's top by M metres (negative: lower), e.g. 7:0.05e-3; repeatable")
    parser.add_argument("--finger", action="store_true",
                        help="fretted notes: a finger presses the string behind each fret (slower); default: the "
                             "string clamped on the fret's top")
    parser.add_argument("--fs", type=float)
    parser.add_argument("--duration", type=float)
    parser.add_argument("--compare", help="another study's output directory: both maps side by side")
    parser.add_argument("--jobs", type=int)
    parser.add_argument("--scheduler")
    parser.add_argument("--resume", action="store_true")
    parser.add_argument("--quiet", action="store_true")
    a = parser.parse_args(argv)
    from . import buzzmap, sweeps
    try:
        if os.path.exists(a.case) or a.case.endswith(".toml"):
            try:
                with open(a.case, encoding="utf-8") as f:
                    text = f.read()
            except OSError as e:
                raise InputError(f"case {a.case}: cannot be read ({e.strerror})") from None
            case = os.path.abspath(a.case)
        else:
            text = _core.load_case(a.case).source_text
            case = a.case
        neck = Neck(text, a.case)
        for name, value in (("relief", a.relief), ("action_nut", a.action_nut), ("action_last", a.action_last_fret)):
            if value is not None:
                if not (math.isfinite(value) and abs(value) <= 0.01 and (name == "relief" or value >= 0)):
                    raise InputError(f"--{name.replace('_', '-')} = {value!r}: must be in "
                                     f"{'[-0.01, 0.01]' if name == 'relief' else '[0, 0.01]'} m")
                setattr(neck, name, value)
        for item in a.raised:
            try:
                fret, height = item.split(":")
                neck.raised[int(fret)] = float(height)
            except ValueError:
                raise InputError(f"--raise {item!r}: give FRET:METRES, e.g. 7:0.05e-3") from None
            if not 1 <= int(fret) <= neck.N or not -neck.fret_height <= float(height) <= 1e-3:
                raise InputError(f"--raise {item!r} (obstacle.frets.height_offsets.{fret}): fret in [1, {neck.N}], "
                                 f"offset in [-{neck.fret_height:g} (down to the board), 0.001] m")
        if a.frets:
            frets = _frets(a.frets, neck, a.finger)
        else:
            frets = list(range(neck.N + 1 if a.finger else neck.N))
            if a.finger:
                frets = [k for k in frets if k == 0 or neck.fret_x(k) < min([neck.pluck_x, *neck.observe])]
        strengths = _numbers(a.strength, "--strength") if a.strength else [neck.amplitude]
        fixed = {k: v for k, v in (("run.fs", a.fs), ("run.duration", a.duration)) if v is not None}
        if a.compare is not None and not os.path.exists(os.path.join(a.compare, "buzz_map.csv")):
            raise InputError(f"--compare {a.compare}: holds no buzz_map.csv (the --out of an earlier `fretbuzz setup`)")
        if a.finger:
            duration = a.duration if a.duration is not None else float(tomllib.loads(text)["run"]["duration"])
            if not duration > pluck_ends(neck, frets) + 0.01:
                raise InputError(f"--duration {duration:g}: a fretted study lets the finger settle and pulls the "
                                 f"string for whole periods first; give at least "
                                 f"{pluck_ends(neck, frets) + 0.01:.3g} s")
        spec_text = (fingered_study_spec if a.finger else study_spec)(neck, case, frets, strengths, fixed)
        spec = _core.SweepSpec.parse(spec_text, os.path.join(a.out, "sweep", "sweep.toml"), os.path.abspath(a.out))
        spec.check()  # every note's case, before anything is written
        progress = None if a.quiet else sweeps._line_printer()
        outcome = sweeps.run_sweep(spec, os.path.join(a.out, "sweep"), jobs=a.jobs, resume=a.resume,
                                   scheduler=a.scheduler, progress=progress)
        if progress is not None and sys.stderr.isatty():
            print(file=sys.stderr)
        table = sweeps.read_table(os.path.join(a.out, "sweep"))
        notes = buzzmap.notes_from_table(table, "fret", os.path.join(a.out, "sweep"), a.out,
                                         features_from_the_note=not a.finger)
        parameters = neck.parameters()
        parameters["stopped notes"] = ("a finger behind the fret (--finger)" if a.finger
                                       else "the string clamped on the fret's top (stand-in)")
        buzzmap.write(a.out, notes, parameters, neck.S, neck.N, compare=a.compare)
    except InputError as e:
        print(f"fretbuzz: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"\nfretbuzz: interrupted; finish with --resume", file=sys.stderr)
        return 130
    except (OSError, RuntimeError) as e:
        print(f"fretbuzz: {e}", file=sys.stderr)
        return 1
    print(f"fretbuzz: {len(notes)} notes ({outcome['computed']} computed, {outcome['failed']} failed) in "
          f"{outcome['wall_seconds']:.3g} s; buzz map in {a.out}/buzz_map.html and buzz_map.csv", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
