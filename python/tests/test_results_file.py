"""results.h5 written by `fretbuzz run`: agrees with the CSV outputs and summary.json, its
contact map agrees with its per-point contact statistics, and the WAV files have the rate
and length asked for. Run by ctest with FRETBUZZ_CLI naming the built command."""
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


if __name__ == "__main__":
    unittest.main()
