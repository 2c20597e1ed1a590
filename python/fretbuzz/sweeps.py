"""Parameter sweeps: fretbuzz.sweep() on this machine's threads or on a Dask cluster.

    table = fretbuzz.sweep("study.toml", out="out/study", progress=True)        # pandas DataFrame
    table = fretbuzz.sweep("study.toml", out="out/study", scheduler="tcp://10.0.0.5:8786")

Both write the same row files (DIR/runs/NNNNNN.json) and the same table (DIR/results.csv,
DIR/results.h5) through the compiled SweepStore, so a sweep started in one place can be
resumed (resume=True) in the other. On Dask each run is one task calling SweepSpec.run_row
on a worker (the workers import this package); the client writes the rows as they arrive.
`fretbuzz sweep SPEC --scheduler ADDRESS` runs main() below (python3 -m fretbuzz.sweeps).
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
import uuid
from typing import Any, Callable, Optional, Union

from . import _core
from ._core import InputError, SolverError, SweepProgress, SweepSpec, SweepStore

__all__ = ["SweepSpec", "SweepProgress", "sweep", "read_table", "main"]

SpecLike = Union[str, "os.PathLike[str]", SweepSpec]
ProgressLike = Union[bool, Callable[[SweepProgress], Any], None]


def _load(spec: SpecLike, max_runs: Optional[int]) -> SweepSpec:
    if isinstance(spec, SweepSpec):
        if max_runs is not None and len(spec) > max_runs:
            raise InputError(f"max_runs = {max_runs}: the spec has {len(spec)} runs")
        return spec
    if isinstance(spec, (str, os.PathLike)):
        if max_runs is None:
            return SweepSpec.load(os.fspath(spec))
        if isinstance(max_runs, bool) or not isinstance(max_runs, int):
            raise TypeError(f"max_runs: expected an int, got {type(max_runs).__name__}")
        return SweepSpec.load(os.fspath(spec), max_runs)
    raise TypeError(f"spec: expected a path to a sweep spec (.toml) or a fretbuzz.SweepSpec, got {type(spec).__name__}")


def _clock(seconds: float) -> str:
    s = int(seconds + 0.5)
    return f"{s // 3600}:{(s // 60) % 60:02d}:{s % 60:02d}"


def progress_text(p: SweepProgress) -> str:
    """The progress line of `fretbuzz sweep`: done/total, failures, elapsed time and ETA."""
    failed = f", {p.failed} failed" if p.failed else ""
    return f"fretbuzz: sweep {p.done}/{p.total} runs{failed}, elapsed {_clock(p.elapsed_s)}, ETA {_clock(p.remaining_s)}"


def _line_printer(stream=sys.stderr) -> Callable[[SweepProgress], None]:
    terminal = stream.isatty()

    def show(p: SweepProgress) -> None:
        print(("\r" if terminal else "") + progress_text(p) + ("   " if terminal else ""),
              end="" if terminal else "\n", file=stream, flush=True)
    return show


def _checking_printer(stream=sys.stderr) -> Callable[[int, int], None]:
    """The command's line while every run's case is checked, as `fretbuzz sweep` prints it."""
    terminal = stream.isatty()

    def show(checked: int, total: int) -> None:
        end = "   " if terminal and checked < total else "\n"
        print(("\r" if terminal else "") + f"fretbuzz: checking the runs' cases: {checked}/{total}", end=end,
              file=stream, flush=True)
    return show


def _progress_handler(progress: ProgressLike, total: int):
    """(callback, closer): None, the caller's callable, or a bar (tqdm where installed, else a line)."""
    if progress is None or progress is False:
        return None, lambda: None
    if callable(progress) and not isinstance(progress, bool):
        return progress, lambda: None
    if progress is not True:
        raise TypeError(f"progress: expected True, False or a callable, got {type(progress).__name__}")
    try:
        from tqdm.auto import tqdm
    except ImportError:
        show = _line_printer()
        return show, lambda: print(file=sys.stderr) if sys.stderr.isatty() else None
    bar = tqdm(desc="fretbuzz sweep", unit="run", total=total)

    def update(p: SweepProgress) -> None:
        bar.total = p.total
        bar.n = p.done
        bar.set_postfix(failed=p.failed, refresh=False)
        bar.refresh()
    return update, bar.close


