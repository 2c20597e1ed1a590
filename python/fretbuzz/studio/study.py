"""The studio's state: one instrument on the bench, the maps played for it and its what-ifs,
a worker thread that plays them one at a time from a short queue, the advice, and the study
folder that holds every file the studio serves.

Nothing here computes geometry or physics: the maps, the what-ifs, the comparison of two
maps, one note's contacts and the advice are fretbuzz.Bench's (setup_bench.py). This module
only keeps them, checks the page's values through the library's own checks, and decides
which files may be served.
"""
from __future__ import annotations

import collections
import errno
import fcntl
import os
import re
import shutil
import stat
import threading
import time
from dataclasses import dataclass, field
from typing import Any, Deque, Dict, List, Optional, Union

from .. import _core
from ..setup_bench import Bench, InputError

# At most this many recomputations wait behind the running one; a newer what-if supersedes
# the oldest waiting one (the page says so), so a burst of clicks never piles up work.
QUEUE_LIMIT = 2
# A value typed in a control: long enough for "0.0625 in" or "soft,medium,hard,pop,slap".
MAX_VALUE_CHARS = 40
# The files the study folder serves: the notes' WAVs and the exported reports.
SERVED_SUFFIXES = {".wav": "audio/wav", ".html": "text/html; charset=utf-8"}


# The study folder's lock: held by the one studio working in it (flock: the kernel lets go
# when that process ends, however it ends); it holds that studio's process id.
LOCK_NAME = ".fretbuzz-studio.lock"
# A map is played into maps/NNN.partial and renamed maps/NNN once every note is written: a
# folder named maps/NNN is a whole map. A map that fails (a full disk) or is stopped removes
# its .partial folder at once; a studio killed mid-map leaves it, removed by the next studio
# in that folder (or `fretbuzz clean`).
PARTIAL = ".partial"
# What-ifs that change one string alone: the other strings' notes are those of the map before.
PER_STRING = ("action12", "nut", "saddle", "saddle_change")
MAP_FOLDER = re.compile(r"([0-9]{3,})(\.partial)?")


class StudyBusy(OSError):
    """Another studio works in this study folder."""


def lock_folder(folder: str) -> int:
    """Takes the study folder's lock (a file descriptor, held until closed); StudyBusy naming
    the process that holds it."""
    fd = os.open(os.path.join(folder, LOCK_NAME), os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC, 0o644)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError as e:
        if e.errno not in (errno.EWOULDBLOCK, errno.EAGAIN):
            os.close(fd)
            raise
        holder = ""
        for _ in range(50):  # the holder writes its id just after locking
            holder = os.pread(fd, 32, 0).decode("ascii", "replace").strip()
            if holder:
                break
            time.sleep(0.02)
        os.close(fd)
        raise StudyBusy(f"another studio works in {folder} (process {holder or 'unknown'}): "
                        "stop it, or give this one another --study") from None
    os.ftruncate(fd, 0)
    os.pwrite(fd, f"{os.getpid()}\n".encode("ascii"), 0)
    return fd


# What a map writes into its folder: each note's WAV, and while one is written its temporary
# file beside it (".note-....tmp-PID-N.wav"). Pruning removes these and nothing else.
MAP_FILE = re.compile(r"\.?note-[^/]*\.wav")
# The study's own folders: a symbolic link (or anything but a folder) in their place is refused,
# never followed.
OWN_FOLDERS = ("maps", "exports")


class StudyLayoutError(InputError):
    """A study folder holding something other than a folder where the studio keeps its own."""


def _open_own_folder(folder_fd: int, name: str, folder: str) -> Optional[int]:
    """The study's own subfolder `name`, opened without following a link (None when missing)."""
    try:
        return os.open(name, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW | os.O_CLOEXEC, dir_fd=folder_fd)
    except FileNotFoundError:
        return None
    except OSError as e:
        if e.errno not in (errno.ELOOP, errno.ENOTDIR):
            raise
        what = "a symbolic link" if os.path.islink(os.path.join(folder, name)) else "not a folder"
        raise StudyLayoutError(f"{os.path.join(folder, name)} is {what}: the studio keeps its {name} in a folder of its "
                               "own inside the study folder and neither follows nor deletes a link there; move it "
                               "away, or give another study folder") from None


