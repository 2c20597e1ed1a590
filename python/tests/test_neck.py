"""The set-up bench from Python (fretbuzz.Bench, fretbuzz.setup): the geometry comes from the
library (the bass-neck instrument's fret tops are the bass-neck case's); the map is a
DataFrame filled in note by note through the progress callback or the notes() iterator, and
an exception raised in the callback stops it and propagates; one note gives its audio at
48 kHz, its pickup signal and its contacts over time, the same pluck as the map's; what-ifs
are new Bench values; bad values raise fretbuzz.InputError naming the argument; the command
line's buzz_map.csv holds the same map; the HTML page is drawn from map.json."""
import csv
import math
import os
import pathlib
import shutil
import subprocess
import tempfile
import unittest

import numpy as np

import fretbuzz

CLI = os.environ.get("FRETBUZZ_CLI")
QUICK = dict(ensemble=2, fs=3e5, duration=0.05)


def quick_bench(**kwargs):
    return fretbuzz.Bench("jazz-bass", **{**QUICK, **kwargs})


class GeometryTest(unittest.TestCase):
    def test_the_single_string_built_in_has_the_bass_neck_cases_fret_tops(self):
        case = fretbuzz.load_case("bass-neck")
        g = fretbuzz.Bench("bass-neck").geometry()
        table = fretbuzz.Bench("bass-neck").strings_table().iloc[0]
        x = case.grid_x
        dx = x[1] - x[0]
        crowns = case.point_obstacles  # (x, height, width): the frets' crowns at their exact positions
        for _, row in g[g["fret"] > 0].iterrows():
            top = max(h for at, h, _ in crowns if abs(at - row["x_m"]) <= dx)
            string_at = (table["nut_height_m"] + (table["saddle_height_m"] - table["nut_height_m"]) * row["x_m"] /
                         table["scale_length_m"])
            self.assertAlmostEqual(row["top_m"] - string_at, top, delta=1e-15)

    def test_what_a_luthier_measures(self):
        table = quick_bench().strings_table().set_index("name")
        self.assertAlmostEqual(table.loc["E", "nut_gap_m"], 0.75e-3, delta=1e-15)
        self.assertAlmostEqual(table.loc["E", "action12_m"], 2.7e-3, delta=1e-15)
        looser = quick_bench().with_changes(relief=0.8).strings_table().set_index("name")
        self.assertAlmostEqual(looser.loc["E", "relief_gap_m"], 0.8e-3, delta=1e-12)
        self.assertAlmostEqual(looser.loc["E", "saddle_height_m"], table.loc["E", "saddle_height_m"], delta=1e-15)
        view = quick_bench().side_view("G")
        self.assertEqual(len(view["frets"]), 21)
        self.assertGreater(len(view["surface"]), 100)

    def test_the_action_at_any_fret_and_moves_from_where_the_neck_is(self):
        bench = quick_bench()
        table = bench.strings_table().set_index("name")
        at17 = bench.with_changes(action={17: {"E": "3/32 in"}})
        gaps = at17.geometry()
        e17 = gaps[(gaps["string"] == "E") & (gaps["fret"] == 17)].iloc[0]
        self.assertAlmostEqual(e17["gap_m"], 3 / 32 * 0.0254, delta=1e-9)
        self.assertEqual(at17.changes, {"action": {17: {"E": "3/32 in"}}})
        moved = bench.with_changes(saddle_change={"E": "-0.25 mm"}, relief_change="+2 thou",
                                   nut_change={"G": -0.05}).strings_table().set_index("name")
        self.assertAlmostEqual(moved.loc["E", "saddle_height_m"], table.loc["E", "saddle_height_m"] - 0.25e-3, delta=1e-15)
        self.assertAlmostEqual(moved.loc["E", "relief_gap_m"], table.loc["E", "relief_gap_m"] + 2e-3 * 0.0254, delta=1e-12)
        self.assertAlmostEqual(moved.loc["G", "nut_height_m"], table.loc["G", "nut_height_m"] - 0.05e-3, delta=1e-15)
        for call, says in ((lambda: bench.with_changes(action={25: {"E": 2}}), "action 25:E"),
                           (lambda: bench.with_changes(action={17: 2}), "action[17]"),
                           (lambda: bench.with_changes(saddle_change={"E": 9}), "saddle_change E"),
                           (lambda: bench.with_changes(relief=0.3, relief_change=0.1), "relief_change")):
            with self.assertRaises(fretbuzz.InputError) as caught:
                call()
            self.assertIn(says, str(caught.exception))

    def test_turns_move_by_what_the_file_says_a_turn_does(self):
        text = quick_bench().instrument.source_text + '\n[adjusters]\ntruss_rod_turn = "0.2 mm"\nsaddle_screw_pitch = "0.5 mm"\n'
        with tempfile.TemporaryDirectory() as folder:
            path = pathlib.Path(folder) / "adjustable.toml"
            path.write_text(text)
            bench = fretbuzz.Bench(str(path), **QUICK)
        table = bench.strings_table().set_index("name")
        turned = bench.with_changes(truss_rod_turns="1/4", saddle_turns={"E": -1.5}).strings_table().set_index("name")
        self.assertAlmostEqual(turned.loc["E", "relief_gap_m"], table.loc["E", "relief_gap_m"] - 0.05e-3, delta=1e-12)
        self.assertAlmostEqual(turned.loc["E", "saddle_height_m"], table.loc["E", "saddle_height_m"] - 0.75e-3, delta=1e-12)
        self.assertEqual(bench.with_changes(truss_rod_turns="1/4").changes, {"truss_rod_turns": "1/4"})
        for call, says in ((lambda: quick_bench().with_changes(truss_rod_turns=0.25), "truss_rod_turns needs adjusters"),
                           (lambda: bench.with_changes(truss_rod_turns="3"), "truss_rod_turns 3: turns must be"),
                           (lambda: bench.with_changes(saddle_turns={"E": 30}), "saddle_turns E")):
            with self.assertRaises(fretbuzz.InputError) as caught:
                call()
            self.assertIn(says, str(caught.exception))