def read_table(directory: Union[str, "os.PathLike[str]"], hdf5: bool = False):
    """A sweep's table as a pandas DataFrame (error and features as text): results.csv, or
    with hdf5=True the same table from results.h5 (through h5py: pandas' own read_hdf reads
    only the PyTables layout): the same frame."""
    import pandas
    if hdf5:
        import h5py
        with h5py.File(os.path.join(os.fspath(directory), "results.h5"), "r") as f:
            group = f["table"]
            order = group.attrs["columns"]
            names = (order.decode() if isinstance(order, bytes) else str(order)).split(",")
            columns = {}
            for name in names:
                values = group[name][()]
                if values.dtype.kind in "OS":
                    values = [v.decode() if isinstance(v, bytes) else str(v) for v in values]
                columns[name] = values
        table = pandas.DataFrame(columns)
        text = {"status", "error", "features"}
        parameters = set(names[1:names.index("status")])
        for name in names:  # typed as pandas types the CSV: numbers where all are, whole ones as integers
            if name not in text and table[name].dtype == object:
                try:  # parameter values that are not all numbers, stored as their text
                    table[name] = pandas.to_numeric(table[name])
                except (ValueError, TypeError):
                    pass
                continue
            column = table[name]
            # The CSV writes whole numbers without exponent below 1e7 (parameters) or 1e17 (metrics).
            limit = 1e7 if name in parameters else 1e17
            if (column.dtype.kind == "f" and len(column) and column.notna().all() and
                    (column == column.round()).all() and (column.abs() < limit).all()):
                table[name] = column.astype("int64")
        return table
    # round_trip: pandas' default float parser can be tens of ulps off the CSV's exact text.
    return pandas.read_csv(os.path.join(os.fspath(directory), "results.csv"), float_precision="round_trip",
                           dtype={"status": str, "error": str, "features": str},
                           keep_default_na=False, na_values={name: [""] for name in _core.sweep_metric_names()})


def _run_row(spec: SweepSpec, index: int, audio_dir: str) -> str:
    """One run on a Dask worker: its row as JSON (a failed run is a row, not an exception)."""
    return spec.run_row(index, audio_dir)


