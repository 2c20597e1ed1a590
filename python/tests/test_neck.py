"""Neck set-up studies and buzz maps: the rewritten cases of the clamped stand-in put every
fret top where the full neck has it, seen from the stopped string; a raised fret makes the
notes just below it buzz more (bass and guitar necks) and the comparison marks them; the
clamped and the fretted (finger) notes agree on which notes buzz; `--raise` is the case key
obstacle.frets.height_offsets; bad options are refused with exit status 2 and nothing written."""
import csv
import math
import os
import shutil
import subprocess
import tempfile
import unittest

import numpy as np

import fretbuzz
from fretbuzz import neck

CLI = os.environ.get("FRETBUZZ_CLI")


def bass_neck():
    return neck.Neck(fretbuzz.load_case("bass-neck").source_text, "bass-neck")


def fret_top_heights(case, scale_length, count):
    """The obstacle's height at each fret of a case: the highest grid point within a grid
    step of it (a fret halfway between two points sits on either)."""
    x, g = case.grid_x, case.obstacle_height
    dx = x[1] - x[0]
    return [g[abs(x - scale_length * (1 - 2 ** (-n / 12))) <= dx].max() for n in range(1, count + 1)]


class StandInGeometryTest(unittest.TestCase):
    def spec(self, n, frets):
        text = neck.study_spec(n, "bass-neck", frets, [n.amplitude])
        return fretbuzz.SweepSpec.parse(text, "study", ".")

    def test_stopped_notes_see_the_fret_tops_of_the_full_neck(self):
        n = bass_neck()
        n.raised[9] = 0.05e-3
        frets = [0, 3, 8, 12, 18]
        spec = self.spec(n, frets)
        for run, k in enumerate(frets):
            case = spec.case(run)
            xk = n.fret_x(k)
            self.assertAlmostEqual(case.L, n.L - xk, places=15)
            rest_k = n.fret_top(k) if k else 0.0
            # Fret k+m's top, measured from the line of the string stopped on fret k's top.
            expected = [n.fret_top(k + m) - rest_k * (n.L - n.fret_x(k + m)) / (n.L - xk)
                        for m in range(1, n.N - k + 1)]
            got = fret_top_heights(case, n.S * 2 ** (-k / 12), n.N - k)
            np.testing.assert_allclose(got, expected, rtol=0, atol=1e-15)
            self.assertAlmostEqual(case.grid_x[1] - case.grid_x[0], n.L / (n.modes + 1), delta=2e-5)

    def test_the_open_string_is_the_case_itself(self):
        n = bass_neck()
        case = self.spec(n, [0]).case(0)
        base = fretbuzz.load_case("bass-neck")
        np.testing.assert_allclose(fret_top_heights(case, n.S, n.N), fret_top_heights(base, n.S, n.N),
                                   rtol=0, atol=1e-15)

    def test_the_last_fret_and_notes_beyond_the_pluck_are_refused(self):
        n = bass_neck()
        with self.assertRaisesRegex(fretbuzz.InputError, "fret 20"):
            n.note(20)
        n.pluck_x = 0.3
        with self.assertRaisesRegex(fretbuzz.InputError, "pluck"):
            n.note(12)


def read_map(folder):
    with open(os.path.join(folder, "buzz_map.csv"), newline="") as f:
        return {(int(r["fret"]), float(r["strength_m"])): r for r in csv.DictReader(f)}