class MapTest(unittest.TestCase):
    def test_the_map_fills_in_note_by_note(self):
        seen = []
        table = quick_bench().map(strings="G", frets=[18, 19, 20], strengths="soft,hard",
                                  progress=lambda note, done, total: seen.append((note["fret"], done, total)))
        self.assertEqual(list(table.columns[:5]), ["string", "fret", "strength", "verdict", "buzz_fraction"])
        self.assertEqual(len(table), 6)
        self.assertEqual([d for _, d, _ in seen], list(range(1, 7)))
        self.assertEqual({t for _, _, t in seen}, {6})
        last = table[table["fret"] == 20]
        self.assertTrue((last["touch_fraction"] == 0).all())  # nothing past the last fret
        notes = list(quick_bench().notes(strings="G", frets=[19, 20], strengths="hard"))
        self.assertEqual(sorted(n["fret"] for n in notes), [19, 20])

    def test_an_exception_in_the_progress_callback_stops_the_map_and_propagates(self):
        calls = []

        def fail(note, done, total):
            calls.append(done)
            raise RuntimeError("stop here")
        with self.assertRaisesRegex(RuntimeError, "stop here"):
            quick_bench().map(strings="E", progress=fail)
        self.assertEqual(len(calls), 1)

    def test_a_note_is_the_maps_pluck_with_its_audio_and_contacts(self):
        bench = quick_bench()
        row = bench.map(strings="G", frets=[19], strengths="hard").iloc[0]
        note = bench.note("G", 19, "hard")
        self.assertEqual(note["audio_rate_hz"], 48000.0)
        self.assertAlmostEqual(len(note["audio"]) / 48000.0, QUICK["duration"], delta=0.002)
        self.assertTrue(note["touched"])
        # The note's run also writes its 48 kHz sound, so the listener's 96 kHz audio is resampled
        # step by step there and in closed form over free stretches in the map's run: equal to the
        # resampler's precision, a few thousandths of a dB on the level.
        self.assertAlmostEqual(note["buzz_dB"], row["pluck_dB"][0], delta=0.01)
        self.assertEqual(list(note["contacts"].columns), ["time_s", "impulse_n_s", "peak_force_n", "fret"])
        self.assertGreater(len(note["contacts"]), 0)
        self.assertEqual(note["buzz_fret"], row["buzz_fret"])

    def test_bad_values_raise_input_error_naming_the_argument(self):
        bench = quick_bench()
        for call, says in ((lambda: bench.with_changes(relief=5), "relief"),
                           (lambda: bench.with_changes(action12={"Q": 2}), "Q"),
                           (lambda: bench.with_changes(fret_offsets={30: 0.1}), "fret_offsets 30"),
                           (lambda: bench.map(frets=[25]), "frets"),
                           (lambda: bench.map(strengths="-1e-3"), "strengths"),
                           (lambda: fretbuzz.Bench("jazz-bass", ensemble=0), "ensemble"),
                           (lambda: fretbuzz.Bench("jazz-bass", listen="amp"), "listen"),
                           (lambda: fretbuzz.Bench("jazz-bass", partial_scatter=60), "partial_scatter"),
                           (lambda: fretbuzz.Bench("banjo"), "jazz-bass"),
                           (lambda: bench.note("G", 3, "hard", member=9), "member")):
            with self.assertRaises(fretbuzz.InputError) as caught:
                call()
            self.assertIn(says, str(caught.exception))

    def test_the_rig_hears_a_touch_less_than_the_pickups_full_range(self):
        # The rig (the pickup's circuit and a cabinet falling above 4 kHz) weighs a touch's click,
        # which spreads far above the note, down: the same pluck reads lower through it.
        rig, pickup = quick_bench(), quick_bench(listen="pickup")
        self.assertEqual((rig.settings["listen"], pickup.settings["listen"]), ("rig", "pickup"))
        through, full = rig.note("G", 19, "hard"), pickup.note("G", 19, "hard")
        self.assertTrue(through["touched"] and full["touched"])
        self.assertLess(through["buzz_dB"], full["buzz_dB"] - 1.0)
        self.assertEqual(quick_bench(partial_scatter=1.5).settings["partial_scatter_cents"], 1.5)

    def test_what_ifs_compare_and_advice(self):
        bench = quick_bench()
        before = bench.map(strings="G", frets=range(4, 8), strengths="medium")
        after = bench.with_changes(fret_offsets={7: 0.3}).map(strings="G", frets=range(4, 8), strengths="medium")
        changes = fretbuzz.Bench.compare(after, before).set_index("fret")
        self.assertEqual(changes.loc[6, "change"], "worse")
        self.assertIn(changes.loc[6, "reason"], ("verdict", "plucks", "margin", "loudness"))  # the rule that decided it
        told = []
        advice = fretbuzz.Bench("jazz-bass", ensemble=1, fs=3e5, duration=0.05).advise(
            strength="soft", strings="G", progress=lambda note, probes: told.append((note, probes)))
        # Told of each note a probe played: every probe plays one at least, in order, all on G.
        self.assertEqual(sorted({probes for _, probes in told}), list(range(1, advice["maps_played"] + 1)))
        self.assertEqual([p for _, p in told], sorted(p for _, p in told))
        self.assertEqual({note["string"] for note, _ in told}, {"G"})
        self.assertEqual(set(advice), {"attack", "units", "frets", "tolerated", "step_mm", "setup_limits",
                                       "lowest_action", "fall_away", "proud_frets", "relief", "maps_played",
                                       "wall_seconds", "cpu_seconds"})
        # Said nothing: as set-ups do, marginal notes pass and a bass's notes above fret 15 are not asked.
        self.assertEqual(advice["frets"], "0-15")
        self.assertIn("as set-ups do", advice["tolerated"])
        self.assertEqual(advice["setup_limits"], {"saddle_move_mm": 1.0, "relief_max_mm": 0.5})
        self.assertIn("beyond_setup", advice["lowest_action"][0])
        self.assertEqual(advice["lowest_action"][0]["string"], "G")
        self.assertEqual(advice["units"], "mm")  # the jazz bass's file gives its gaps in mm
        # The advice answers for the frets asked, and says what it tolerates.
        low = fretbuzz.Bench("jazz-bass", ensemble=1, fs=3e5, duration=0.05).advise(
            strength="soft", strings="G", frets=range(0, 13), tolerate="marginal")
        self.assertEqual((low["frets"], low["tolerated"]), ("0-12", "marginal notes"))
        self.assertLessEqual(low["lowest_action"][0]["limiting_fret"], 12)
        with self.assertRaises(fretbuzz.InputError) as caught:
            quick_bench().advise(strength="soft", tolerate="above=99")
        self.assertIn("tolerate above=99", str(caught.exception))
        # A map whose notes buzz (its buzz_fret column holds whole numbers and None) is read back.
        quick = fretbuzz.Bench("jazz-bass", ensemble=1, fs=3e5, duration=0.05)
        hard = quick.map(strings="G", strengths="hard")
        self.assertTrue(any(isinstance(f, int) for f in hard["buzz_fret"]))
        proud = quick.advise(hard, strength="hard", strings="G")["proud_frets"]
        self.assertTrue(all(p["worse"] == [] for p in proud))


