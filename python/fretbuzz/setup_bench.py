"""The set-up bench from Python: an instrument's buzz map, what-ifs, one note's sound and
contacts, comparisons and advice, over the same C++ library as `fretbuzz setup`.

    import fretbuzz
    bench = fretbuzz.Bench("jazz-bass")                  # or an instrument file, or Bench.from_text(...)
    table = bench.map(progress=lambda note, done, total: print(done, total, note["buzz_fraction"]))
    looser = bench.with_changes(relief=0.7)              # the truss rod: relief 0.7 mm
    changed = looser.compare(looser.map(strings=["E"], strengths="medium"), table)
    note = bench.note("E", 12, "hard")                    # audio, pickup signal, contacts over time
    advice = bench.advise(table, strength="medium")
    fretbuzz.setup("jazz-bass", strings=["G"])            # the map as a DataFrame, in one call

This module is the contract for front ends (the studio page builds on it). Every method that
takes values checks them as `fretbuzz setup` checks its options and instrument files: a bad
value raises fretbuzz.InputError (a ValueError) whose message names the argument (or the
instrument file's key) and its allowed range, before anything runs. Lengths are in mm (or
strings with a unit: "0.3 mm", "5/64 in"), frequencies in Hz, times in s.

Tables (pandas DataFrames):
- map: one row per note and attack: string, fret (0 = open), strength, verdict ("clean",
  "marginal", "buzzes"; "" when not played), buzz_fraction (the share of the note's plucks
  heard to buzz) with its 90 % interval buzz_fraction_low and buzz_fraction_high, buzz_dB
  (their median level above the masked threshold, 0 dB: just heard; NaN when most touch
  nothing), buzz_fret (the fret they buzz against; "board" for the board or body; None),
  touch_fraction, plucks, clean_up_to (how much harder than the attack the note stays clean,
  a multiple of it; inf: at least 3 times), clean_up_to_value and its unit ("mm" or "m/s"),
  stiffness_sensitive ("" unless asked; "no", or the stiffness factors 0.5 and 1.5 that
  change the verdict), status ("ok", "frets out", "not played: ...", "failed: ..."),
  clearance_mm (the smallest gap between the note's string at rest and a fret past the stop),
  pluck_dB (each pluck's level), first_touch_s (when the plucks that touch first do, the median;
  pluck_touch_s each one's), audio (the WAV's name when the map wrote WAVs), deciding_pluck (the
  member of the note's ensemble whose outcome agrees with its verdict: the loudest pluck of a
  note that buzzes or is marginal, the loudest one not heard of a clean note; note(member=...)
  plays it).
- geometry: one row per string and fret (frets 0 .. N, 0 being the nut end of the fret line):
  string, fret, x_m (along the string from its nut), top_m (the fret's top above the fret
  plane), line_m (the fret line, without the fret's own offset), gap_m (the open string's gap
  over it: the action there).
"""
from __future__ import annotations

import json
import os
import queue
import threading
from typing import Any, Callable, Dict, Iterable, Iterator, List, Optional, Sequence, Union

from . import _core
from ._core import InputError, Instrument

__all__ = ["Bench", "setup"]

Millimetres = Union[float, int, str]
Progress = Optional[Callable[[dict, int, int], Any]]


def _names(values: Union[str, Iterable[str], None]) -> List[str]:
    if values is None:
        return []
    if isinstance(values, str):
        return [v for v in values.split(",") if v]
    return [str(v) for v in values]


def _frets(values: Union[int, Iterable[int], None]) -> List[int]:
    if values is None:
        return []
    if isinstance(values, int) and not isinstance(values, bool):
        values = [values]
    elif isinstance(values, (str, bytes, bool)) or not hasattr(values, "__iter__"):
        raise InputError(f"frets: {values!r} is not a fret or a list of frets (whole numbers, 0 for the open string)")
    frets = []
    for v in values:
        if isinstance(v, bool) or not isinstance(v, int) or v < 0:
            raise InputError(f"frets: {v!r} is not a fret (a whole number, 0 for the open string)")
        frets.append(v)
    return frets