def check_own_folders(folder: str) -> None:
    """StudyLayoutError unless each of the study's own folders is a real folder or missing."""
    folder_fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)
    try:
        for name in OWN_FOLDERS:
            fd = _open_own_folder(folder_fd, name, folder)
            if fd is not None:
                os.close(fd)
    finally:
        os.close(folder_fd)


def _remove_map(maps_fd: int, name: str) -> bool:
    """Removes the files a map wrote in maps/<name> and the folder once empty; False (the
    folder kept, with what fretbuzz did not write) if anything else is in it. Every step is
    relative to the open folders: a link is removed as a name, never followed."""
    try:
        fd = os.open(name, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW | os.O_CLOEXEC, dir_fd=maps_fd)
    except OSError as e:
        if e.errno in (errno.ELOOP, errno.ENOTDIR, errno.ENOENT):
            return False  # a link or a file with a map's name: not a map
        raise
    try:
        for entry in os.listdir(fd):
            if MAP_FILE.fullmatch(entry) and stat.S_ISREG(os.stat(entry, dir_fd=fd, follow_symlinks=False).st_mode):
                os.unlink(entry, dir_fd=fd)
    finally:
        os.close(fd)
    try:
        os.rmdir(name, dir_fd=maps_fd)
    except OSError as e:
        if e.errno in (errno.ENOTEMPTY, errno.EEXIST):
            return False
        raise
    return True


def prune_maps(folder: str, keep: Optional[int] = None) -> tuple:
    """Removes the unfinished maps of a study folder (maps/NNN.partial) and, with keep, all
    but the newest `keep` finished ones; the caller holds the folder's lock. Only what a map
    writes is removed (its WAVs): a map folder holding anything else keeps it, and stays.
    StudyLayoutError if maps/ is a symbolic link or not a folder. Returns (the unfinished
    removed, the finished removed)."""
    check_own_folders(folder)
    folder_fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)
    try:
        maps_fd = _open_own_folder(folder_fd, "maps", folder)
    finally:
        os.close(folder_fd)
    if maps_fd is None:
        return 0, 0
    try:
        partial, whole = [], []
        for name in os.listdir(maps_fd):
            m = MAP_FOLDER.fullmatch(name)
            if m and stat.S_ISDIR(os.stat(name, dir_fd=maps_fd, follow_symlinks=False).st_mode):
                (partial if m.group(2) else whole).append((int(m.group(1)), name))
        old = sorted(whole)[:max(len(whole) - keep, 0)] if keep is not None else []
        return (sum(_remove_map(maps_fd, name) for _, name in partial),
                sum(_remove_map(maps_fd, name) for _, name in old))
    finally:
        os.close(maps_fd)


def remove_partial(folder: str, relative: str) -> None:
    """Removes what a map that failed or was stopped wrote into its unfinished folder
    (maps/NNN.partial): it would take the disk's room from every map after it."""
    folder_fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)
    try:
        maps_fd = _open_own_folder(folder_fd, "maps", folder)
    finally:
        os.close(folder_fd)
    if maps_fd is not None:
        try:
            _remove_map(maps_fd, os.path.basename(relative) + PARTIAL)
        finally:
            os.close(maps_fd)


class FieldErrors(InputError):
    """Bad values from the page, each message keyed by the control it belongs to."""

    def __init__(self, errors: Dict[str, str]):
        super().__init__("; ".join(errors.values()))
        self.errors = errors


class StudyPathError(Exception):
    """A request for a file the studio does not serve (outside the study folder, or not one of its files)."""


@dataclass
class MapRecord:
    """One map: the Bench it was played with, the what-ifs that made it and its notes so far."""
    id: int
    bench: Bench
    label: str
    strengths: str
    folder: str  # relative to the study folder, e.g. "maps/003" (maps/003.partial on disk until it is whole)
    total: int
    changes: Dict[str, Any] = field(default_factory=dict)  # the what-ifs, as Bench.with_changes takes them
    notes: List[dict] = field(default_factory=list)
    status: str = "waiting"  # waiting, running, done, stopped, failed, superseded
    error: str = ""
    before: Optional["MapRecord"] = None
    seconds: Optional[float] = None
    advice: Optional[dict] = None
    advice_status: str = ""  # "", waiting, running, done, failed
    advice_error: str = ""
    dress: Optional[dict] = None  # the fret dress (Bench.dress, its DataFrame and Bench left out)
    dress_status: str = ""
    dress_error: str = ""
    whole: bool = False  # its folder renamed from NNN.partial to NNN: every note written
    replayed: Optional[List[str]] = None  # the strings played again (the others' notes are the map before's); None: all
    attack_scale: Optional[float] = None  # the player's touch (a calibration's attack scale) it was played at
    advice_tolerate: str = ""  # what the advice and the dress were asked to tolerate ("": set-up practice)
    dress_tolerate: str = ""
    # A running search's progress, as the page says it: the notes its probes played so far.
    advice_progress: str = ""
    dress_progress: str = ""

    @property
    def attacks(self) -> List[str]:
        """The attacks' labels in the order asked for (the advice takes the last, the strongest)."""
        return [a.strip() for a in self.strengths.split(",") if a.strip()]


