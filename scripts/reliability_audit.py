#!/usr/bin/env python3
"""The reliability audit, as CI runs it: every scenario the security and reliability audits
found (links where fretbuzz's own folders belong, partial files on a full disk, strings runs
unbounded, Python signals and threads, temporary files, signals while a page is drawn, which
files a strings case may name, the smaller gaps), a fuzz of the strings-case reader, signals
during `setup --advice`, `setup --dress` and a strings run, and the tests that held before.

Each check prints PASS, FAIL or SKIP (what it needs is missing: root for a small file system,
a built test program) with what it saw; the exit status is 1 if any check failed.

    scripts/reliability_audit.py [--build build] [--mutants 300] [--quick] [--only NAME]

It takes a few minutes on two cores (--quick: signals in one phase only, and no test
programs). Everything it writes is in one scratch folder, removed at the end; each check also
verifies that nothing was written or deleted outside the output folder and the study folder
it gave the command.
"""
from __future__ import annotations

import argparse
import contextlib
import json
import os
import random
import re
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import textwrap
import threading
import time
from typing import Callable, Dict, List, Optional

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
INTERRUPTED = {130, 143}
RESULTS: List[tuple] = []


# --- the harness -------------------------------------------------------------------------

class Failed(Exception):
    pass


class Skipped(Exception):
    pass


def expect(condition: bool, what: str) -> None:
    if not condition:
        raise Failed(what)


def check(name: str):
    def register(function: Callable[[], Optional[str]]):
        CHECKS.append((name, function))
        return function
    return register


CHECKS: List[tuple] = []


def run_checks(selected: Optional[str]) -> int:
    for name, function in CHECKS:
        if selected and selected not in name:
            continue
        started = time.monotonic()
        try:
            detail = function() or ""
            status = "PASS"
        except Skipped as e:
            status, detail = "SKIP", str(e)
        except Failed as e:
            status, detail = "FAIL", str(e)
        except Exception as e:  # the audit's own fault, reported as a failure
            status, detail = "FAIL", f"{type(e).__name__}: {e}"
        RESULTS.append((name, status))
        print(f"{status} {name} ({time.monotonic() - started:.1f} s): {detail}", flush=True)
    failed = [n for n, s in RESULTS if s == "FAIL"]
    print(f"\nreliability audit: {sum(s == 'PASS' for _, s in RESULTS)} passed, {len(failed)} failed, "
          f"{sum(s == 'SKIP' for _, s in RESULTS)} skipped{': ' + ', '.join(failed) if failed else ''}")
    return 1 if failed else 0


class Scratch:
    """A folder of its own for one check; snapshot() and changed() tell what a command touched."""

    def __init__(self, tag: str):
        self.path = tempfile.mkdtemp(prefix=f"fretbuzz-audit-{tag}-", dir=TOP)

    def __call__(self, *parts: str) -> str:
        return os.path.join(self.path, *parts)

    def snapshot(self) -> Dict[str, tuple]:
        seen = {}
        for folder, dirs, files in os.walk(self.path):
            for name in dirs + files:
                full = os.path.join(folder, name)
                st = os.lstat(full)
                seen[os.path.relpath(full, self.path)] = (st.st_mode, st.st_size, st.st_mtime_ns)
        return seen

    def changed(self, before: Dict[str, tuple], *allowed: str) -> List[str]:
        """What differs from `before`, outside the allowed relative folders."""
        after = self.snapshot()
        keys = set(before) | set(after)
        inside = lambda k: any(k == a or k.startswith(a + os.sep) for a in allowed)  # noqa: E731
        return sorted(k for k in keys if not inside(k) and before.get(k) != after.get(k))


def fb(*args: str, timeout: float = 120, env: Optional[dict] = None, limits: Optional[Callable] = None,
       cwd: Optional[str] = None) -> subprocess.CompletedProcess:
    return subprocess.run([FB, *args], capture_output=True, text=True, timeout=timeout, env=env, preexec_fn=limits,
                          cwd=cwd)


def python(code: str, timeout: float = 120, **kwargs) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": MODULE}
    return subprocess.Popen([sys.executable, "-u", "-c", textwrap.dedent(code)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env, **kwargs)


def children(pid: int) -> List[int]:
    try:
        with open(f"/proc/{pid}/task/{pid}/children") as f:
            return [int(p) for p in f.read().split()]
    except OSError:
        return []


def wait_for(condition: Callable[[], bool], seconds: float) -> bool:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if condition():
            return True
        time.sleep(0.01)
    return False


@contextlib.contextmanager
def small_disk(scratch: Scratch, size: str):
    """A tmpfs of `size` (root only; Skipped otherwise)."""
    where = scratch("disk")
    os.makedirs(where)
    if os.geteuid() != 0 or subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", where],
                                           capture_output=True).returncode != 0:
        raise Skipped("mounting a small tmpfs needs root")
    try:
        yield where
    finally:
        subprocess.run(["umount", "-l", where])