@unittest.skipUnless(CLI, "FRETBUZZ_CLI (the fretbuzz program) is not set")
class CommandTest(unittest.TestCase):
    def setUp(self):
        self.folder = tempfile.mkdtemp(prefix="fretbuzz-bench-test-")

    def tearDown(self):
        shutil.rmtree(self.folder, ignore_errors=True)

    def test_the_command_writes_the_pythons_map_and_draws_it(self):
        out = os.path.join(self.folder, "map")
        subprocess.run([CLI, "setup", "jazz-bass", "--out", out, "--strings", "G", "--frets", "17-20", "--strength",
                        "hard", "--ensemble", "2", "--fs", "300kHz", "--duration", "0.05", "--quiet"], check=True)
        with open(os.path.join(out, "buzz_map.csv"), newline="") as f:
            rows = list(csv.DictReader(f))
        # The same plucks: with their WAVs too (writing audio moves free flight's steps, and so
        # the last bits of a buzzing pluck's level).
        table = quick_bench().map(strings="G", frets=range(17, 21), strengths="hard",
                                  audio_dir=os.path.join(self.folder, "wavs"))
        self.assertEqual(len(rows), len(table))
        for r, (_, t) in zip(rows, table.iterrows()):
            self.assertEqual(float(r["buzz_fraction"]), t["buzz_fraction"])
            if r["buzz_dB"]:
                self.assertEqual(float(r["buzz_dB"]), t["buzz_dB"])
            else:
                self.assertTrue(t["buzz_dB"] is None or math.isnan(t["buzz_dB"]))
        with open(os.path.join(out, "buzz_map.html"), encoding="utf-8") as f:
            page = f.read()
        self.assertIn("Buzz map: jazz-bass", page)
        self.assertIn('data-audio="note-G-19-hard.wav"', page)
        self.assertIn("heights &times;", page)  # the side view says it exaggerates heights
        # The page can be drawn again from map.json alone.
        os.remove(os.path.join(out, "buzz_map.html"))
        from fretbuzz import setup_report
        self.assertEqual(setup_report.main([out]), 0)
        self.assertTrue(os.path.exists(os.path.join(out, "buzz_map.html")))