@dataclass
class Job:
    id: Union[int, str]  # a map's number, "advice N" / "dress N" / "calibration of map N" for the jobs on map N
    kind: str  # "map", "advice", "dress" or "calibration"
    record: MapRecord
    label: str
    superseded_by: Optional[Union[int, str]] = None
    report: str = ""  # a calibration's: the player's report (CSV) as it was when asked for
    tolerate: str = ""  # a calibration's: what its advice tolerates


def _text(field_name: str, value: Any) -> Optional[str]:
    """A control's value as the library takes it: None when left empty, else a bounded string."""
    if value is None or (isinstance(value, str) and not value.strip()):
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise FieldErrors({field_name: f"{field_name}: expected a number or a length such as \"0.3 mm\", "
                                       f"got {type(value).__name__}"})
    text = str(value).strip()
    if len(text) > MAX_VALUE_CHARS:
        raise FieldErrors({field_name: f"{field_name}: at most {MAX_VALUE_CHARS} characters"})
    return text


def _as_played(note: dict) -> dict:
    """A note of a studio map as the library gave it (without the comparison added to it)."""
    return {k: v for k, v in note.items() if k not in ("change", "reason", "before")}


def _per_string(form: dict, key: str) -> dict:
    values = form.get(key) or {}
    if not isinstance(values, dict):
        raise FieldErrors({key: f"{key}: expected one value per string"})
    return values


