"""results.h5 written by `fretbuzz run`: agrees with the CSV outputs and summary.json, its
contact map agrees with its per-point contact statistics, and the WAV files have the rate
and length asked for. Run by ctest with FRETBUZZ_CLI naming the built command."""
import hashlib
import json
import math
import os
import subprocess
import tempfile
import unittest
import wave

import h5py
import numpy as np

from fretbuzz.plots import contact_map_times, reduced_contact_map

FS = 400000
DURATION = 0.02
SNAPSHOT_RATE = 5000
AUDIO_RATE = 96000


class ResultsFile(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.temp = tempfile.TemporaryDirectory(prefix="fretbuzz-results-test-")
        cls.dir = cls.temp.name
        subprocess.run([os.environ["FRETBUZZ_CLI"], "run", "bass-pop", "--fs", str(FS), "--duration", str(DURATION),
                        "--observe", "0.3", "--snapshots", str(SNAPSHOT_RATE), "--audio-rate", str(AUDIO_RATE),
                        "--velocity-audio", "--dense-contact-map", "-q", "--out", cls.dir], check=True)
        cls.h5 = h5py.File(os.path.join(cls.dir, "results.h5"), "r")

    @classmethod
    def tearDownClass(cls):
        cls.h5.close()
        cls.temp.cleanup()

    def csv(self, name):
        return np.loadtxt(os.path.join(self.dir, name), delimiter=",", skiprows=1)

    def test_signals_match_the_csv_files_exactly(self):
        observation = self.csv("observation.csv")
        np.testing.assert_array_equal(self.h5["time"][()], observation[:, 0])
        np.testing.assert_array_equal(self.h5["observation/displacement"][()], observation[:, 1:])
        np.testing.assert_array_equal(self.h5["observation/points_m"][()], [0.854, 0.3])
        energy = self.csv("energy.csv")
        for column, name in enumerate(["time", "total", "contact", "dissipated"]):
            np.testing.assert_array_equal(self.h5["energy/" + name][()], energy[:, column])

    def test_case_text_and_summary_are_stored(self):
        self.assertIn('name = "bass-pop"', self.h5["case/text"][()].decode())
        with open(os.path.join(self.dir, "summary.json")) as f:
            self.assertEqual(json.loads(self.h5["summary"][()]), json.load(f))
        self.assertEqual(self.h5.attrs["steps"], round(FS * DURATION))
        self.assertEqual(self.h5.attrs["format"], "fretbuzz results")

    def test_sparse_contact_map_reads_back_to_the_dense_map_exactly(self):
        dense = self.h5["contact/max_force_dense"][()]
        time, rebuilt = reduced_contact_map(self.h5, np)
        self.assertEqual(rebuilt.dtype, dense.dtype)
        np.testing.assert_array_equal(rebuilt, dense)
        self.assertGreater(np.count_nonzero(dense), 0)
        # Only entries with a force are stored, each once.
        self.assertEqual(len(self.h5["contact/max_force"]), np.count_nonzero(dense))
        self.assertTrue(np.all(self.h5["contact/max_force"][()] > 0))
        self.assertEqual(len(time), dense.shape[0])
        # Folding rows by their maximum agrees with folding the dense map.
        folded_time, folded = reduced_contact_map(self.h5, np, 7)
        group = math.ceil(dense.shape[0] / 7)
        for k in range(folded.shape[0]):
            np.testing.assert_array_equal(folded[k], dense[k * group:(k + 1) * group].max(axis=0))
            self.assertEqual(folded_time[k], time[min((k + 1) * group, len(time)) - 1])

    def test_contact_map_agrees_with_the_per_point_statistics(self):
        time, force = reduced_contact_map(self.h5, np)
        steps = self.h5["contact/steps"][()]
        first, last = self.h5["contact/first_s"][()], self.h5["contact/last_s"][()]
        interval = int(self.h5["contact"].attrs["interval_steps"])
        self.assertEqual(force.shape, (math.ceil(round(FS * DURATION) / interval), len(self.h5["grid/x_m"])))
        np.testing.assert_allclose(time, np.arange(1, force.shape[0] + 1) * interval / FS, rtol=1e-12)
        np.testing.assert_array_equal(time, contact_map_times(self.h5, np))
        touched = steps > 0
        self.assertTrue(touched.any(), "bass-pop slaps on its frets")
        np.testing.assert_array_equal(touched, force.max(axis=0) > 0)
        np.testing.assert_array_equal(touched, np.isfinite(first))
        self.assertTrue(np.all(first[touched] <= last[touched]))
        np.testing.assert_allclose(force.max(axis=0), self.h5["contact/peak_force"][()], rtol=1e-7)  # stored as float32
        # The first contact of each point falls in the first row where its column is non-zero.
        for i in np.flatnonzero(touched)[:10]:
            row = np.flatnonzero(force[:, i])[0]
            self.assertEqual(row, (round(first[i] * FS) - 1) // interval)
        summary = json.loads(self.h5["summary"][()])
        self.assertAlmostEqual(np.nanmin(first), summary["first_contact_s"], delta=0.5 / FS)
        self.assertAlmostEqual(np.nanmax(last), summary["last_contact_s"], delta=0.5 / FS)

    def test_snapshots_at_the_requested_rate(self):
        times = self.h5["snapshots/time"][()]
        shapes = self.h5["snapshots/displacement"][()]
        self.assertEqual(len(times), round(DURATION * SNAPSHOT_RATE) + 1)
        np.testing.assert_allclose(np.diff(times), 1.0 / SNAPSHOT_RATE, rtol=1e-9)
        self.assertEqual(shapes.shape, (len(times), len(self.h5["grid/x_m"])))
        obstacle = self.h5["grid/obstacle_height_m"][()]
        self.assertTrue(np.all(shapes[0] >= obstacle - 1e-12))  # the release shape clears the neck

    def test_audio_files_have_the_requested_rate_and_length(self):
        for name in ["audio.wav", "audio_0.3m.wav", "velocity.wav", "velocity_0.3m.wav"]:
            with wave.open(os.path.join(self.dir, name)) as w:
                self.assertEqual(w.getframerate(), AUDIO_RATE, name)
                self.assertEqual(w.getnchannels(), 1, name)
                self.assertEqual(w.getsampwidth(), 3, name)
                # fs * duration + 1 samples in, resampled: the output has one sample more or less.
                self.assertLessEqual(abs(w.getnframes() - round(DURATION * AUDIO_RATE)), 1, name)

    def test_every_dataset_has_units(self):
        missing = []
        self.h5.visititems(lambda name, obj: missing.append(name)
                           if isinstance(obj, h5py.Dataset) and "units" not in obj.attrs else None)
        self.assertEqual(missing, [], "datasets without a units attribute")
        self.assertEqual(self.h5["observation/displacement"].attrs["units"], "m")
        self.assertEqual(self.h5["energy/total"].attrs["units"], "J")
        self.assertEqual(self.h5["modes/frequency_hz"].attrs["units"], "Hz")

    def test_provenance_names_version_command_case_hash_and_modes(self):
        case_text = self.h5["case/text"][()].decode()
        digest = hashlib.sha256(case_text.encode()).hexdigest()
        attrs = self.h5.attrs
        self.assertEqual(attrs["case_sha256"], digest)
        self.assertRegex(attrs["fretbuzz_version"], r"^\d+\.\d+\.\d+")
        self.assertRegex(attrs["created_utc"], r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ$")
        self.assertIn("run bass-pop", attrs["command_line"])
        self.assertIn(self.dir, attrs["command_line"])
        self.assertTrue(attrs["platform"])
        with open(os.path.join(self.dir, "summary.json")) as f:
            provenance = json.load(f)["provenance"]
        self.assertEqual(provenance["case_sha256"], digest)
        self.assertEqual(provenance["case_text"], case_text)
        self.assertEqual(provenance["command_line"], attrs["command_line"])
        # The mode table is the one `fretbuzz modes` prints (17 significant digits), in both files.
        listing = subprocess.run([os.environ["FRETBUZZ_CLI"], "modes", "bass-pop"], check=True, text=True,
                                 capture_output=True).stdout.splitlines()[1:]
        frequencies = [float(line.split(",")[1]) for line in listing]
        np.testing.assert_array_equal(self.h5["modes/frequency_hz"][()], frequencies)
        np.testing.assert_array_equal(provenance["mode_table"]["frequency_hz"], frequencies)
        np.testing.assert_array_equal(self.h5["modes/mode"][()], np.arange(1, len(frequencies) + 1))
        self.assertEqual([s.decode() for s in self.h5["modes/source"][()]], [line.split(",")[3] for line in listing])

    def test_audio_starts_silent_and_records_its_full_scale(self):
        with open(os.path.join(self.dir, "summary.json")) as f:
            audio = {a["file"]: a for a in json.load(f)["audio"]}
        self.assertEqual(sorted(audio), ["audio.wav", "audio_0.3m.wav", "velocity.wav", "velocity_0.3m.wav"])
        for name, entry in audio.items():
            with wave.open(os.path.join(self.dir, name)) as w:
                raw = np.frombuffer(w.readframes(w.getnframes()), dtype=np.uint8).reshape(-1, 3)
            samples = (raw[:, 0].astype(np.int32) | raw[:, 1].astype(np.int32) << 8 | raw[:, 2].astype(np.int32) << 16)
            samples = np.where(samples >= 1 << 23, samples - (1 << 24), samples) / float(1 << 23)
            self.assertEqual(samples[0], 0.0, name)  # faded in: no click
            self.assertAlmostEqual(np.abs(samples).max(), 0.99, delta=1e-6)
            self.assertEqual(entry["full_scale_unit"], "m/s" if name.startswith("velocity") else "m")
            self.assertEqual(entry["fade_in_s"], 0.005)
        # Full scale times the loudest sample is the loudest displacement in the file: at least
        # the loudest after the fade-in, at most the loudest overall (to the resampler's band
        # limit and the pickup's high-pass, which turns the phase of the lowest partials by a
        # few degrees: a few per cent).
        observation = self.csv("observation.csv")
        loudest = audio["audio.wav"]["full_scale"] * 0.99
        self.assertGreater(loudest, 0.93 * np.abs(observation[observation[:, 0] >= 0.005, 1]).max())
        self.assertLess(loudest, 1.03 * np.abs(observation[:, 1]).max())

    def test_plots_in_vector_formats_with_chosen_windows_and_range(self):
        from fretbuzz.plots import colour_ticks, plot_directory
        written = plot_directory(self.dir, formats=("pdf", "svg"), zoom=[(0.001, 0.004), (0.01, 0.012)], db_range=80)
        for name in ("signal", "spectrogram", "energy", "contactogram"):
            for form in ("pdf", "svg"):
                self.assertIn(os.path.join(self.dir, f"{name}.{form}"), written)
                self.assertGreater(os.path.getsize(os.path.join(self.dir, f"{name}.{form}")), 1000)
        # The contactogram's scale: labelled ticks over its three decades, not one.
        ticks = colour_ticks(2.3e3, 2.3e6, np)
        self.assertEqual(ticks[:3], [5e3, 1e4, 2e4])
        self.assertEqual(len(ticks), 9)
        self.assertEqual(colour_ticks(3.0, 4.0, np), [3.0, 4.0])


class PlayedResults(unittest.TestCase):
    """A plucked string (guitar-pluck: a plectrum pulls the string up at 0.2 m/s until it
    slips off at 2 N): results.h5 carries the energy terms of energy.csv, the plucker's pad
    and path, summary.json counts its contact apart from the obstacle's, and the figures
    draw it."""

    @classmethod
    def setUpClass(cls):
        cls.temp = tempfile.TemporaryDirectory(prefix="fretbuzz-played-test-")
        cls.dir = cls.temp.name
        subprocess.run([os.environ["FRETBUZZ_CLI"], "run", "guitar-pluck", "--duration", "0.012",
                        "--snapshots", "2000", "-q", "--out", cls.dir], check=True)
        cls.h5 = h5py.File(os.path.join(cls.dir, "results.h5"), "r")

    @classmethod
    def tearDownClass(cls):
        cls.h5.close()
        cls.temp.cleanup()

    def test_finger_energy_columns_match_energy_csv_exactly(self):
        energy = np.loadtxt(os.path.join(self.dir, "energy.csv"), delimiter=",", skiprows=1)
        for column, name in enumerate(["finger", "work", "finger_loss"]):
            np.testing.assert_array_equal(self.h5["energy/" + name][()], energy[:, 4 + column])
        self.assertEqual(self.h5["energy/work"].attrs["units"], "J")

    def test_the_plucker_follows_its_path_and_leaves(self):
        self.assertEqual([k.decode() for k in self.h5["played/kind"][()]], ["pluck"])
        np.testing.assert_array_equal(self.h5["played/position_m"][()], [0.85])
        height = self.h5["played/height"][()][:, 0]
        time = self.h5["energy/time"][()]
        self.assertEqual(len(height), len(time))
        dt = float(self.h5.attrs["dt_s"])
        there = np.isfinite(height)
        self.assertTrue(there[0] and not there[-1])  # there from the start, gone by the end
        # Pulling: from the string at rest (u = 0) at step 1, 0.2 m/s, up to its peak.
        peak = int(np.argmax(np.where(there, height, -np.inf)))
        steps = np.round(time[:peak + 1] / dt + 0.5)
        np.testing.assert_allclose(height[:peak + 1], 0.2 * (steps - 1) * dt, rtol=0, atol=1e-12)
        # It let go at 2 N, about 1.4 mm up (F x (L - x) / (T L) at 0.85 m on the 1.002 m string).
        self.assertAlmostEqual(height[peak] * 1e3, 2.0 * 0.85 * (1.002 - 0.85) / (180.5 * 1.002) * 1e3, delta=0.15)

    def test_summary_counts_the_plucker_apart_from_the_obstacle(self):
        with open(os.path.join(self.dir, "summary.json")) as f:
            summary = json.load(f)
        dt = float(self.h5.attrs["dt_s"])
        pulled = np.sum(np.isfinite(self.h5["played/height"][()][:, 0])) * float(self.h5.attrs["output_stride"])
        # The plucker touches for its whole pull (within one output row either way).
        self.assertAlmostEqual(summary["finger_contact_steps"], pulled, delta=float(self.h5.attrs["output_stride"]))
        self.assertLess(summary["contact_steps"], summary["steps"])
        self.assertGreater(summary["first_contact_s"], dt)  # the obstacle's first touch, not the plucker's
        self.assertGreater(summary["free_flight_fraction"], 0.0)  # once the plucker has left, the run flies

    def test_figures_draw_the_plucker(self):
        from fretbuzz.plots import plot_directory
        written = plot_directory(self.dir, animation="gif")
        names = {os.path.basename(p) for p in written}
        self.assertTrue({"contactogram.png", "snapshots.png", "animation.gif", "energy.png"} <= names)


if __name__ == "__main__":
    unittest.main()
