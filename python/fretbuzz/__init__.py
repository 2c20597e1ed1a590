"""fretbuzz: strings vibrating against obstacles (modal scheme with an exact energy balance).

    import fretbuzz
    r = fretbuzz.run("bass-pop", fs=400000, duration=0.05, progress=True)
    r.time, r.observation, r.energy, r.dissipated, r.summary
    c = fretbuzz.load_case("bass-pop"); c["K"] = 1e12
    r = fretbuzz.run(c, fs=400000, duration=0.05, out="out/pop")   # the CLI's files too
    r.plot(); r.audio(); r.save("elsewhere")
    table = fretbuzz.sweep("study.toml", out="out/study", progress=True)  # pandas DataFrame

The compiled part (fretbuzz._core) is the same C++ library as the `fretbuzz` program.
"""
from __future__ import annotations

import os
import sys
import warnings
from typing import Any, Callable, Optional, Union

from . import _core
from ._core import Case, InputError, Progress, RecordedRun, SolverError, cases, load_case
from .results import Results

__version__ = _core.__version__
__all__ = ["Case", "FretbuzzWarning", "InputError", "Progress", "Results", "SolverError", "cases", "load_case", "run",
           "__version__"]


class FretbuzzWarning(UserWarning):
    """What `fretbuzz run` prints as "fretbuzz: warning: ..." (e.g. modes above fs/2 under
    contact): run() emits each through Python's warnings module as well as keeping it in
    Results.summary["warnings"]."""

# Every other public function of the compiled part (each binding file in python/bindings/
# adds its own, e.g. estimate) is part of the package too, except the internals run() wraps.
_INTERNAL = {"simulate", "audio_file_names", "run_sweep_local"}
for _name in dir(_core):
    if not _name.startswith("_") and _name not in globals() and _name not in _INTERNAL:
        globals()[_name] = getattr(_core, _name)
        __all__.append(_name)

from .sweeps import read_table, sweep  # noqa: E402  (after the compiled names it uses)
from .setup_bench import Bench, setup  # noqa: E402

__all__ += ["sweep", "read_table", "Bench", "setup"]

CaseLike = Union[str, "os.PathLike[str]", Case]


def _resolve(case: CaseLike) -> Case:
    if isinstance(case, Case):
        return case.copy()  # the caller's case is left as it is
    if isinstance(case, (str, os.PathLike)):
        return load_case(os.fspath(case))
    raise TypeError(f"case: expected a built-in case name, a path to a .toml file or a fretbuzz.Case, "
                    f"got {type(case).__name__}")


def _progress_callback(progress: Union[bool, Callable[[Progress], Any], None], duration: float):
    """None, the caller's callable, or a progress bar (tqdm where installed, else a line on stderr)."""
    if progress is None or progress is False:
        return None, None
    if callable(progress) and not isinstance(progress, bool):
        return progress, None
    if progress is not True:
        raise TypeError(f"progress: expected True, False or a callable, got {type(progress).__name__}")
    try:
        from tqdm.auto import tqdm
    except ImportError:
        def line(p: Progress) -> None:
            print(f"\r  {100 * p.fraction:5.1f}%  t = {p.simulated_s:.4f} s  ETA {p.remaining_s:.1f} s",
                  end="", file=sys.stderr, flush=True)
        return line, None
    bar = tqdm(total=duration, unit="s", unit_scale=False, desc="fretbuzz", bar_format=
               "{desc}: {percentage:3.0f}%|{bar}| {n:.4f}/{total:g} s simulated [{elapsed}<{remaining}]")

    def update(p: Progress) -> None:
        bar.n = p.simulated_s
        bar.refresh()
    return update, bar


def run(case: CaseLike, *, fs: Optional[float] = None, duration: Optional[float] = None,
        observe: Optional[Any] = None, output_rate: Union[float, str, None] = None, lossless: bool = False,
        K: Optional[float] = None, alpha: Optional[float] = None, law: Optional[str] = None,
        restitution: Optional[float] = None, snapshots: float = 0.0,
        snapshot_until: Optional[float] = None, screen: bool = True, free_flight: bool = True,
        out: Union[str, "os.PathLike[str]", None] = None, velocity_audio: bool = False,
        progress: Union[bool, Callable[[Progress], Any]] = False, fade_in: Optional[float] = None,
        fade_out: Optional[float] = None) -> Results:
    """Runs a case and returns its Results.

    case: a built-in name (see cases()), a path to a .toml file, or a Case (not modified).
    fs, duration, K, alpha, output_rate ('native' for every step), observe (observation
    points in m, replacing the case's): override the case's values, checked together.
    law: the contact law at the obstacle, "penalty" or "impact" (Newton's, rigid), with
    restitution e in [0, 1] for the impact law.
    lossless: remove all damping. snapshots: also record the string shape at this rate (Hz),
    up to snapshot_until (s). screen, free_flight: the fast paths (False: the reference paths).
    out: also write the files of `fretbuzz run --out DIR` there (CSV, WAV, results.h5,
    summary.json), through the same writers; velocity_audio adds velocity.wav; fade_in and
    fade_out (s): the WAV files' raised-cosine fades (default 0.005 s in, none out; the
    summary records them with each file's full scale).
    progress: True for a progress bar (tqdm where installed), or a callable taking a
    fretbuzz.Progress, called about twice a second.
    Ctrl-C stops the run within about half a second with KeyboardInterrupt; `out` then
    receives no files. An exception the progress callable raises stops the run the same way
    and reaches the caller (it is called at least once, at the end).
    The warnings of the run (those `fretbuzz run` prints) are emitted as FretbuzzWarning and
    kept in Results.summary["warnings"].
    """
    for name, flag in (("lossless", lossless), ("screen", screen), ("free_flight", free_flight),
                       ("velocity_audio", velocity_audio)):
        if not isinstance(flag, bool):
            raise TypeError(f"{name}: expected a bool, got {type(flag).__name__}")
    c = _resolve(case)
    overrides = {key: value for key, value in (("fs", fs), ("duration", duration), ("K", K), ("alpha", alpha),
                                               ("law", law), ("restitution", restitution),
                                               ("observe", observe), ("output_rate", output_rate))
                 if value is not None}
    if overrides:
        c.update(overrides)
    if lossless:
        c.make_lossless()
    settings = {"snapshots": snapshots, "snapshot_until": snapshot_until, "screen": screen,
                "free_flight": free_flight, "velocity_audio": velocity_audio, "fade_in": fade_in, "fade_out": fade_out}
    callback, bar = _progress_callback(progress, c.duration)
    try:
        recorded = _core.simulate(c, out=out, progress=callback, **settings)
        if bar is not None:
            bar.n = bar.total
    finally:
        if bar is not None:
            bar.close()
        elif callback is not None and progress is True:
            print(file=sys.stderr)
    for text in recorded.summary.get("warnings", []):
        warnings.warn(text, FretbuzzWarning, stacklevel=2)
    return Results(recorded, c, settings, directory=out)