def no_staging(folder: str) -> List[str]:
    return [os.path.join(d, n) for d, dirs, files in os.walk(folder) for n in dirs + files if n.startswith(".fretbuzz")]


QUICK_SETUP = ["--strings", "G", "--ensemble", "1", "--fs", "300kHz", "--duration", "0.05", "--strength", "medium",
               "--jobs", "1", "--quiet"]
STRINGS_CASE = """name = "x"
[run]
fs = 96000
duration = {duration}
{extra}
[bridge]
[[bridge.mode]]
mass_kg = 0.005
frequency_hz = 300.0
participation = [1.0, 1.0]
[[string]]
name = "a"
case = "p.toml"
[[string]]
name = "b"
case = "p.toml"
"""


def strings_case(scratch: Scratch, duration="0.05", extra="") -> str:
    shutil.copy(os.path.join(ROOT, "cases", "bridges", "pair-string.toml"), scratch("p.toml"))
    with open(scratch("s.toml"), "w") as f:
        f.write(STRINGS_CASE.format(duration=duration, extra=extra))
    return scratch("s.toml")


def memory_limit():  # as the reproducers ran: 8 GB of address space
    resource.setrlimit(resource.RLIMIT_AS, (8 << 30, 8 << 30))


# --- 1. links where fretbuzz's own folders belong -------------------------------------------

@check("1 clean: a study whose maps/ is a link")
def clean_linked_maps():
    s = Scratch("clean-link")
    for name in ("001", "002", "003.partial", "1234", "notes"):
        os.makedirs(s("victim", name))
        with open(s("victim", name, "keep.txt"), "w") as f:
            f.write("mine\n")
    os.makedirs(s("study"))
    open(s("study", ".fretbuzz-studio.lock"), "w").close()
    os.symlink("../victim", s("study", "maps"))
    before = s.snapshot()
    r = fb("clean", s("study"), "--keep-maps", "0")
    expect(r.returncode == 2, f"exit {r.returncode}: {r.stderr.strip()}")
    expect(not s.changed(before, "study"), f"touched: {s.changed(before, 'study')}")
    return f"exit 2, victim intact: {r.stderr.strip()[:100]}"


# --- 2. export: links and a full disk --------------------------------------------------------

@check("2 export: links planted in DIR")
def export_links():
    s = Scratch("export-link")
    os.makedirs(s("v", "folder"))
    os.makedirs(s("out"))
    os.makedirs(s("out2"))
    with open(s("v", "precious.toml"), "w") as f:
        f.write("mine\n")
    os.symlink("../v/precious.toml", s("out", "strings-on-a-bridge.toml"))
    os.symlink("../v/folder", s("out2", "bridges"))
    before = s.snapshot()
    a = fb("export", "strings-on-a-bridge", s("out"))
    b = fb("export", "sitar-taraf", s("out2"))
    expect(a.returncode == 2 and b.returncode == 2, f"exits {a.returncode}, {b.returncode}")
    expect(not s.changed(before), f"touched: {s.changed(before)}")
    return "exit 2 for each, nothing written through a link"


@check("2 export: a full disk")
def export_full_disk():
    s = Scratch("export-full")
    os.makedirs(s("limited"))
    limit = lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (2048, 2048))  # noqa: E731
    # SIGXFSZ ignored: a write past the limit fails (EFBIG) as on a full disk.
    r = subprocess.run(["sh", "-c", 'trap "" XFSZ; exec "$0" "$@"', FB, "export", "sitar-taraf", s("limited", "out")],
                       capture_output=True, text=True, timeout=60, preexec_fn=limit)
    expect(r.returncode == 1, f"file-size limit: exit {r.returncode}: {r.stderr.strip()}")
    expect(os.listdir(s("limited")) == [], f"file-size limit: left {os.listdir(s('limited'))}")
    detail = "a 2 KiB file-size limit: exit 1, nothing left"
    try:
        with small_disk(s, "8k") as disk:
            r = fb("export", "sitar-taraf", os.path.join(disk, "out"))
            expect(r.returncode == 1, f"8 KiB tmpfs: exit {r.returncode}: {r.stderr.strip()}")
            expect(os.listdir(disk) == [], f"8 KiB tmpfs: left {os.listdir(disk)}")
            detail += "; an 8 KiB tmpfs: exit 1, nothing left"
    except Skipped as e:
        detail += f"; tmpfs skipped ({e})"
    return detail