def _jobs(jobs: Optional[int]) -> int:
    if jobs is None:
        return 0
    if isinstance(jobs, bool) or not isinstance(jobs, int) or not 1 <= jobs <= 256:
        raise InputError(f"jobs = {jobs!r} is out of range: must be a whole number in [1, 256] (or None: every core)")
    return jobs


def _frame(rows: List[dict], columns: Sequence[str]):
    import pandas
    frame = pandas.DataFrame(rows, columns=list(columns))
    for name in ("buzz_fret", "buzz_fret_before", "fret"):  # fret numbers stay whole, None stays None
        if name in frame.columns and frame[name].dtype.kind == "f":
            frame[name] = pandas.Series([r.get(name) for r in rows], dtype=object, index=frame.index)
    return frame


def _records(table) -> List[dict]:
    """A map's rows as the library reads them (a DataFrame's NaN as None, its float frets as int)."""
    records = table.to_dict("records") if hasattr(table, "to_dict") else [dict(r) for r in table]
    for r in records:
        for key in ("buzz_dB", "buzz_fret", "clean_up_to"):
            value = r.get(key)
            if isinstance(value, float) and value != value:
                r[key] = None
        if isinstance(r.get("buzz_fret"), float):
            r["buzz_fret"] = int(r["buzz_fret"])
    return records


MAP_COLUMNS = ("string", "fret", "strength", "verdict", "buzz_fraction", "buzz_fraction_low", "buzz_fraction_high",
               "buzz_dB", "buzz_fret", "touch_fraction", "plucks", "clean_up_to", "clean_up_to_value", "unit",
               "stiffness_sensitive", "status", "clearance_mm", "pluck_dB", "audio", "first_touch_s", "deciding_pluck")