class CalibrationTest(unittest.TestCase):
    def test_a_players_report_calibrates_the_attack_and_bad_rows_are_refused(self):
        bench = quick_bench()
        notes = []
        out = bench.calibrate("string,fret,heard\nG,19,buzz\nG,5,clean\n",
                              progress=lambda note, done, total: notes.append((done, total)))
        self.assertEqual(len(out["notes"]), 2)
        self.assertEqual(notes[-1], (2, 2))
        self.assertTrue(out["attack_scale"] is None or 0.0 < out["attack_scale"] <= 3.0)
        for note in out["notes"]:
            self.assertIn("clean_up_to", note)
            self.assertIn(note["heard"], ("buzz", "clean"))
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "report.csv")
            with open(path, "w", encoding="utf-8") as f:
                f.write("string,fret,heard\nG,5,sometimes\n")
            with self.assertRaises(fretbuzz.InputError) as e:
                bench.calibrate(pathlib.Path(path))
            self.assertIn("column heard", str(e.exception))
            self.assertIn("report.csv", str(e.exception))

    def test_the_players_touch_is_read_and_checked_as_player_reads_it(self):
        bench = quick_bench()
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "calibration.json")
            with open(path, "w", encoding="utf-8") as f:
                f.write('{"attack_scale": 1.37}')
            touch = bench.with_player(pathlib.Path(path))
            self.assertEqual(touch.attack_scale, 1.37)
            self.assertIsNone(bench.attack_scale)  # a Bench is a value
            self.assertEqual(bench.with_player({"attack_scale": 0.5}).attack_scale, 0.5)
            self.assertIsNone(touch.with_player(None).attack_scale)
            for bad, says in ((os.path.join(d, "absent.json"), "no such file"), (d, "not a regular file"),
                              (12.5, "(0, 10]"), ({"attack_scale": 0.0}, "(0, 10]"),
                              ({"attack_scale": None, "statement": "none fits"}, "none fits")):
                with self.assertRaises(fretbuzz.InputError, msg=str(bad)) as e:
                    bench.with_player(bad)
                self.assertIn(says, str(e.exception))


if __name__ == "__main__":
    unittest.main()