# --- 3. strings runs bounded and streamed ----------------------------------------------------

@check("3 strings: [run] audio_rate out of range")
def strings_audio_rate():
    seen = []
    for rate in ("1e300", "1e-300", "1e12", "3e9", "1e7", "1"):
        s = Scratch("audio-rate")
        case = strings_case(s, extra=f"audio_rate = {rate}")
        started = time.monotonic()
        try:
            r = fb("run", case, "--out", s("out"), "--quiet", timeout=20, limits=memory_limit)
            code = r.returncode
        except subprocess.TimeoutExpired:
            code = "timeout"
        seen.append(f"{rate}: {code}")
        expect(code == 2 and not os.path.exists(s("out")),
               f"audio_rate = {rate}: exit {code} after {time.monotonic() - started:.1f} s (want 2, nothing written)")
    return ", ".join(seen)


@check("3 strings: --duration out of range")
def strings_duration():
    seen = []
    for duration in ("1e300", "1e-7", "1e5"):
        s = Scratch("duration")
        try:
            r = fb("run", "strings-on-a-bridge", "--duration", duration, "--out", s("out"), "--quiet", timeout=20,
                   limits=memory_limit)
            code = r.returncode
        except subprocess.TimeoutExpired:
            code = "timeout"
        seen.append(f"{duration}: {code}")
        expect(code == 2 and not os.path.exists(s("out")), f"--duration {duration}: exit {code} (want 2)")
    return ", ".join(seen)


@check("3 strings: a long run streams its rows")
def strings_memory():
    s = Scratch("memory")
    case = strings_case(s, duration="41666", extra="output_rate = 96000")
    p = subprocess.Popen([FB, "run", case, "--out", s("out"), "--quiet"], stdout=subprocess.DEVNULL,
                         stderr=subprocess.PIPE, text=True, preexec_fn=memory_limit)

    def rss_kb():
        try:
            with open(f"/proc/{p.pid}/status") as f:
                return next(int(line.split()[1]) for line in f if line.startswith("VmRSS:"))
        except (OSError, StopIteration):
            return None
    try:
        time.sleep(3)
        first = rss_kb()
        time.sleep(6)
        second = rss_kb()
        if first is None or second is None or p.poll() is not None:
            p.wait(timeout=60)
            raise Failed(f"the run ended within 9 s: exit {p.returncode}: {p.stderr.read()[-300:]}")
    finally:
        if p.poll() is None:
            p.send_signal(signal.SIGINT)
        try:
            code = p.wait(timeout=60)
        except subprocess.TimeoutExpired:
            p.kill()
            raise Failed("still running 60 s after SIGINT") from None
    grown = (second - first) / 1024
    expect(grown < 20, f"RSS grew {grown:.0f} MB in 6 s ({first // 1024} -> {second // 1024} MB): rows kept in memory")
    expect(code == 130 and not os.path.exists(s("out")), f"Ctrl-C: exit {code}")
    # The summary names its balance as a one-string run's does.
    short = strings_case(Scratch("summary"), duration="0.02")
    out = os.path.join(os.path.dirname(short), "out")
    r = fb("run", short, "--out", out, "--quiet")
    expect(r.returncode == 0, f"a short strings run: exit {r.returncode}: {r.stderr[:200]}")
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    expect("max_relative_energy_increase" in json.dumps(summary), "summary.json lacks max_relative_energy_increase")
    return f"RSS {first // 1024} -> {second // 1024} MB over 6 s; Ctrl-C exit 130; summary names its balance"


# --- 4. Python --------------------------------------------------------------------------------

DECAY = """
import fretbuzz, numpy as np, threading, time
fs = 48000
t = np.arange(fs * 8) / fs
x = sum(np.exp(-t * (0.5 + k * 0.3)) * np.sin(2 * np.pi * 98 * k * t) / k for k in range(1, 60))
"""


@check("4 python: Ctrl-C during estimate()")
def py_estimate_ctrlc():
    p = python(DECAY + "print('go', flush=True)\nfretbuzz.estimate(x, fs, f0=98.0)\nprint('finished')\n")
    expect(p.stdout.readline().strip() == "go", "did not start")
    time.sleep(1.0)
    sent = time.monotonic()
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=120)
    latency = time.monotonic() - sent
    expect("KeyboardInterrupt" in err and "finished" not in out, f"no KeyboardInterrupt: {err[-200:]}")
    expect(latency < 3.0, f"KeyboardInterrupt {latency:.2f} s after SIGINT")
    return f"KeyboardInterrupt {latency:.2f} s after SIGINT"