def _connect(scheduler: str, timeout: float):
    try:
        from distributed import Client
    except ImportError as e:
        raise InputError(f"--scheduler: Dask distributed is not installed ({e}); apt-get install python3-distributed") from e
    try:
        return Client(scheduler, timeout=timeout, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as e:
        raise InputError(f"--scheduler {scheduler}: no Dask scheduler answered within {timeout:g} s "
                         f"(expected tcp://HOST:PORT of a running `dask scheduler`): {e}") from e


def _run_on_dask(spec: SweepSpec, out: str, scheduler: str, resume: bool,
                 progress: Optional[Callable[[SweepProgress], Any]], timeout: float) -> dict:
    from distributed import as_completed
    # Every value, before connecting or writing anything (a large grid takes a while: said).
    spec.check(None if progress is None else _checking_printer())
    client = _connect(scheduler, timeout)
    futures = []
    try:
        store = SweepStore(spec, out, resume)
        todo = store.missing()
        total = len(spec)
        outcome = {"total": total, "computed": 0, "resumed": total - len(todo), "failed": store.failed(),
                   "jobs": sum(w.get("nthreads", 1) for w in client.scheduler_info()["workers"].values()),
                   "interrupted": False}
        token = uuid.uuid4().hex
        start = time.monotonic()
        futures = [client.submit(_run_row, spec, i, os.path.abspath(store.audio_dir(i)) if spec.audio else "",
                                 key=f"fretbuzz-sweep-{token}-{i}", pure=False) for i in todo]
        for future in as_completed(futures, loop=client.loop):
            row = future.result()
            store.record(row)
            outcome["computed"] += 1
            outcome["failed"] += 0 if json.loads(row)["ok"] else 1
            if progress is not None:
                elapsed = time.monotonic() - start
                left = len(todo) - outcome["computed"]
                progress(SweepProgress(done=outcome["resumed"] + outcome["computed"], total=total,
                                       failed=outcome["failed"], resumed=outcome["resumed"], elapsed_s=elapsed,
                                       remaining_s=elapsed / outcome["computed"] * left))
        store.write_table()
        outcome["wall_seconds"] = time.monotonic() - start
        return outcome
    finally:
        for future in futures:
            future.cancel()
        client.close()


def run_sweep(spec: SpecLike, out: Union[str, "os.PathLike[str]"], *, jobs: Optional[int] = None,
              resume: bool = False, scheduler: Optional[str] = None, progress: ProgressLike = False,
              timeout: float = 10.0, max_runs: Optional[int] = None) -> dict:
    """Runs the missing rows of a sweep into `out` and writes its table; returns counts
    (total, computed, resumed, failed, wall_seconds, jobs). See sweep()."""
    s = _load(spec, max_runs)
    callback, close = _progress_handler(progress, len(s))
    try:
        if scheduler is not None:
            if jobs is not None:
                raise InputError("jobs: with a scheduler the cluster's workers set the parallelism")
            return _run_on_dask(s, os.fspath(out), scheduler, resume, callback, timeout)
        if jobs is not None and (isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1):
            raise InputError(f"jobs = {jobs!r}: must be a whole number >= 1 (or None: every core)")
        return _core.run_sweep_local(s, os.fspath(out), jobs or 0, resume, callback)
    finally:
        close()


def sweep(spec: SpecLike, out: Union[str, "os.PathLike[str]", None] = None, *, jobs: Optional[int] = None,
          resume: bool = False, scheduler: Optional[str] = None, progress: ProgressLike = False,
          timeout: float = 10.0, max_runs: Optional[int] = None):
    """Runs a sweep and returns its table as a pandas DataFrame (one row per run: the run's
    index, the swept values, status, error, the obstacle features touched and the buzz
    metrics; docs/sweeps.md defines each).

    spec: a sweep spec file (.toml) or a fretbuzz.SweepSpec. out: the directory of the
    row files and tables (as `fretbuzz sweep --out`); None: a temporary one, removed.
    jobs: runs at a time on this machine (None: every core). resume: finish the sweep in
    `out`, running only the runs without a row. scheduler: 'tcp://HOST:PORT' of a Dask
    scheduler: each run becomes a task on its workers (timeout: seconds to wait for it).
    progress: True for a bar (tqdm where installed), or a callable taking a
    fretbuzz.SweepProgress (done, total, failed, resumed, elapsed_s, remaining_s).
    max_runs: refuse a spec of more runs than this (default 100000, as `fretbuzz sweep`).
    Ctrl-C stops after the runs under way; their rows are kept for resume=True.
    """
    if out is None:
        with tempfile.TemporaryDirectory(prefix="fretbuzz-sweep-") as tmp:
            return sweep(spec, os.path.join(tmp, "sweep"), jobs=jobs, resume=resume, scheduler=scheduler,
                         progress=progress, timeout=timeout, max_runs=max_runs)
    outcome = run_sweep(spec, out, jobs=jobs, resume=resume, scheduler=scheduler, progress=progress, timeout=timeout,
                        max_runs=max_runs)
    if outcome.get("interrupted"):
        raise KeyboardInterrupt
    return read_table(out)


def main(argv=None) -> int:
    """`fretbuzz sweep SPEC --out DIR --scheduler ADDRESS`: exit 0, or 2 for bad input (an
    unreachable scheduler included), 1 for I/O failures, 3 for numerical ones, 130 on Ctrl-C."""
    parser = argparse.ArgumentParser(prog="fretbuzz sweep", description="Run a sweep on a Dask cluster.")
    parser.add_argument("spec")
    parser.add_argument("--out", required=True)
    parser.add_argument("--scheduler", required=True, help="tcp://HOST:PORT of a running `dask scheduler`")
    parser.add_argument("--resume", action="store_true")
    parser.add_argument("--quiet", action="store_true")
    parser.add_argument("--timeout", type=float, default=10.0, help="seconds to wait for the scheduler")
    parser.add_argument("--max-runs", type=int, default=None, help="refuse a spec of more runs than this")
    a = parser.parse_args(argv)
    progress = None if a.quiet else _line_printer()
    try:
        o = run_sweep(a.spec, a.out, resume=a.resume, scheduler=a.scheduler, progress=progress, timeout=a.timeout,
                      max_runs=a.max_runs)
    except InputError as e:
        print(f"fretbuzz: {e}", file=sys.stderr)
        return 2
    except SolverError as e:
        print(f"fretbuzz: {e}", file=sys.stderr)
        return 3
    except RuntimeError as e:  # writing the rows or the table failed
        print(f"fretbuzz: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"\nfretbuzz: interrupted; the finished runs are kept in {a.out}/runs; finish it with: "
              f"fretbuzz sweep {a.spec} --out {a.out} --scheduler {a.scheduler} --resume", file=sys.stderr)
        return 130
    except OSError as e:
        print(f"fretbuzz: {e}", file=sys.stderr)
        return 1
    if progress is not None and o["computed"] and sys.stderr.isatty():
        print(file=sys.stderr)
    resumed = f", {o['resumed']} from before" if o["resumed"] else ""
    print(f"fretbuzz: {o['total']} runs ({o['computed']} computed{resumed}, {o['failed']} failed) on "
          f"{o['jobs']} Dask worker threads in {o['wall_seconds']:.3g} s; table in {a.out}/results.csv and results.h5",
          file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
