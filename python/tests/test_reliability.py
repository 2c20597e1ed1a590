"""Nothing outside its own folders, every call bounded: a study folder whose maps/ (or
exports/) is a symbolic link is refused by `fretbuzz clean` and by the studio, and nothing of
the link's target is deleted; pruning removes only the WAVs a map wrote; a map that fails on a
full disk removes its unfinished folder at once, so the next map has the room; Ctrl-C reaches
fretbuzz.estimate() and the advice's and dress's searches within a fraction of a second;
run() and estimate() on a daemon thread never abort the process at the interpreter's end;
the bench's lists are bounded and each entry counts once; a fret or a member beyond any
range, nonsense map rows and a dress depth of 1e308 are refused naming the argument, before
anything is played."""
import errno
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import textwrap
import time
import unittest

import fretbuzz
from fretbuzz.studio import study as study_module
from fretbuzz.studio.study import Study, StudyLayoutError, prune_maps

CLI = os.environ.get("FRETBUZZ_CLI")
QUICK = dict(ensemble=2, fs=3e5, duration=0.05)
PYTHON = sys.executable


def quick_bench(instrument="bass-neck", **kwargs):
    return fretbuzz.Bench(instrument, **{**QUICK, **kwargs})


def listing(folder):
    return sorted(os.path.relpath(os.path.join(d, n), folder) for d, dirs, files in os.walk(folder) for n in dirs + files)


class LinkedFoldersTest(unittest.TestCase):
    """A study folder with a symbolic link where the studio keeps a folder of its own."""

    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="fretbuzz-links-")
        self.victim = os.path.join(self.dir, "victim")
        for name in ("001", "002", "003.partial", "1234", "notes"):
            os.makedirs(os.path.join(self.victim, name))
            with open(os.path.join(self.victim, name, "keep.txt"), "w") as f:
                f.write("mine\n")
        with open(os.path.join(self.victim, "001", "note-G-00-medium.wav"), "wb") as f:
            f.write(b"RIFF")
        self.study = os.path.join(self.dir, "study")
        os.makedirs(self.study)
        open(os.path.join(self.study, study_module.LOCK_NAME), "w").close()
        self.before = listing(self.victim)

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    @unittest.skipUnless(CLI, "FRETBUZZ_CLI (the fretbuzz program) is not set")
    def test_fretbuzz_clean_refuses_a_linked_maps_folder_and_deletes_nothing(self):
        os.symlink("../victim", os.path.join(self.study, "maps"))
        for words in ([], ["--keep-maps", "0"]):
            run = subprocess.run([CLI, "clean", self.study, *words], capture_output=True, text=True, timeout=60)
            self.assertEqual(run.returncode, 2, run.stderr)
            self.assertIn("maps is a symbolic link", run.stderr)
            self.assertEqual(listing(self.victim), self.before)

    def test_the_studio_refuses_a_linked_folder_of_its_own(self):
        for name in ("maps", "exports"):
            link = os.path.join(self.study, name)
            os.symlink("../victim", link)
            with self.assertRaises(StudyLayoutError) as refused:
                Study(quick_bench(), self.study, start=False, keep_maps=0)
            self.assertIn(f"{name} is a symbolic link", str(refused.exception))
            self.assertIsInstance(refused.exception, fretbuzz.InputError)  # the studio exits 2
            self.assertEqual(listing(self.victim), self.before)
            os.unlink(link)
        Study(quick_bench(), self.study, start=False).close()  # the lock was let go

    def test_pruning_removes_only_what_a_map_wrote(self):
        maps = os.path.join(self.study, "maps")
        os.makedirs(os.path.join(maps, "001"))
        for name in ("note-G-00-medium.wav", ".note-G-01-medium.tmp-12-3.wav", "keep.txt"):
            open(os.path.join(maps, "001", name), "w").close()
        os.makedirs(os.path.join(maps, "002.partial"))
        open(os.path.join(maps, "002.partial", "note-G-00-medium.wav"), "w").close()
        os.makedirs(os.path.join(maps, "003"))
        os.symlink(os.path.join(self.victim, "001", "note-G-00-medium.wav"), os.path.join(maps, "003", "note-G-02-soft.wav"))
        os.symlink("../../victim/002", os.path.join(maps, "004"))  # a link with a map's name
        self.assertEqual(prune_maps(self.study, keep=0), (1, 0))
        # 001 keeps what fretbuzz did not write (and so stays); 003's link named like a WAV is
        # not a file the map wrote: it stays, and its target too; 004 is no map.
        self.assertEqual(sorted(os.listdir(maps)), ["001", "003", "004"])
        self.assertEqual(os.listdir(os.path.join(maps, "001")), ["keep.txt"])
        self.assertEqual(listing(self.victim), self.before)