@check("4 python: run() and estimate() on a daemon thread at exit")
def py_daemon():
    seen = []
    # The run on its slow reference path: still stepping when the interpreter ends.
    for work in ("fretbuzz.run('bass-pop', duration=3, screen=False, free_flight=False)",
                 "fretbuzz.estimate(x, fs, f0=98.0)"):
        # A slow interpreter end (4e6 objects to free): the daemon thread wakes while it ends.
        p = python(DECAY + "junk = [{'k': i} for i in range(4 * 10**6)]\n"
                   f"th = threading.Thread(target=lambda: {work}, daemon=True)\nth.start()\ntime.sleep(1.5)\n"
                   "print('alive', th.is_alive())\n")
        out, err = p.communicate(timeout=120)
        expect("alive True" in out, f"{work}: ended before the interpreter did")
        expect(p.returncode == 0 and "terminate called" not in err, f"{work}: exit {p.returncode}: {err[-200:]}")
        seen.append(f"exit {p.returncode}")
    return ", ".join(seen)


@check("4 python: the bench's lists are bounded")
def py_limits():
    p = python("""
        import fretbuzz, time
        b = fretbuzz.Bench('jazz-bass', strengths='medium')
        t = time.time()
        for call in (lambda: b.map(frets=[0] * 10**6), lambda: b.map(strings=['G'] * 10**5)):
            try:
                call(); print('accepted')
            except fretbuzz.InputError as e:
                print('refused:', e)
        print('rows:', b.check(strings='G,G,G', frets=[0, 0]), 'seconds:', round(time.time() - t, 2))
    """)
    out, err = p.communicate(timeout=120)
    expect(p.returncode == 0, err[-300:])
    expect(out.count("refused:") == 2 and "frets" in out and "strings" in out, out)
    expect("rows: 1 " in out, f"duplicates each played: {out}")
    return " | ".join(line[:70] for line in out.strip().splitlines())


# --- 5. temporary files -----------------------------------------------------------------------