class Study:
    """The studio's state and its worker. Study(bench, folder) plays the instrument as it is
    (the first map) unless start=False (the tests drive the queue by hand). It takes the
    folder's lock (StudyBusy when another studio holds it) until close(), removes the maps a
    killed studio left unfinished and, with keep_maps, all but the newest keep_maps maps."""

    def __init__(self, bench: Bench, folder: str, *, strengths: str = "medium", start: bool = True,
                 keep_maps: Optional[int] = None):
        self.base = bench
        self.what_if({"strengths": strengths})  # a bad attack is refused before the folder is made
        os.makedirs(folder, exist_ok=True)
        self.folder = os.path.realpath(folder)
        self._lock_fd: Optional[int] = lock_folder(self.folder)
        try:
            self.pruned = prune_maps(self.folder, keep_maps)
        except BaseException:
            self._unlock()
            raise
        self.lock = threading.Condition()
        self.version = 0
        self.pending: Deque[Job] = collections.deque()
        self.running: Optional[Job] = None
        self.superseded: Deque[Job] = collections.deque(maxlen=8)
        self.latest: Optional[MapRecord] = None  # the newest map under way or finished
        self.done: Optional[MapRecord] = None  # the newest finished map
        self.maps: Dict[int, MapRecord] = {}
        self.exports: List[str] = []
        # The player's report, as clicked on the maps: {(string, fret, attack): "buzz" or "clean"},
        # and its calibration (Bench.calibrate's result) once asked for.
        self.heard: Dict[tuple, str] = {}
        self.heard_version = 0
        self.calibration: Optional[dict] = None
        self.calibration_status = ""  # "", waiting, running, done, failed
        self.calibration_error = ""
        self.calibrated_map: Optional[int] = None  # the map played with the player's touch after it
        self.closing = False
        self._next_id = self._first_free_id()
        self.strengths = strengths  # the attacks the page starts with
        self.submit_map({"strengths": strengths})
        self._worker: Optional[threading.Thread] = None
        if start:
            self.start()

    def _first_free_id(self) -> int:
        """Maps are numbered on from those an earlier session left in the folder."""
        maps = os.path.join(self.folder, "maps")
        names = os.listdir(maps) if os.path.isdir(maps) else []
        return max((int(m.group(1)) for m in map(MAP_FOLDER.fullmatch, names) if m), default=0) + 1

    def start(self) -> None:
        self._worker = threading.Thread(target=self._work, name="fretbuzz-studio", daemon=True)
        self._worker.start()

    def close(self) -> None:
        """Stops the map under way (within about 0.2 s) and the worker, and lets go of the
        folder's lock."""
        with self.lock:
            self.closing = True
            self.lock.notify_all()
        if self._worker is not None:
            self._worker.join(timeout=10)
        self._unlock()

    def _unlock(self) -> None:
        if self._lock_fd is not None:
            os.close(self._lock_fd)
            self._lock_fd = None

    def _changed(self) -> None:
        self.version += 1
        self.lock.notify_all()

    # What-ifs -------------------------------------------------------------------------

    def what_if(self, form: dict) -> tuple:
        """The page's controls (relief, action12/nut/saddle {string: mm}, fret and fret_offset,
        strengths) as a Bench after those changes from the instrument as loaded, and the
        attacks. Every value goes through the library's checks; FieldErrors names the
        control of each bad one."""
        if not isinstance(form, dict):
            raise FieldErrors({"form": "expected the controls as a JSON object"})
        errors: Dict[str, str] = {}
        changes: Dict[str, Any] = {}

        def check(name: str, **change: Any) -> bool:
            try:
                self.base.with_changes(**change).instrument.geometry()
                return True
            except (InputError, FieldErrors) as e:
                errors[name] = str(e)
                return False

        def take(name: str, value: Any) -> Optional[str]:
            try:
                return _text(name, value)
            except FieldErrors as e:
                errors.update(e.errors)
                return None

        relief = take("relief", form.get("relief"))
        if relief is not None and check("relief", relief=relief):
            changes["relief"] = relief
        for key in PER_STRING:  # the page's saddle box is saddle_change: a move, as a luthier makes one
            try:
                values = _per_string(form, key)
            except FieldErrors as e:
                errors.update(e.errors)
                continue
            for string, raw in values.items():
                name = f"{key}.{string}"
                value = take(name, raw)
                if value is not None and check(name, **{key: {str(string): value}}):
                    changes.setdefault(key, {})[str(string)] = value
        fret_text = take("fret", form.get("fret"))
        offset = take("fret_offset", form.get("fret_offset"))
        if offset is not None:
            if fret_text is None:
                errors["fret"] = f"fret: choose the fret to change (1 to {self.base.frets})"
            elif not re.fullmatch(r"[0-9]{1,4}", fret_text):  # ASCII: int() takes "٣" too
                errors["fret"] = f"fret: {fret_text!r} is not a fret (a whole number, 1 to {self.base.frets})"
            else:
                fret = int(fret_text)
                if check("fret", fret_offsets={fret: 0.0}) and check("fret_offset", fret_offsets={fret: offset}):
                    changes["fret_offsets"] = {fret: offset}
        player = form.get("player", False)
        if not isinstance(player, bool):
            errors["player"] = f"player: expected true or false, got {type(player).__name__}"
        elif player and (self.calibration is None or self.calibration.get("attack_scale") is None):
            errors["player"] = ("player: no calibration with an attack scale yet: mark the notes as you hear them "
                                "and calibrate first")
        strengths = take("strengths", form.get("strengths"))
        if strengths is None and "strengths" not in errors:
            errors["strengths"] = "strengths: choose at least one attack (soft, medium, hard, pop, slap or an amplitude in mm)"
        elif strengths is not None:
            try:
                self.base.check(strengths=strengths, frets=[0])
            except InputError as e:
                errors["strengths"] = str(e)
        if errors:
            raise FieldErrors(errors)
        bench = self.base.with_changes(**changes) if changes else self.base
        try:
            bench.instrument.geometry()  # the changes together (each alone passed)
        except InputError as e:
            raise FieldErrors({"form": str(e)}) from None
        if player:
            bench = bench.with_player(self.calibration)
        return bench, changes, strengths

    @staticmethod
    def describe(changes: Dict[str, Any], strengths: str, attack_scale: Optional[float] = None) -> str:
        """The what-ifs in words, for the page and the report."""
        def length(value: Any) -> str:  # as typed, in mm unless it says its unit
            return f"{value} mm" if re.fullmatch(r"[-+]?[0-9.]+", str(value)) else str(value)
        words = []
        if "relief" in changes:
            words.append(f"relief {length(changes['relief'])}")
        for key, what in (("action12", "action at fret 12"), ("nut", "gap over fret 1"), ("saddle", "saddle height"),
                          ("saddle_change", "saddle moved by")):
            for string, value in changes.get(key, {}).items():
                words.append(f"{string} {what} {length(value)}")
        for fret, value in changes.get("fret_offsets", {}).items():
            words.append(f"fret {fret} levelled" if value == "level" else f"fret {fret} moved by {length(value)}")
        touch = f" x{attack_scale:.2f}, the player's touch" if attack_scale is not None else ""
        return (", ".join(words) or "as set up") + f"; attack {strengths}{touch}"

    # The queue ------------------------------------------------------------------------

    def _queue(self, job: Job) -> List[Job]:
        """Adds a job behind the running one; when QUEUE_LIMIT already wait, the oldest
        waiting ones are superseded. Returns those."""
        dropped = []
        with self.lock:
            while len(self.pending) >= QUEUE_LIMIT:
                old = self.pending.popleft()
                old.superseded_by = job.id
                if old.kind == "map":
                    old.record.status = "superseded"
                    self.maps.pop(old.record.id, None)  # never played: nothing of it to show
                elif old.kind == "calibration":
                    self.calibration_status = ""
                else:
                    setattr(old.record, f"{old.kind}_status", "")
                self.superseded.append(old)
                dropped.append(old)
            self.pending.append(job)
            self._changed()
        return dropped

    def _new_id(self) -> int:
        """The next map's number."""
        with self.lock:
            n = self._next_id
            self._next_id += 1
            return n

    def submit_map(self, form: dict) -> tuple:
        """Queues the map of a what-if (the page's controls, see what_if); returns the job and
        the jobs it superseded. FieldErrors, and nothing queued, for a bad value."""
        bench, changes, strengths = self.what_if(form)
        record = self._new_map(bench, changes, strengths)
        job = Job(record.id, "map", record, record.label)
        return job, self._queue(job)

    def _new_map(self, bench: Bench, changes: Dict[str, Any], strengths: str) -> MapRecord:
        """A map of this study, to be played (registered under the next number)."""
        n = self._new_id()
        record = MapRecord(n, bench, self.describe(changes, strengths, bench.attack_scale), strengths,
                           f"maps/{n:03d}", bench.check(strengths=strengths), changes, attack_scale=bench.attack_scale)
        with self.lock:
            self.maps[n] = record
        return record

    def tolerance(self, value: Any) -> str:
        """What the page asks the advice and the dress to tolerate, as --tolerate takes it
        ("": set-up practice's defaults); FieldErrors keyed "tolerate" with the library's message."""
        text = _text("tolerate", value) or ""
        try:
            _core._setup_tolerance(self.base.instrument, text)
        except InputError as e:
            raise FieldErrors({"tolerate": str(e)}) from None
        return text

    def submit_advice(self, kind: str = "advice", tolerate: str = "") -> tuple:
        """Queues the advice ("advice") or the fret dress ("dress") for the newest finished map
        (InputError when there is none yet), tolerating what `tolerate` says (see tolerance);
        nothing when the same is waiting, running or done."""
        what = {"advice": "advice", "dress": "fret dress"}[kind]
        tolerate = self.tolerance(tolerate)
        with self.lock:
            record = self.done
            if record is None:
                raise InputError(f"{kind}: no map has finished yet; the {what} searches from a finished map")
            status = getattr(record, f"{kind}_status")
            if status in ("waiting", "running") or (status == "done" and getattr(record, f"{kind}_tolerate") == tolerate):
                return None, []
            setattr(record, f"{kind}_status", "waiting")
            setattr(record, f"{kind}_tolerate", tolerate)
        job = Job(f"{kind} {record.id}", kind, record, f"{what} for map {record.id} ({record.label})")
        return job, self._queue(job)

    # The worker -----------------------------------------------------------------------

    def _work(self) -> None:
        while True:
            with self.lock:
                while not self.pending and not self.closing:
                    self.lock.wait()
                if self.closing:
                    return
                job = self.pending.popleft()
                self.running = job
                self._changed()
            try:
                if job.kind == "map":
                    self._play(job.record)
                elif job.kind == "calibration":
                    self._calibrate(job)
                else:
                    self._advise(job.record, job.kind)
            finally:
                with self.lock:
                    self.running = None
                    self._changed()

    @staticmethod
    def replayed_strings(record: MapRecord) -> Optional[List[str]]:
        """The strings a map must play when it differs from the finished map before it only in
        per-string settings (action, nut, saddle) at the same attacks: those strings, in the
        map's order; None when every string must be played."""
        before = record.before
        if (before is None or before.status != "done" or not before.whole or before.strengths != record.strengths
                or before.attack_scale != record.attack_scale):
            return None
        now, was = record.changes, before.changes
        if any(now.get(k) != was.get(k) for k in set(now) | set(was) if k not in PER_STRING):
            return None
        changed = {s for k in PER_STRING for s in set(now.get(k, {})) | set(was.get(k, {}))
                   if now.get(k, {}).get(s) != was.get(k, {}).get(s)}
        names = list(dict.fromkeys(n["string"] for n in before.notes))
        return [s for s in names if s in changed]

    def _play(self, record: MapRecord) -> None:
        with self.lock:
            record.before = self.done
            record.status = "running"
            self.latest = record
            self._changed()
        before = list(record.before.notes) if record.before else []
        replay = record.replayed = self.replayed_strings(record)
        started = time.monotonic()

        def progress(note: dict, done: int, total: int) -> None:
            change, reason, was = "", "", None
            if before:
                compared = Bench.compare([dict(note)], before).iloc[0]
                change, reason = compared["change"], compared["reason"]
                was = next((_as_played(b) for b in before
                            if (b["string"], b["fret"], b["strength"]) == (note["string"], note["fret"], note["strength"])),
                           None)
            with self.lock:
                record.notes.append({**note, "change": change, "reason": reason, "before": was})
                self._changed()

        partial = os.path.join(self.folder, record.folder + PARTIAL)
        try:
            if replay is not None:  # the unchanged strings' notes and sounds as the map before has them
                os.makedirs(partial, exist_ok=True)
                kept = [_as_played(n) for n in before if n["string"] not in replay]
                for n in kept:
                    if n.get("audio"):
                        source = os.path.join(self.folder, record.before.folder, n["audio"])
                        try:  # only a regular file the studio wrote: never through a link planted there
                            regular = stat.S_ISREG(os.lstat(source).st_mode)
                        except OSError:
                            regular = False
                        if not regular:
                            n["audio"] = ""  # the note is kept, its sound is not
                            continue
                        try:
                            os.link(source, os.path.join(partial, n["audio"]), follow_symlinks=False)
                        except OSError:
                            shutil.copyfile(source, os.path.join(partial, n["audio"]), follow_symlinks=False)
                for i, n in enumerate(kept):
                    progress(n, i + 1, record.total)
            if replay is None or replay:
                record.bench.map(strings=replay, strengths=record.strengths, audio_dir=partial, progress=progress,
                                 stop=lambda: self.closing)
            status, error = ("stopped", "") if self.closing else ("done", "")
        except Exception as e:  # shown on the page; the studio keeps serving
            status, error = "failed", f"{type(e).__name__}: {e}" if not isinstance(e, InputError) else str(e)
        with self.lock:
            if status == "done":
                try:
                    if os.path.isdir(partial):
                        os.rename(partial, os.path.join(self.folder, record.folder))
                    record.whole = True
                except OSError as e:
                    status, error = "failed", f"cannot keep the map's sounds: {e}"
            if status != "done":
                try:  # its sounds would take the disk's room from every map after it
                    remove_partial(self.folder, record.folder)
                except OSError as e:
                    error += f" (its unfinished sounds stay in {record.folder + PARTIAL}: {e})"
            record.status, record.error = status, error
            record.seconds = time.monotonic() - started
            if status == "done":
                self.done = record
            self._changed()

    def _advise(self, record: MapRecord, kind: str = "advice") -> None:
        with self.lock:
            setattr(record, f"{kind}_status", "running")
            setattr(record, f"{kind}_progress", "")
            self._changed()
        played = 0

        def progress(note: dict, probes: int) -> None:
            nonlocal played
            played += 1
            with self.lock:
                setattr(record, f"{kind}_progress",
                        f"{played} note{'s' if played != 1 else ''} played in {probes} "
                        f"probe{'s' if probes != 1 else ''}; the last, {note['string']} fret {note['fret']}: "
                        f"{note['verdict'] or note['status']}")
                self._changed()
        attack = record.attacks[-1]
        at_attack = [{k: v for k, v in n.items() if k not in ("change", "before")} for n in record.notes
                     if n["strength"] == attack]
        try:
            # The map's notes at that attack (None: the library plays them, should the labels differ).
            tolerate = getattr(record, f"{kind}_tolerate")
            if kind == "advice":
                result = record.bench.advise(at_attack or None, strength=attack, tolerate=tolerate, progress=progress)
            else:
                result = record.bench.dress(at_attack or None, strength=attack, tolerate=tolerate, progress=progress)
                result = {k: v for k, v in result.items() if k not in ("dressed",)}
                result["after"] = result["after"].to_dict("records")
            with self.lock:
                setattr(record, kind, result)
                setattr(record, f"{kind}_status", "done")
        except Exception as e:  # shown on the page
            with self.lock:
                setattr(record, f"{kind}_status", "failed")
                setattr(record, f"{kind}_error", str(e))
        with self.lock:
            self._changed()

    # The player's report ------------------------------------------------------------

    def set_heard(self, form: Any) -> None:
        """One note of the player's report, as clicked on a map: {string, fret, strength, heard}
        with heard "buzz", "clean" or "" (taken out of the report). FieldErrors keyed "heard"."""
        if not isinstance(form, dict):
            raise FieldErrors({"heard": "heard: expected the note as a JSON object"})
        string, fret, strength, heard = (form.get(k) for k in ("string", "fret", "strength", "heard"))
        if heard not in ("buzz", "clean", ""):
            raise FieldErrors({"heard": f"heard: {str(heard)[:MAX_VALUE_CHARS]!r} must be \"buzz\", \"clean\" or "
                                        "\"\" (out of the report)"})
        if not isinstance(string, str) or string not in self.base.strings:
            raise FieldErrors({"heard": f"string: {str(string)[:MAX_VALUE_CHARS]!r} is not a string of "
                                        f"{self.base.instrument.name} (its strings: {', '.join(self.base.strings)})"})
        if isinstance(fret, bool) or not isinstance(fret, int) or not 0 <= fret <= self.base.frets:
            raise FieldErrors({"heard": f"fret: {str(fret)[:MAX_VALUE_CHARS]!r} is not a fret (0 to {self.base.frets})"})
        try:
            attack = _text("strength", strength)
            self.base.check(strengths=attack or "", frets=[0])
            if attack is None or "," in attack:
                raise InputError(f"strength: {strength!r}: give one attack")
        except InputError as e:
            raise FieldErrors({"heard": str(e)}) from None
        with self.lock:
            if heard:
                self.heard[(string, fret, attack)] = heard
            else:
                self.heard.pop((string, fret, attack), None)
            self.heard_version += 1
            self._changed()

    def report_csv(self) -> str:
        """The player's report as `fretbuzz setup --calibrate` reads it."""
        with self.lock:
            rows = [f"{s},{k},{a},{h}" for (s, k, a), h in self.heard.items()]
        return "\n".join(["string,fret,strength,heard", *rows]) + "\n"

    def submit_calibration(self, tolerate: str = "") -> tuple:
        """Queues the calibration of the player's report on the instrument as loaded; with a
        scale found, it then plays the newest finished map's set-up at the player's touch and
        its advice (tolerating `tolerate`). InputError with no report or no finished map."""
        tolerate = self.tolerance(tolerate)
        with self.lock:
            if not self.heard:
                raise FieldErrors({"calibrate": "calibrate: the report is empty: click a note of the map and say "
                                                "whether it buzzes or rings clean for you"})
            record = self.done
            if record is None:
                raise FieldErrors({"calibrate": "calibrate: no map has finished yet; the calibrated map repeats the "
                                                "newest finished one"})
            if self.calibration_status in ("waiting", "running"):
                return None, []
            self.calibration_status, self.calibration_error = "waiting", ""
            report = self.report_csv()
        job = Job(f"calibration of map {record.id}", "calibration", record,
                  f"calibration of the player's report ({len(self.heard)} notes), then map {record.id}'s set-up "
                  "at the player's touch and its advice", report=report, tolerate=tolerate)
        return job, self._queue(job)

    def _calibrate(self, job: Job) -> None:
        record = job.record
        with self.lock:
            self.calibration_status = "running"
            self._changed()
        try:
            result = self.base.calibrate(job.report)
        except Exception as e:  # shown on the page
            with self.lock:
                self.calibration_status, self.calibration_error = "failed", str(e)
                self._changed()
            return
        with self.lock:
            self.calibration, self.calibration_status = result, "done"
            self._changed()
        if result.get("attack_scale") is None or self.closing:
            return
        calibrated = self._new_map(record.bench.with_player(result), dict(record.changes), record.strengths)
        with self.lock:
            self.calibrated_map = calibrated.id
        self._play(calibrated)
        if calibrated.status == "done" and not self.closing:
            calibrated.advice_status, calibrated.advice_tolerate = "waiting", job.tolerate
            self._advise(calibrated)

    # Notes ----------------------------------------------------------------------------

    def note(self, map_id: int, string: str, fret: int, strength: str) -> dict:
        """One note of a map: its verdict, and the pluck its verdict rests on (the library's
        deciding_pluck) played again with everything kept (the contacts over time) and its
        sound's place in the study folder: the map's WAV when that pluck is the attack itself
        (member 0), else a WAV of it written beside the map's (once)."""
        record = self.maps.get(map_id)
        if record is None:
            raise InputError(f"map: {map_id} is not a map of this study (maps: {', '.join(map(str, self.maps))})")
        verdict = next((n for n in list(record.notes)
                        if (n["string"], n["fret"], n["strength"]) == (string, fret, strength)), None)
        if verdict is None:
            raise InputError(f"{string} fret {fret} {strength}: not played in map {map_id} (yet)")
        member = int(verdict.get("deciding_pluck") or 0)
        name = verdict.get("audio") or ""
        if member and name:
            name = f"{name[:-len('.wav')]}-pluck{member + 1}.wav"
            with self.lock:
                folder = os.path.join(self.folder, record.folder + ("" if record.whole else PARTIAL))
            wav = os.path.join(folder, name)
            played = record.bench.note(string, fret, strength, member=member,
                                       wav=None if os.path.isfile(wav) else wav)
        else:
            played = record.bench.note(string, fret, strength, member=member)
        audio = f"{record.folder}/{name}" if name else None
        return {"record": record, "verdict": verdict, "played": played, "audio": audio, "member": member}

    # Files ----------------------------------------------------------------------------

    def path(self, relative: str) -> str:
        """The real path of one of the study's files (a note's WAV, a report), or
        StudyPathError: absolute paths, '..', names that resolve outside the folder (through a
        symbolic link or otherwise), and anything but a regular .wav or .html file are refused."""
        if not relative or "\x00" in relative or "\\" in relative or relative.startswith("/") or os.path.isabs(relative):
            raise StudyPathError(f"{relative!r}: not a file of the study")
        if any(part in ("", ".", "..") for part in relative.split("/")):
            raise StudyPathError(f"{relative!r}: not a file of the study")
        parts = relative.split("/")
        if len(parts) > 2 and parts[0] == "maps" and re.fullmatch(r"[0-9]{3,}", parts[1]):
            record = self.maps.get(int(parts[1]))
            if record is not None and not record.whole:  # still under its unfinished name
                relative = "/".join([parts[0], parts[1] + PARTIAL] + parts[2:])
        real = os.path.realpath(os.path.join(self.folder, relative))
        if os.path.commonpath([real, self.folder]) != self.folder or real == self.folder:
            raise StudyPathError(f"{relative!r}: outside the study folder")
        if os.path.splitext(real)[1].lower() not in SERVED_SUFFIXES or not os.path.isfile(real):
            raise FileNotFoundError(relative)
        return real

    def as_found(self) -> Optional[MapRecord]:
        """The instrument as found: the first finished map of the study with no what-if."""
        with self.lock:
            found = [r for _, r in sorted(self.maps.items())
                     if r.status == "done" and not r.changes and r.attack_scale is None]
        return found[0] if found else None

    def export_path(self, record: MapRecord) -> str:
        """Where the report of a map goes, relative to the study folder."""
        return f"exports/report-{record.id:03d}.html"