class FullDiskTest(unittest.TestCase):
    """A map that fails on a full disk removes its unfinished folder: the next map has the room."""

    def test_a_failed_map_leaves_no_partial_folder(self):
        folder = tempfile.mkdtemp(prefix="fretbuzz-full-")
        try:
            study = Study(quick_bench(), folder, start=False)
            try:
                job = study.pending.popleft()
                played = job.record.bench.map

                def full_disk(*, audio_dir, **kwargs):  # a note's WAV written, then the disk is full
                    os.makedirs(audio_dir, exist_ok=True)
                    with open(os.path.join(audio_dir, "note-E-00-medium.wav"), "wb") as f:
                        f.write(b"\0" * 4096)
                    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), os.path.join(audio_dir, "note-E-01-medium.wav"))

                job.record.bench.map = full_disk
                study._play(job.record)
                self.assertEqual(job.record.status, "failed")
                self.assertIn("No space left on device", job.record.error)
                self.assertEqual(os.listdir(os.path.join(folder, "maps")), [])
                # The next what-if plays whole.
                job.record.bench.map = played
                second, _ = study.submit_map({"strengths": "medium", "relief": "0.3"})
                study.pending.remove(second)
                study._play(second.record)
                self.assertEqual(second.record.status, "done", second.record.error)
                self.assertEqual(os.listdir(os.path.join(folder, "maps")), [second.record.folder.split("/")[1]])
            finally:
                study.close()
        finally:
            shutil.rmtree(folder, ignore_errors=True)


def python_program(*parts):
    code = "".join(textwrap.dedent(part) for part in parts)
    return subprocess.Popen([PYTHON, "-u", "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


class SignalsAndThreadsTest(unittest.TestCase):
    # A free decay whose estimate takes several seconds.
    DECAY = """
        import fretbuzz, numpy as np, threading, time
        fs = 48000
        t = np.arange(fs * 8) / fs
        x = sum(np.exp(-t * (0.5 + k * 0.3)) * np.sin(2 * np.pi * 98 * k * t) / k for k in range(1, 60))
    """

    def test_ctrl_c_reaches_an_estimate_at_once(self):
        p = python_program(self.DECAY, """
        print("go", flush=True)
        fretbuzz.estimate(x, fs, f0=98.0)
        print("finished", flush=True)
        """)
        self.assertEqual(p.stdout.readline().strip(), "go")
        time.sleep(1.0)  # well inside the estimate
        sent = time.monotonic()
        p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=120)
        latency = time.monotonic() - sent
        self.assertNotIn("finished", out)
        self.assertIn("KeyboardInterrupt", err)
        self.assertLess(latency, 3.0, "Ctrl-C seen only when the estimate ended")

    def test_ctrl_c_reaches_a_search_at_once(self):
        # The dress's search (its probes are the advice's: NoteTrials) with its map given.
        p = python_program("""
        import fretbuzz
        bench = fretbuzz.Bench('jazz-bass', strengths='medium', ensemble=3, fs=5e5, duration=0.1)
        notes = bench.map(strings='E')
        print("go", flush=True)
        bench.dress(notes, strings='E', depth=0.5, tolerate='none')  # every note: a long search
        print("finished", flush=True)
        """)
        self.assertEqual(p.stdout.readline().strip(), "go")
        time.sleep(1.0)  # the search plays its probes (several seconds of them)
        sent = time.monotonic()
        p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=300)
        self.assertNotIn("finished", out, "the search ended within 1 s: nothing to interrupt")
        self.assertIn("KeyboardInterrupt", err)
        self.assertLess(time.monotonic() - sent, 3.0, "Ctrl-C seen only when the search ended")

    def test_a_daemon_thread_at_the_interpreters_end_does_not_abort(self):
        # The run on its slow reference path: still stepping when the interpreter ends.
        for work in ("fretbuzz.run('bass-pop', duration=3, screen=False, free_flight=False)",
                     "fretbuzz.estimate(x, fs, f0=98.0)"):
            with self.subTest(work=work):
                p = python_program(self.DECAY, f"""
                junk = [{{"k": i}} for i in range(4 * 10**6)]  # a slow interpreter end: the thread wakes in it
                thread = threading.Thread(target=lambda: {work}, daemon=True)
                thread.start()
                time.sleep(1.5)
                print("still working at the end:", thread.is_alive(), flush=True)
                """)
                out, err = p.communicate(timeout=120)
                self.assertIn("still working at the end: True", out)
                self.assertEqual(p.returncode, 0, err)
                self.assertNotIn("terminate called", err)


class BoundedArgumentsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.bench = fretbuzz.Bench("jazz-bass", strengths="medium")

    def refused(self, call, *words):
        with self.assertRaises(fretbuzz.InputError) as e:
            call()
        for word in words:
            self.assertIn(word, str(e.exception))
        return str(e.exception)

    def test_lists_are_bounded_and_each_entry_counts_once(self):
        self.assertEqual(self.bench.check(strings="G,G,G", frets=[0, 0, 5, 0]), 2)
        self.assertEqual(self.bench.check(strings=["G", "G"], frets=[3]), 1)
        started = time.monotonic()
        self.refused(lambda: self.bench.map(frets=[0] * 10**6), "frets", "1000000 entries")
        self.refused(lambda: self.bench.map(strings=["G"] * 10**5), "strings", "100000 entries")
        self.assertLess(time.monotonic() - started, 10.0)

    def test_numbers_beyond_any_range_name_the_argument(self):
        self.refused(lambda: self.bench.check(frets=[2**64]), "frets = 18446744073709551616", "[0, 20]")
        self.refused(lambda: self.bench.map(frets=[2**64]), "frets", "[0, 20]")
        self.refused(lambda: self.bench.note("G", 10**30), "fret = 1" + "0" * 30, "[0, 20]")
        self.refused(lambda: self.bench.note("G", 0, member=10**30), "member")

    def row(self, **change):
        return {"string": "G", "fret": 3, "strength": "medium", "verdict": "clean", "buzz_fraction": 0.0,
                "buzz_dB": None, "buzz_fret": None, "clean_up_to": None, **change}

    def test_nonsense_rows_are_refused_naming_the_row(self):
        for change, words in (({"fret": 99}, ("map row 0: fret", "0 to 20")),
                              ({"string": "Q"}, ("map row 0:", "Q")),
                              ({"verdict": "banana"}, ("map row 0: verdict", "banana")),
                              ({"buzz_fret": 77}, ("map row 0: buzz_fret",)),
                              ({"clean_up_to": -3.0}, ("map row 0: clean_up_to",)),
                              ({"buzz_dB": 1e300}, ("map row 0: buzz_dB",))):
            with self.subTest(change=change):
                rows = [self.row(), self.row(fret=4)]
                rows[0].update(change)
                self.refused(lambda: self.bench.advise(rows, strings="G", frets=[3, 4]), *words)
                self.refused(lambda: self.bench.dress(rows, strings="G", frets=[3, 4]), *words)

    def test_a_bad_dress_is_refused_before_anything_is_played(self):
        bench = fretbuzz.Bench("jazz-bass", strengths="medium")

        def played(**kwargs):
            raise AssertionError("the map was played before the dress's arguments were checked")

        bench.map = played
        self.refused(lambda: bench.dress(depth=1e308), "depth", "[0.01, 1] mm")
        self.refused(lambda: bench.dress(crown="5 mm"), "crown")
        self.refused(lambda: bench.dress(fall_away=10**30), "fall_away")
        self.refused(lambda: bench.dress(frets=[2**64]), "frets")


if __name__ == "__main__":
    unittest.main()