@check("5 temporary files: SIGKILL as setup starts its Python child")
def sigkill_temp():
    s = Scratch("sigkill")
    os.makedirs(s("tmp"))
    env = {**os.environ, "TMPDIR": s("tmp")}
    for trial in range(3):
        p = subprocess.Popen([FB, "setup", "jazz-bass", *QUICK_SETUP, "--frets", "0", "--out", s(f"o{trial}")],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
        expect(wait_for(lambda: p.poll() is not None or children(p.pid), 120), "no child started")
        p.kill()
        p.wait()
        time.sleep(0.5)
    left = os.listdir(s("tmp"))
    expect(left == [], f"left in the temporary folder: {left}")
    return "3 trials, the temporary folder stays empty"


# --- 6. a full disk in the studio ----------------------------------------------------------------

@check("6 studio: a full disk")
def studio_full_disk():
    s = Scratch("studio-disk")
    with small_disk(s, "1m") as disk:
        p = python(f"""
            import os, time, fretbuzz
            from fretbuzz.studio.study import Study
            bench = fretbuzz.Bench('bass-neck', ensemble=1, fs=3e5, duration=0.6)
            study = Study(bench, {os.path.join(disk, 'study')!r}, strengths='medium')
            def settled(n):
                while len(study.maps) < n or study.maps[n].status in ('waiting', 'running'):
                    time.sleep(0.1)
                return study.maps[n]
            first = settled(1)
            print('map 1:', first.status, len(first.notes), 'notes;', 'No space' in first.error, first.error[-60:])
            print('maps/ after map 1:', sorted(os.listdir(os.path.join(study.folder, 'maps'))))
            study.submit_map({{'strengths': 'medium', 'relief': '0.3'}})
            second = settled(2)
            print('map 2:', second.status, len(second.notes), 'notes')
            print('maps/ after map 2:', sorted(os.listdir(os.path.join(study.folder, 'maps'))))
            study.close()
        """)
        out, err = p.communicate(timeout=300)
    expect(p.returncode == 0, err[-400:])
    lines = dict(line.split(":", 1) for line in out.strip().splitlines())
    first_notes = int(lines["map 1"].split()[1])
    expect("failed" in lines["map 1"] and "True" in lines["map 1"], f"map 1 did not fail on the full disk: {out}")
    expect(lines["maps/ after map 1"].strip() == "[]", f"a failed map's folder stayed: {out}")
    second_notes = int(lines["map 2"].split()[1])
    expect(second_notes >= max(1, first_notes - 2),
           f"map 2 failed at once ({second_notes} notes against {first_notes}): {out}")
    return " | ".join(line.strip()[:80] for line in out.strip().splitlines())


# --- 7. a signal while the page is drawn -----------------------------------------------------------

@check("7 setup: SIGTERM or Ctrl-C while the page is drawn")
def setup_page_signal():
    seen = []
    for sig, group in ((signal.SIGTERM, False), (signal.SIGINT, True)):
        # The signal must land while the page's child lives; on a loaded machine the run may
        # end between two looks, which is no answer: try again (up to five times).
        for attempt in range(5):
            s = Scratch("page-signal")
            before = s.snapshot()
            p = subprocess.Popen([FB, "setup", "jazz-bass", *QUICK_SETUP, "--frets", "0", "--out", s("out")],
                                 stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True)
            expect(wait_for(lambda: p.poll() is not None or children(p.pid), 120), "no child started")
            time.sleep(0.05)
            if p.poll() is None and children(p.pid):
                os.killpg(p.pid, sig) if group else p.send_signal(sig)
                out, _ = p.communicate(timeout=120)
                break
            p.communicate(timeout=120)
        else:
            raise Failed(f"{sig.name}: the run ended before the page's child could be signalled, 5 times")
        expect(p.returncode == 128 + sig, f"{sig.name}: exit {p.returncode}: {out[-300:]}")
        expect("python3-jinja2" not in out, f"{sig.name}: a false warning: {out[-300:]}")
        expect(not s.changed(before), f"{sig.name}: written: {s.changed(before)}")
        seen.append(f"{sig.name}{' to the group' if group else ''}: exit {p.returncode}, nothing written")
    return "; ".join(seen)


# --- 8. which files a strings case may name ----------------------------------------------------------

@check("8 strings case: a [[string]] case naming another file")
def strings_case_any_file():
    s = Scratch("any-file")
    os.makedirs(s("case"))
    os.makedirs(s("outside"))
    with open(s("outside", "secret.toml"), "w") as f:
        f.write("root:SECRET-HASH:19000:0:99999:7:::\n")
    os.symlink("../outside/secret.toml", s("case", "link.toml"))
    names = [s("outside", "secret.toml"), "../outside/secret.toml", "link.toml"]
    if os.access("/etc/shadow", os.R_OK):
        names.append("/etc/shadow")
    seen = []
    for named in names:
        with open(s("case", "s.toml"), "w") as f:
            f.write(STRINGS_CASE.format(duration="0.01", extra="").replace("p.toml", named))
        r = fb("show", s("case", "s.toml"))
        text = r.stdout + r.stderr
        expect(r.returncode == 2, f"{named}: exit {r.returncode}")
        expect("SECRET" not in text and "expected '='" not in text and not re.search(r":1:\d+:", text),
               f"{named}: the message tells of the file: {text.strip()[:200]}")
        seen.append(named if not named.startswith("/tmp") else "an absolute path")
    return "refused, exit 2, nothing of the file told: " + ", ".join(seen)


# --- 9. the smaller gaps -----------------------------------------------------------------------------------

@check("9 gaps: relief, Python ranges, duplicates, rows, dress depth, clean")
def smaller_gaps():
    s = Scratch("gaps")
    text = fb("show", "--instrument", "jazz-bass").stdout
    text = re.sub(r"^\[neck\.relief\].*?(?=^\[)", "[neck.relief]\nfret = 8\n\n", text, count=1, flags=re.S | re.M)
    with open(s("no-gap.toml"), "w") as f:
        f.write(text)
    r = fb("setup", s("no-gap.toml"), "--out", s("out"), "--quiet")
    expect(r.returncode == 2 and "neck.relief.gap" in r.stderr and "unknown key" not in r.stderr,
           f"relief fret without its gap: exit {r.returncode}: {r.stderr.strip()[:200]}")
    r = fb("clean", s("no-such-folder"))
    expect(r.returncode == 2, f"clean of a missing path: exit {r.returncode}")
    p = python("""
        import fretbuzz, time
        b = fretbuzz.Bench('jazz-bass', strengths='medium')
        def refused(call):
            try:
                call(); return 'accepted'
            except fretbuzz.InputError as e:
                return str(e)[:60]
        print(refused(lambda: b.check(frets=[2**64])))
        print(refused(lambda: b.note('G', 10**30)))
        row = dict(string='G', fret=3, strength='medium', verdict='banana', buzz_fraction=0.0, buzz_dB=None, buzz_fret=None)
        print(refused(lambda: b.advise([row], strings='G', frets=[3])))
        print(refused(lambda: b.dress([dict(row, verdict='clean', fret=99)], strings='G', frets=[3])))
        b.map = lambda **k: (_ for _ in ()).throw(AssertionError('played'))
        t = time.time()
        print(refused(lambda: b.dress(depth=1e308)), round(time.time() - t, 2))
    """)
    out, err = p.communicate(timeout=120)
    expect(p.returncode == 0, err[-300:])
    lines = out.strip().splitlines()
    expect(len(lines) == 5 and "frets" in lines[0] and "fret" in lines[1] and "verdict" in lines[2]
           and "fret" in lines[3] and "depth" in lines[4], out)
    return "relief exit 2 naming neck.relief.gap; clean exit 2; Python: " + " | ".join(lines)


# --- fuzz: the strings-case reader -------------------------------------------------------------------------

HOSTILE = ["/etc/shadow", "../outside/secret.toml", "link.toml", "fifo.toml", "big.toml", "notes.txt", "", "sitar",
           "bridges/taraf-string.toml", "sub/../../outside/secret.toml", "p.toml", "\u00e9.toml", "a" * 300 + ".toml"]
TOKENS = ["=", "[", "]", "[[string]]", "[bridge]", "\"", ",", "1e308", "-1", "nan", "inf", "0", "1e-300", "{", "}",
          "case = \"../outside/secret.toml\"", "set.run.fs = 1", "mirror = true", "pitch_ratio = 1e9", "\n", "#",
          "participation = []", "mass_kg = 0", "[[bridge.mode]]"]


def mutate(text: str, rng: random.Random) -> str:
    for _ in range(rng.randint(1, 4)):
        kind = rng.randrange(5)
        at = rng.randrange(len(text) + 1)
        if kind == 0 and text:  # delete a stretch
            text = text[:at] + text[at + rng.randint(1, 40):]
        elif kind == 1:  # insert a token
            text = text[:at] + rng.choice(TOKENS) + text[at:]
        elif kind == 2:  # a number replaced
            numbers = list(re.finditer(r"-?[0-9][0-9.eE+-]*", text))
            if numbers:
                m = rng.choice(numbers)
                text = text[:m.start()] + rng.choice(["0", "-1", "1e308", "1e-308", "nan", "1e12", "3"]) + text[m.end():]
        elif kind == 3:  # a string's case replaced by a hostile name
            cases = list(re.finditer(r'case = "[^"]*"', text))
            if cases:
                m = rng.choice(cases)
                text = text[:m.start()] + f'case = "{rng.choice(HOSTILE)}"' + text[m.end():]
        elif text:  # a byte flipped
            text = text[:at] + chr(rng.randrange(1, 256)) + text[at + 1:]
    return text


@check("fuzz: the strings-case reader")
def fuzz_strings_cases():
    s = Scratch("fuzz")
    os.makedirs(s("case", "sub"))
    os.makedirs(s("outside"))
    with open(s("outside", "secret.toml"), "w") as f:
        f.write("root:SECRET-HASH:19000:0:99999:7:::\n")
    os.symlink("../outside/secret.toml", s("case", "link.toml"))
    os.mkfifo(s("case", "fifo.toml"))
    with open(s("case", "big.toml"), "w") as f:
        f.truncate(5 << 20)
    with open(s("case", "notes.txt"), "w") as f:
        f.write("root:SECRET-HASH\n")
    for name in ("pair-string", "taraf-string", "tanpura-string", "guitar-string"):
        shutil.copy(os.path.join(ROOT, "cases", "bridges", name + ".toml"), s("case", name + ".toml"))
    shutil.copy(os.path.join(ROOT, "cases", "bridges", "pair-string.toml"), s("case", "p.toml"))
    seeds = []
    for name in ("strings-on-a-bridge", "tanpura-four", "sitar-taraf", "guitar-chord"):
        with open(os.path.join(ROOT, "cases", "bridges", name + ".toml")) as f:
            seeds.append(f.read().replace('case = "bridges/', 'case = "'))
    rng = random.Random(58)
    codes: Dict[int, int] = {}
    slowest = 0.0
    before = s.snapshot()
    for k in range(MUTANTS):
        text = mutate(rng.choice(seeds), rng)
        with open(s("case", "m.toml"), "w", encoding="utf-8", errors="surrogateescape") as f:
            f.write(text)
        started = time.monotonic()
        try:
            r = subprocess.run([FB, "show", s("case", "m.toml")], capture_output=True, timeout=20,
                               preexec_fn=memory_limit)
        except subprocess.TimeoutExpired:
            raise Failed(f"mutant {k} hangs (kept in {s('case', 'm.toml')})") from None
        slowest = max(slowest, time.monotonic() - started)
        codes[r.returncode] = codes.get(r.returncode, 0) + 1
        output = r.stdout + r.stderr
        if r.returncode not in (0, 2) or b"SECRET" in output:
            shutil.copy(s("case", "m.toml"), os.path.join(TOP, f"mutant-{k}.toml"))
            raise Failed(f"mutant {k}: exit {r.returncode}: {output[-300:]!r} (kept as mutant-{k}.toml)")
    os.unlink(s("case", "m.toml"))
    changed = [c for c in s.changed(before) if c != "case"]  # the folder itself: m.toml came and went
    expect(not changed, f"touched: {changed}")
    detail = f"{MUTANTS} mutants through `fretbuzz show`: exits {dict(sorted(codes.items()))}, slowest {slowest:.2f} s"
    fuzzer = os.path.join(ROOT, "build-sanitizers", "tests", "fuzz", "strings_case_fuzzer")
    if os.path.exists(fuzzer):
        corpus = s("corpus")
        os.makedirs(corpus)
        for name in os.listdir(os.path.join(ROOT, "cases", "bridges")):
            shutil.copy(os.path.join(ROOT, "cases", "bridges", name), corpus)
        r = subprocess.run([fuzzer, corpus, f"-runs={MUTANTS}", "-max_len=16384", "-timeout=10"], capture_output=True,
                           text=True, timeout=600, env={**os.environ, "ASAN_OPTIONS": "detect_leaks=1"})
        expect(r.returncode == 0, f"libFuzzer: exit {r.returncode}: {r.stderr[-400:]}")
        detail += f"; libFuzzer under ASan and UBSan: {MUTANTS} runs, clean"
    return detail


# --- signals during setup --advice, --dress and a strings run -------------------------------------------------

def interrupted_cleanly(name: str, words: List[str], phases: List[tuple]) -> str:
    """The command run whole, then once per phase and signal: SIGINT to its process group (as
    a terminal's Ctrl-C) and SIGTERM to it, each sent as the command enters that phase (a line
    of its output matching the phase's pattern, or "child": its Python child started). Exit 0
    or 2 as documented, 130/143 when interrupted (then nothing written); nothing touched
    outside --out; no staging folder left; no crash, no hang."""
    s = Scratch("whole")
    r = fb(*[w.replace("{out}", s("out")) for w in words], timeout=300, cwd=s.path)
    expect(r.returncode == 0 and os.path.isdir(s("out")), f"{name}: exit {r.returncode} uninterrupted: {r.stderr[-300:]}")
    seen = []
    for phase, trigger in phases:
        for sig, group in ((signal.SIGINT, True), (signal.SIGTERM, False)):
            s = Scratch("signals")
            os.makedirs(s("tmp"))
            before = s.snapshot()
            p = subprocess.Popen([FB, *[w.replace("{out}", s("out")) for w in words]], stdout=subprocess.PIPE,
                                 stderr=subprocess.STDOUT, text=True, start_new_session=True, cwd=s.path,
                                 env={**os.environ, "TMPDIR": s("tmp")})
            lines: List[str] = []
            reader = threading.Thread(target=lambda: lines.extend(iter(p.stdout.readline, "")), daemon=True)
            reader.start()
            if trigger == "child":
                reached = wait_for(lambda: p.poll() is not None or bool(children(p.pid)), 300)
            else:
                reached = wait_for(lambda: p.poll() is not None or any(re.search(trigger, l) for l in list(lines)), 300)
            time.sleep(0.1)
            running = p.poll() is None
            if running:
                os.killpg(p.pid, sig) if group else p.send_signal(sig)
            try:
                code = p.wait(timeout=180)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                raise Failed(f"{name}: hangs after {sig.name} in {phase}") from None
            reader.join(timeout=10)
            out = "".join(lines)
            expect(reached and running, f"{name}: ended before {phase} (exit {code}): {out[-300:]}")
            expect(code in (0, 2) or code in INTERRUPTED, f"{name}, {sig.name} in {phase}: exit {code}: {out[-300:]}")
            if code in INTERRUPTED:
                expect(code == 128 + sig, f"{name}: {sig.name} gave exit {code}")
                expect(not os.path.exists(s("out")), f"{name}: --out written after {sig.name} in {phase}")
            else:  # the signal came after the last moment it could stop the commit: the results are whole
                expect(os.path.isdir(s("out")), f"{name}: exit {code} after {sig.name} in {phase}, and no --out")
            expect(not s.changed(before, "out"), f"{name}, {sig.name} in {phase}: touched {s.changed(before, 'out')}")
            expect(not no_staging(s.path), f"{name}: staging left: {no_staging(s.path)}")
            seen.append(f"{sig.name[3:]} in {phase}: {code}")
    return f"{name}: " + ", ".join(seen)


SETUP_QUICK_LOUD = [w for w in QUICK_SETUP if w != "--quiet"]


@check("signals: setup --advice")
def signals_advice():
    phases = [("the map", r"fretbuzz: 1/"), ("the search", r"advice: searching"), ("the page", "child")]
    return interrupted_cleanly("setup --advice", ["setup", "jazz-bass", *SETUP_QUICK_LOUD, "--frets", "0,5,12",
                                                  "--advice", "--out", "{out}"], phases[:1] if QUICK else phases)


@check("signals: setup --dress")
def signals_dress():
    phases = [("the map", r"fretbuzz: 1/"), ("the search", r"fret dress: searching"), ("the page", "child")]
    return interrupted_cleanly("setup --dress", ["setup", "jazz-bass", *SETUP_QUICK_LOUD, "--frets", "0,5,12",
                                                 "--dress", "--out", "{out}"], phases[:1] if QUICK else phases)


@check("signals: a strings run")
def signals_strings_run():
    return interrupted_cleanly("run sitar-taraf", ["run", "sitar-taraf", "--duration", "1", "--out", "{out}"],
                               [("the run", r"strings on a bridge")])


# --- what held before --------------------------------------------------------------------------------------------

@check("earlier: the reliability and hazard tests, the studio's guard")
def earlier_tests():
    tests = os.path.join(BUILD, "tests", "fretbuzz_tests")
    if QUICK or not os.path.exists(tests):
        raise Skipped("--quick" if QUICK else f"no {tests}")
    filters = "Reliability.*:HostileFiles.*:Aliasing.*:CaseKeys.*:ObstacleSide.*:PolarisationY.*:StiffString.*:" \
              "Export.*:Clean.*:PythonChild.*:StringsCaseReference.*:InstrumentRelief.*"
    r = subprocess.run([tests, f"--gtest_filter={filters}", "--gtest_brief=1"], capture_output=True, text=True,
                       timeout=1500)
    passed = re.search(r"\[  PASSED  \] (\d+) test", r.stdout)
    expect(r.returncode == 0, f"C++ tests: exit {r.returncode}: {r.stdout[-600:]}")
    env = {**os.environ, "PYTHONPATH": MODULE, "FRETBUZZ_CLI": FB}
    studio = subprocess.run([sys.executable, "-m", "unittest", "test_studio_attacks.ExposedModeTest",
                             "test_studio_attacks.HostileNameTest", "test_studio_attacks.OneStudioPerFolderTest",
                             "test_studio.GuardTest"], capture_output=True, text=True, timeout=1200, env=env,
                            cwd=os.path.join(ROOT, "python", "tests"))
    ran = re.search(r"Ran (\d+) test", studio.stderr)
    expect(studio.returncode == 0, f"studio tests: {studio.stderr[-600:]}")
    return f"C++: {passed.group(1) if passed else '?'} tests passed; studio (Host, Origin, token, folders): " \
           f"{ran.group(1) if ran else '?'} tests passed"


def main() -> int:
    global FB, MODULE, BUILD, TOP, MUTANTS, QUICK
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default=os.path.join(ROOT, "build"), help="the build folder (default: build)")
    parser.add_argument("--mutants", type=int, default=300, help="strings cases the fuzz tries (default: 300)")
    parser.add_argument("--quick", action="store_true", help="signals in one phase only; no test programs")
    parser.add_argument("--only", help="run only the checks whose name contains this")
    args = parser.parse_args()
    BUILD = os.path.abspath(args.build)
    FB = os.path.join(BUILD, "cli", "fretbuzz")
    MODULE = os.path.join(BUILD, "python", "module")
    MUTANTS = args.mutants
    QUICK = args.quick
    if not os.access(FB, os.X_OK):
        print(f"reliability audit: no program {FB}: build it first (cmake --build {args.build} --target fretbuzz_cli "
              "fretbuzz_python fretbuzz_python_files)", file=sys.stderr)
        return 2
    sys.path.insert(0, MODULE)
    TOP = tempfile.mkdtemp(prefix="fretbuzz-audit-")
    try:
        return run_checks(args.only)
    finally:
        for folder, dirs, files in os.walk(TOP):  # no tmpfs left mounted below it
            for d in dirs:
                subprocess.run(["umount", "-l", os.path.join(folder, d)], capture_output=True) \
                    if os.path.ismount(os.path.join(folder, d)) else None
        kept = [n for n in os.listdir(TOP) if n.startswith("mutant-")]
        if kept:
            print(f"reliability audit: failing mutants kept in {TOP}", file=sys.stderr)
        else:
            shutil.rmtree(TOP, ignore_errors=True)


FB = MODULE = BUILD = TOP = ""
MUTANTS = 300
QUICK = False

if __name__ == "__main__":
    sys.exit(main())