class Bench:
    """An instrument on the set-up bench, with how its notes are played.

    Bench(instrument="jazz-bass", *, strengths="soft,medium,hard", finger=False, jobs=None,
          ensemble=None, fs=None, duration=None, listen=None, partial_scatter=None)

    instrument: a built-in name (fretbuzz.instruments()), the path of an instrument file, or a
    fretbuzz.Instrument. strengths: the attacks the map plays by default (soft, medium and hard
    finger plucks, pop, slap, or an amplitude such as "1.2 mm"). finger: play stopped notes with
    the finger model (slow) instead of the stand-in. jobs: threads (None: every core).
    ensemble, fs, duration: override the instrument's plucks per note, sampling rate (Hz) and
    seconds per note. listen: "rig" (the pickup's circuit and a cabinet, the default) or
    "pickup" (its full range). partial_scatter: each stopped note's partials detuned at random by
    this rms, in cents (the coherence study's knob; default 0). A Bench is a value: what-ifs
    return a new Bench; with_player(calibration) one whose attacks are the player's (as
    `fretbuzz setup --player calibration.json`).
    """

    def __init__(self, instrument: Union[str, Instrument] = "jazz-bass", *, strengths: str = "soft,medium,hard",
                 finger: bool = False, jobs: Optional[int] = None, ensemble: Optional[int] = None,
                 fs: Optional[float] = None, duration: Optional[float] = None, listen: Optional[str] = None,
                 partial_scatter: Optional[float] = None):
        if isinstance(instrument, Instrument):
            base = instrument
        elif isinstance(instrument, str):
            base = _core.load_instrument(instrument)
        else:
            raise TypeError(f"instrument: expected a name, a path or a fretbuzz.Instrument, got {type(instrument).__name__}")
        if not isinstance(finger, bool):
            raise TypeError(f"finger: expected a bool, got {type(finger).__name__}")
        self.instrument: Instrument = base.with_settings(ensemble=ensemble, fs=fs, duration=duration, listen=listen,
                                                         partial_scatter=partial_scatter)
        self.strengths = strengths
        self.finger = finger
        self.jobs = _jobs(jobs)
        self.changes: Dict[str, Any] = {}
        self.attack_scale: Optional[float] = None  # with_player's: every attack's size times it (None: as they are)
        self.instrument.geometry()  # every string clear of its frets, or InputError now

    @classmethod
    def from_text(cls, text: str, name: str = "instrument.toml", base_dir: str = ".", **kwargs) -> "Bench":
        """A Bench for the text of an instrument file (data files relative to base_dir)."""
        return cls(_core.instrument_from_text(text, name, base_dir), **kwargs)

    def _copy(self, instrument: Instrument, changes: Dict[str, Any]) -> "Bench":
        other = Bench.__new__(Bench)
        other.instrument, other.strengths, other.finger, other.jobs = instrument, self.strengths, self.finger, self.jobs
        other.changes = {**self.changes, **changes}
        other.attack_scale = self.attack_scale
        return other

    def with_player(self, calibration: Union[dict, float, str, "os.PathLike[str]", None]) -> "Bench":
        """A new Bench whose every attack (its maps', notes', advice's and dress's) is the
        player's, as `fretbuzz setup --player` plays them: each size times the calibration's
        attack_scale. calibration: what calibrate() returns, the path of a calibration.json, a
        scale, or None (the attacks as they are). InputError when the scale is not in (0, 10]
        or the calibration found none."""
        scale = None
        if isinstance(calibration, (str, os.PathLike)):  # read and checked as --player reads it
            scale = _core._setup_player_scale(os.fspath(calibration))
        elif calibration is not None:
            scale = calibration.get("attack_scale") if isinstance(calibration, dict) else calibration
            if scale is None:
                raise InputError("attack_scale: the calibration found no scale (" +
                                 str(calibration.get("statement") or "no reported note could be used") + ")")
            if isinstance(scale, bool) or not isinstance(scale, (int, float)):
                raise InputError(f"attack_scale: expected a number, got {type(scale).__name__}")
            scale = _core._setup_attack_scale(float(scale))  # the library's range
        other = self._copy(self.instrument, {})
        other.attack_scale = scale
        return other

    @property
    def _scale(self) -> float:
        """The attacks' scale as the library takes it (1: as they are)."""
        return 1.0 if self.attack_scale is None else self.attack_scale

    # The instrument -------------------------------------------------------------------

    @property
    def strings(self) -> List[str]:
        """The strings' names, low to high as in the file (e.g. ['E', 'A', 'D', 'G'])."""
        return list(self.instrument.strings)

    @property
    def frets(self) -> int:
        """The number of frets (notes are played at frets 0 .. frets)."""
        return self.instrument.frets

    @property
    def settings(self) -> dict:
        """fs_hz, duration_s, grid_step_m, output_rate_hz, observe_from_bridge_m, buzz_band_hz,
        audible_dB (the threshold a pluck's buzz level must reach to count as audible),
        ensemble, position_spread_m, strength_spread, seed, stopped_modes, listen ("rig" or
        "pickup"), partial_scatter_cents."""
        return self.instrument.settings

    def strings_table(self):
        """One row per string: name, frequency_hz, tension_n, linear_density, inharmonicity,
        gauge_m, tension_source, nut_gap_m (over fret 1), action12_m (over fret 12),
        relief_gap_m (at relief_fret, string pressed at fret 1 and the last fret),
        nut_height_m and saddle_height_m (the open string's ends above the fret plane),
        nut_axial_m (a fanned neck: the nut's place along the neck), lateral_nut_m and
        lateral_bridge_m (off the neck's centre line), scale_length_m."""
        keys = ("name", "scale_length_m", "frequency_hz", "tension_n", "linear_density", "inharmonicity", "gauge_m",
                "tension_source", "nut_gap_m", "action12_m", "relief_gap_m", "relief_fret", "nut_height_m",
                "saddle_height_m", "nut_axial_m", "lateral_nut_m", "lateral_bridge_m")
        return _frame([{k: s[k] for k in keys} for s in self.instrument.geometry()], keys)

    def geometry(self):
        """The neck under every string, fret by fret (see the module's doc: string, fret, x_m,
        top_m, line_m, gap_m), for a side view: heights in m above each string's fret plane."""
        rows = []
        for s in self.instrument.geometry():
            for k, (x, top, line, gap) in enumerate(zip(s["fret_x_m"], s["fret_top_m"], s["fret_line_m"], s["gap_m"])):
                rows.append({"string": s["name"], "fret": k, "x_m": x, "top_m": top, "line_m": line,
                             "gap_m": None if k == 0 else gap})
        return _frame(rows, ("string", "fret", "x_m", "top_m", "line_m", "gap_m"))

    def side_view(self, string: str) -> dict:
        """Everything a side view of one string draws (heights in m above its fret plane, x
        along it from the nut): 'frets' (the geometry() rows of that string), 'surface'
        (DataFrame x_m, z_m: the board and the body under the string), 'string' ((0,
        nut_height_m) to (scale_length_m, saddle_height_m): the open string at rest)."""
        import pandas
        for s in self.instrument.geometry():
            if s["name"] == string:
                g = self.geometry()
                return {"frets": g[g["string"] == string].reset_index(drop=True),
                        "surface": pandas.DataFrame({"x_m": s["surface_x_m"], "z_m": s["surface_z_m"]}),
                        "string": ((0.0, s["nut_height_m"]), (s["scale_length_m"], s["saddle_height_m"]))}
        raise InputError(f"string {string!r} is not on {self.instrument.name} (its strings: {', '.join(self.strings)})")

    # The map --------------------------------------------------------------------------

    def map(self, *, strings: Union[str, Iterable[str], None] = None, frets: Union[int, Iterable[int], None] = None,
            strengths: Optional[str] = None, progress: Progress = None, audio_dir: Optional[str] = None,
            stop: Optional[Callable[[], bool]] = None):
        """Plays the notes and returns the map (a DataFrame, see the module's doc).

        strings: names (default all); frets: 0 .. frets (default all, the last one included);
        strengths: attacks (default the Bench's). progress(note, done, total) is called on this
        thread as each note's verdict is ready (note: a dict with the map's columns): a page
        fills its map in as notes finish. An exception raised in it stops the map and
        propagates. stop(): asked about every 0.2 s; True stops the map (the notes finished so
        far are returned). audio_dir: also write each note's WAV there. Ctrl-C stops the map
        with KeyboardInterrupt."""
        rows = _core._setup_map(self.instrument, strengths or self.strengths, _names(strings), _frets(frets),
                                self.finger, self.jobs, audio_dir or "", progress, stop, self._scale)
        return _frame(rows, MAP_COLUMNS)

    def check(self, *, strings: Union[str, Iterable[str], None] = None, frets: Union[int, Iterable[int], None] = None,
              strengths: Optional[str] = None) -> int:
        """The number of notes (times attacks) map() would play with these arguments, without
        playing any; InputError for anything map() would refuse (a page checks its controls)."""
        return _core._setup_check(self.instrument, strengths or self.strengths, _names(strings), _frets(frets), self.finger,
                                  self._scale)

    def notes(self, *, strings=None, frets=None, strengths: Optional[str] = None) -> Iterator[dict]:
        """The map as an iterator: yields each note (a dict with the map's columns) as it is
        ready, plays them on a thread of its own. Closing the iterator early stops the map."""
        results: "queue.Queue[Any]" = queue.Queue()
        done = threading.Event()
        finished = object()

        def work() -> None:
            try:
                self.map(strings=strings, frets=frets, strengths=strengths,
                         progress=lambda note, *_: results.put(note), stop=done.is_set)
                results.put(finished)
            except BaseException as e:  # handed to the consumer
                results.put(e)

        thread = threading.Thread(target=work, daemon=True)
        thread.start()
        try:
            while True:
                item = results.get()
                if item is finished:
                    return
                if isinstance(item, BaseException):
                    raise item
                yield item
        finally:
            done.set()
            thread.join()

    def calibrate(self, report: Union[str, "os.PathLike[str]"], *, progress: Progress = None) -> dict:
        """The attack scale that explains what a player hears (docs/setup.md, "Calibrating the
        attack to your own ears"): report is the CSV's text (string,fret,heard[,strength];
        heard: buzz or clean) or a path to it. Plays the reported notes on this Bench's
        instrument, at the attacks as the instrument has them (a player's scale is not applied),
        and returns what calibration.json holds: attack_scale, attack_scale_low and
        attack_scale_high, explained, disagreements, statement, disagreeing and notes
        (with_player applies it).
        progress(note, done, total) as map(); Ctrl-C stops it with KeyboardInterrupt."""
        source = "(text)"
        if isinstance(report, os.PathLike):
            source = os.fspath(report)
            with open(source, encoding="utf-8") as f:
                report = f.read(4 << 20)
        return json.loads(_core._setup_calibrate(self.instrument, report, source, self.finger, self.jobs, progress))

    def note(self, string: str, fret: int, strength: str = "medium", *, member: int = 0,
             wav: Optional[str] = None) -> dict:
        """One pluck of one note, with everything kept: 'audio' (NumPy array, the pickup's
        displacement band-limited to 'audio_rate_hz' = 48 kHz, as the note's WAV before it is
        normalised and faded), 'signal' and 'signal_rate_hz' (the same at the run's output
        rate, unfiltered), 'contacts' (DataFrame time_s, impulse_n_s, peak_force_n, fret: the
        obstacle's pushes on the string in 0.5 ms stretches and the fret that took most),
        'touched', 'heard' (heard to buzz, as the verdicts count a pluck), 'buzz_dB', 'buzz_fret',
        'first_contact_s', 'peak_force_n'. member: which
        pluck of the note's ensemble (0: the attack itself; a map's deciding_pluck: the one its
        verdict rests on). wav: also write the pluck's sound there, as long as a map's note's."""
        if isinstance(fret, bool) or not isinstance(fret, int) or fret < 0:
            raise InputError(f"fret: {fret!r} is not a fret (0 .. {self.frets})")
        if isinstance(member, bool) or not isinstance(member, int) or member < 0:
            raise InputError(f"member: {member!r} is not a pluck of the ensemble (0 .. {self.settings['ensemble'] - 1})")
        out = _core._setup_note(self.instrument, string, fret, strength, member, self.finger, wav or "",
                                self._scale)
        out["contacts"] = _frame(out["contacts"], ("time_s", "impulse_n_s", "peak_force_n", "fret"))
        return out

    # What-ifs, comparisons, advice ----------------------------------------------------

    def with_changes(self, *, relief: Optional[Millimetres] = None, action12: Optional[Dict[str, Millimetres]] = None,
                     nut: Optional[Dict[str, Millimetres]] = None, saddle: Optional[Dict[str, Millimetres]] = None,
                     fret_offsets: Optional[Dict[int, Union[Millimetres, str]]] = None,
                     tune: Optional[Dict[str, Union[float, str]]] = None, string_set: Optional[str] = None,
                     relief_change: Optional[Millimetres] = None,
                     action: Optional[Dict[int, Dict[str, Millimetres]]] = None,
                     nut_change: Optional[Dict[str, Millimetres]] = None,
                     saddle_change: Optional[Dict[str, Millimetres]] = None,
                     truss_rod_turns: Union[float, str, None] = None,
                     saddle_turns: Optional[Dict[str, Union[float, str]]] = None) -> "Bench":
        """A new Bench after set-up changes, each leaving the rest where it physically is:
        relief (the truss rod set for this relief gap, mm, nut and saddles staying put);
        action12 {string: mm} (the saddle set for this gap over fret 12) and action {fret:
        {string: mm}} (the same at any fret, e.g. {17: {"E": "3/32 in"}}); nut {string: mm} (the
        slot filed for this gap over fret 1); saddle {string: mm} (its height above the fret
        plane); relief_change, nut_change {string: mm} and saddle_change {string: mm}: moved by
        that much from where they are (+ up, e.g. saddle_change={"E": "-0.25 mm"});
        truss_rod_turns (+ clockwise, tighter: less relief, e.g. "1/4") and saddle_turns
        {string: turns} (+ up), where the instrument file's [adjusters] say what a turn does;
        fret_offsets {k: mm} (fret k raised, or lowered if negative, by that much) or
        {k: "level"} (dressed down to its neighbours); tune {string: note or Hz} (retuned, e.g.
        {"E": "D2"} for drop D) and string_set (a named set's strings at the same pitches): the
        neck bows with the strings' pull, the truss rod left as it was. A length is mm, or a
        string with its unit (mm, in, "3/32 in", "12 thou"). InputError names the argument."""
        # A relief of 0 is a change too; an empty {} is none.
        changes = {k: v for k, v in (("relief", relief), ("action12", action12), ("nut", nut), ("saddle", saddle),
                                     ("fret_offsets", fret_offsets), ("tune", tune), ("string_set", string_set),
                                     ("relief_change", relief_change), ("action", action), ("nut_change", nut_change),
                                     ("saddle_change", saddle_change), ("truss_rod_turns", truss_rod_turns),
                                     ("saddle_turns", saddle_turns))
                   if v is not None and not (isinstance(v, (dict, str)) and not v)}
        instrument = self.instrument.with_changes(relief=relief, action12=action12 or {}, nut=nut or {},
                                                  saddle=saddle or {}, fret_offsets=fret_offsets or {}, tune=tune or {},
                                                  string_set=string_set, relief_change=relief_change,
                                                  action=action or {}, nut_change=nut_change or {},
                                                  saddle_change=saddle_change or {},
                                                  truss_rod_turns=truss_rod_turns, saddle_turns=saddle_turns or {})
        return self._copy(instrument, changes)

    @staticmethod
    def compare(now, before):
        """How each note of map `now` changed from map `before` (DataFrames from map(), or
        read from two buzz_map.csv files): the map's columns and change ("worse": a worse
        verdict, more of its plucks buzz, a clean_up_to 10 % lower, or as many 3 dB louder;
        "better"; "moved": as many, against another fret;
        "same"; "new": not in `before`), reason (the first of those rules that decided it:
        "verdict", "plucks", "margin", "loudness", "fret"; "" for same and new),
        buzz_fraction_before, buzz_dB_before, buzz_fret_before."""
        out = _core._setup_compare(_records(now), _records(before))
        return _frame(out, MAP_COLUMNS + ("change", "reason", "buzz_fraction_before", "buzz_dB_before",
                                          "buzz_fret_before"))

    def advise(self, map=None, *, strength: Optional[str] = None, strings: Union[str, Iterable[str], None] = None,
               frets: Union[int, Iterable[int], None] = None, tolerate: str = "",
               progress: Optional[Callable[[dict, int], Any]] = None) -> dict:
        """The bench's advice (docs/setup.md, section 5), each answer played: 'lowest_action'
        (per string, the lowest gap over fret 12 on a 0.05 mm grid at which every note passes,
        action12_mm and lowest_clean_action12_mm with their _in, the saddle move to it
        saddle_change_mm (+ up) and saddle_change_in, and what the step below does),
        'fall_away' (where the upper frets set a string's action: what the lower frets would
        allow, and the fall-away predicted to get there), 'proud_frets' (frets standing above
        their neighbours whose levelling makes failing notes pass), 'relief' (the relief with
        the fewest failing notes, played; the range predicted clean), 'units' (the instrument
        file's: "mm", "64ths" or "thousandths"). strength: the attack (default the strongest of
        the Bench's); strings, frets: the notes answered for (default all); tolerate:
        "marginal" (marginal notes pass), "above=K" (notes above fret K may buzz), both,
        comma-separated, or "none" (every note must be clean); "" as set-ups do: marginal
        notes, and on a bass the notes above fret 15. A saddle move over 1 mm or a relief over
        0.5 mm is flagged 'beyond_setup', what it means in 'beyond_setup_says'. map: this
        Bench's map at that attack, with clean_up_to (played if not given): it places the
        searches. progress(note, probes): each note a search plays (a dict with the map's
        columns) and the probes played so far (a search has no total to count down)."""
        attack = strength or self.strengths.split(",")[-1]
        if map is None:
            _core._setup_tolerance(self.instrument, tolerate)  # refused before anything is played
            map = self.map(strings=strings, frets=frets, strengths=attack)
        return json.loads(_core._setup_advice(self.instrument, _records(map), attack, _names(strings), _frets(frets),
                                              tolerate, self.finger, self.jobs, self._scale, progress))

    def dress(self, map=None, *, strength: Optional[str] = None, strings: Union[str, Iterable[str], None] = None,
              frets: Union[int, Iterable[int], None] = None, tolerate: str = "", depth: Optional[Millimetres] = None,
              crown: Optional[Millimetres] = None, fall_away: Optional[int] = None,
              progress: Optional[Callable[[dict, int], Any]] = None) -> dict:
        """The virtual fret dress (docs/setup.md, section 5): the least taken off each fret so
        that every note passes at the attack. 'frets' (fret, remove_mm, remove_in per fret),
        'total_mm', 'fall_away' (from_fret and depth_mm, or None), 'clean', 'unresolved' (what it
        could not clear, and why), 'after' (the map after it, a DataFrame), 'csv' (dress.csv's
        text), 'text', 'dressed' (a Bench with the frets dressed). depth: at most this off a fret
        (mm, default 0.3); crown: crowns kept this high above the board (default 0.75 mm);
        fall_away: first a fall-away over the frets past this one. strength, strings, frets,
        tolerate, map and progress as advise()."""
        attack = strength or self.strengths.split(",")[-1]
        # Every argument refused before anything is played.
        _core._setup_dress_check(self.instrument, attack, _names(strings), _frets(frets), tolerate, depth, crown,
                                 fall_away, self.finger, self._scale)
        if map is None:
            map = self.map(strings=strings, frets=frets, strengths=attack)
        out = _core._setup_dress(self.instrument, _records(map), attack, _names(strings), _frets(frets), tolerate,
                                 depth, crown, fall_away, self.finger, self.jobs, self._scale, progress)
        out["after"] = _frame(out["after"], MAP_COLUMNS)
        out["dressed"] = self._copy(out["dressed"], {"dress": True})
        return out

    def __repr__(self) -> str:
        changes = f", changes {self.changes}" if self.changes else ""
        player = f", the player's attacks x{self.attack_scale:g}" if self.attack_scale is not None else ""
        return (f"<fretbuzz.Bench {self.instrument.name}: strings {','.join(self.strings)}, strengths {self.strengths}"
                f"{changes}{player}>")


def setup(instrument: Union[str, Instrument] = "jazz-bass", *, strings=None, frets=None,
          strengths: str = "soft,medium,hard", finger: bool = False, jobs: Optional[int] = None,
          progress: Progress = None, **changes):
    """The buzz map of an instrument as a DataFrame, in one call: Bench(instrument, strengths=...,
    finger=..., jobs=...).with_changes(**changes).map(strings=..., frets=..., progress=...)."""
    bench = Bench(instrument, strengths=strengths, finger=finger, jobs=jobs)
    if changes:
        bench = bench.with_changes(**changes)
    return bench.map(strings=strings, frets=frets, progress=progress)