@unittest.skipUnless(CLI, "FRETBUZZ_CLI (the fretbuzz program) is not set")
class SetupCommandTest(unittest.TestCase):
    def setUp(self):
        self.folder = tempfile.mkdtemp(prefix="fretbuzz-neck-test-")
        self.addCleanup(shutil.rmtree, self.folder, ignore_errors=True)
        # bass-neck on a 4 mm grid (215 modes, all below 45 kHz) for a cheap study.
        text = fretbuzz.load_case("bass-neck").source_text.replace("modes = 862", "modes = 215")
        self.case = os.path.join(self.folder, "neck.toml")
        with open(self.case, "w") as f:
            f.write(text)

    def setup(self, out, *options, frets="6-10"):
        return subprocess.run([CLI, "setup", self.case, "--out", os.path.join(self.folder, out), "--frets", frets,
                               "--strength", "1e-3,2e-3", "--fs", "400000", "--duration", "0.05", "--quiet",
                               *options], capture_output=True, text=True, timeout=600)

    def test_a_raised_fret_makes_the_notes_below_it_buzz_more(self):
        r = self.setup("nominal")
        self.assertEqual(r.returncode, 0, r.stderr)
        r = self.setup("raised", "--raise", "9:0.05e-3", "--compare", os.path.join(self.folder, "nominal"))
        self.assertEqual(r.returncode, 0, r.stderr)
        nominal, raised = read_map(os.path.join(self.folder, "nominal")), read_map(os.path.join(self.folder, "raised"))
        self.assertEqual(sorted(nominal), [(k, a) for k in range(6, 11) for a in (1e-3, 2e-3)])
        # Fret 9 0.05 mm high: the note just below it, which cleared it plucked gently, now
        # buzzes against it, and buzzes louder plucked harder.
        self.assertEqual(nominal[8, 1e-3]["buzz_fret"], "")
        self.assertEqual(nominal[8, 1e-3]["buzz_dB"], "")
        self.assertEqual(raised[8, 1e-3]["buzz_fret"], "9")
        self.assertTrue(math.isfinite(float(raised[8, 1e-3]["buzz_dB"])))
        self.assertGreater(float(raised[8, 2e-3]["buzz_dB"]), float(nominal[8, 2e-3]["buzz_dB"]) + 1.0)
        self.assertGreater(float(raised[8, 2e-3]["contact_time_s"]), float(nominal[8, 2e-3]["contact_time_s"]))
        # A note stopped above the raised fret never sees it: the same row exactly.
        for a in (1e-3, 2e-3):
            self.assertEqual(raised[10, a], nominal[10, a])
        # The map marks what changed, and has an audio player per note.
        with open(os.path.join(self.folder, "raised", "buzz_map.html")) as f:
            page = f.read()
        self.assertIn("Notes that changed", page)
        self.assertIn("<li>fret 8, strength 0.001 m: buzzes against fret none -&gt; 9</li>", page)
        self.assertNotIn("<li>fret 10,", page)
        self.assertEqual(page.count("<audio"), 10)
        for row in raised.values():
            self.assertTrue(os.path.exists(os.path.join(self.folder, "raised", row["audio"])), row["audio"])
            self.assertEqual(row["status"], "ok")

    def test_a_study_on_dask_draws_the_same_map(self):
        from test_sweep import DaskProcesses
        r = self.setup("local", frets="7-8")
        self.assertEqual(r.returncode, 0, r.stderr)
        cluster = DaskProcesses(self.folder)
        self.addCleanup(cluster.close)
        r = self.setup("dask", "--scheduler", cluster.address, frets="7-8")
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(self.folder, "local", "buzz_map.csv")) as a, \
                open(os.path.join(self.folder, "dask", "buzz_map.csv")) as b:
            self.assertEqual(a.read(), b.read())
        for row in read_map(os.path.join(self.folder, "dask")).values():
            self.assertTrue(os.path.exists(os.path.join(self.folder, "dask", row["audio"])), row["audio"])

    def test_offsets_in_the_case_and_raise_draw_the_same_map(self):
        # `--raise 9:M` is the case key obstacle.frets.height_offsets = { 9 = M }.
        with open(self.case) as f:
            text = f.read()
        raised_case = os.path.join(self.folder, "raised.toml")
        with open(raised_case, "w") as f:
            f.write(text.replace("crown_width = 0.0", "crown_width = 0.0\nheight_offsets = { 9 = 0.05e-3 }"))
        r = self.setup("by-option", "--raise", "9:0.05e-3", frets="8-9")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.case = raised_case
        r = self.setup("by-key", frets="8-9")
        self.assertEqual(r.returncode, 0, r.stderr)
        by_option, by_key = read_map(os.path.join(self.folder, "by-option")), read_map(os.path.join(self.folder, "by-key"))
        self.assertEqual(by_option, by_key)
        self.assertEqual(by_key[8, 1e-3]["buzz_fret"], "9")

    def test_guitar_neck_a_raised_fret_makes_the_note_below_it_buzz(self):
        # guitar-neck on a 4 mm grid (161 modes), picked 0.5 mm: the nominal set-up clears
        # every fret; fret 9 0.05 mm high, the note just below it buzzes against it, loudest
        # of all, and the notes above it do not change.
        text = fretbuzz.load_case("guitar-neck").source_text.replace("modes = 647", "modes = 161")
        self.case = os.path.join(self.folder, "guitar.toml")
        with open(self.case, "w") as f:
            f.write(text)
        maps = {}
        for name, options in (("nominal", []), ("raised", ["--raise", "9:0.05e-3"])):
            r = subprocess.run([CLI, "setup", self.case, "--out", os.path.join(self.folder, name), "--frets", "7-10",
                                "--strength", "0.5e-3", "--fs", "400000", "--duration", "0.05", "--quiet", *options],
                               capture_output=True, text=True, timeout=600)
            self.assertEqual(r.returncode, 0, r.stderr)
            maps[name] = read_map(os.path.join(self.folder, name))
        for k in range(7, 11):
            self.assertEqual(maps["nominal"][k, 5e-4]["frets_touched"], "", k)
        raised = maps["raised"]
        self.assertEqual(raised[8, 5e-4]["buzz_fret"], "9")
        loudest = max(range(7, 11), key=lambda k: float(raised[k, 5e-4]["buzz_dB"] or "-inf"))
        self.assertEqual(loudest, 8)
        for k in (9, 10):
            self.assertEqual(raised[k, 5e-4], maps["nominal"][k, 5e-4])

    def test_fretted_and_clamped_notes_agree_on_which_notes_buzz(self):
        # Fret 9 0.05 mm high, notes 7-10 plucked 1 mm: with the string clamped on the fret
        # and with a finger pressing it behind the fret, the note just below the high fret
        # buzzes against it, loudest of all; the notes above it never touch. With the finger,
        # raising the fret makes that note buzz more than on the nominal neck.
        maps = {}
        for name, options in (("clamped", []), ("fretted", ["--finger"]), ("fretted-nominal", ["--finger"])):
            raised = [] if name == "fretted-nominal" else ["--raise", "9:0.05e-3"]
            r = subprocess.run([CLI, "setup", self.case, "--out", os.path.join(self.folder, name), "--frets", "7-10",
                                "--strength", "1e-3", "--fs", "400000", "--duration", "0.15", "--quiet",
                                *options, *raised], capture_output=True, text=True, timeout=600)
            self.assertEqual(r.returncode, 0, r.stderr)
            maps[name] = read_map(os.path.join(self.folder, name))
        for name in ("clamped", "fretted"):
            m = maps[name]
            self.assertEqual(m[8, 1e-3]["buzz_fret"], "9", name)
            loudest = max(range(7, 11), key=lambda k: float(m[k, 1e-3]["buzz_dB"] or "-inf"))
            self.assertEqual(loudest, 8, name)
            for k in (9, 10):
                self.assertEqual(m[k, 1e-3]["frets_touched"], "", (name, k))
        self.assertGreater(float(maps["fretted"][8, 1e-3]["buzz_dB"]),
                           float(maps["fretted-nominal"][8, 1e-3]["buzz_dB"] or "-inf") + 1.0)
        with open(os.path.join(self.folder, "fretted", "setup.json")) as f:
            self.assertIn("finger", f.read())

    def test_bad_options_are_refused_and_nothing_is_written(self):
        for options, frets, named in ((["--raise", "40:1e-4"], "6-10", "--raise"), ([], "0-25", "--frets"),
                                      (["--relief", "0.5"], "6-10", "--relief"),
                                      (["--compare", "nowhere"], "6-10", "--compare"),
                                      (["--finger", "--duration", "0.01"], "6-10", "--duration"),
                                      (["--finger"], "0-21", "--frets"),
                                      (["--raise", "9:-2e-3"], "6-10", "height_offsets.9")):
            r = self.setup("bad", *options, frets=frets)
            self.assertEqual(r.returncode, 2, r.stderr)
            self.assertIn(named, r.stderr)
            self.assertFalse(os.path.exists(os.path.join(self.folder, "bad")))
        r = subprocess.run([CLI, "setup", "bass-pop", "--out", os.path.join(self.folder, "bad")],
                           capture_output=True, text=True, timeout=120)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("fretboard", r.stderr)
        self.assertFalse(os.path.exists(os.path.join(self.folder, "bad")))


if __name__ == "__main__":
    unittest.main()
