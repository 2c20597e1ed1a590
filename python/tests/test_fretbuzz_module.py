"""Tests of the fretbuzz Python module: physics through the bindings, and the case editing API.

Run by ctest with PYTHONPATH set to the built module (Debian's /usr/bin/python3 and numpy).
"""
import math
import unittest

import numpy as np

import fretbuzz

FS = 400000.0
DURATION = 0.01


def initial_shape_at(case, x):
    """u(x, 0) = sum_j q_j(0) sqrt(2/L) sin(j pi x / L), from the case's modal displacement."""
    j = np.arange(1, case.modes + 1)
    return float(np.sum(case.initial_displacement * math.sqrt(2.0 / case.L) * np.sin(j * math.pi * x / case.L)))


class RunResults(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.case = fretbuzz.load_case("bass-pop")
        cls.results = fretbuzz.run("bass-pop", fs=FS, duration=DURATION)

    def test_arrays_have_one_row_per_output_sample(self):
        r = self.results
        self.assertEqual(r.observation.shape, (len(r.time), len(r.points)))
        self.assertEqual(len(r.energy), len(r.time) - 1)  # energy lives at half steps, from (stride - 1/2) dt
        self.assertEqual(len(r.dissipated), len(r.energy))
        self.assertEqual(len(r.contact_energy), len(r.energy))
        self.assertAlmostEqual(r.time[0], 0.0)
        self.assertAlmostEqual(r.time[-1], DURATION, places=12)
        self.assertTrue(np.all(np.diff(r.time) > 0))

    def test_two_polarisations_record_y_and_its_energy_terms(self):
        two = fretbuzz.run("bass-pop-30", fs=FS, duration=DURATION)
        self.assertEqual(two.observation_y.shape, two.observation.shape)
        self.assertEqual(len(two.friction), len(two.energy))
        self.assertTrue(np.all(np.diff(two.friction) >= 0))  # friction only dissipates
        # energy includes y, dissipated includes its damping and the friction: their sum holds.
        balance = two.energy + two.dissipated - two.summary["energy_initial_J"]
        self.assertLess(np.max(np.abs(balance)) / two.summary["energy_initial_J"], 1e-10)
        self.assertEqual(self.results.observation_y.shape[0], 0)  # one polarisation: no y

    def test_energy_plus_dissipated_energy_is_constant(self):
        r = self.results
        initial = r.summary["energy_initial_J"]
        self.assertGreater(initial, 0.0)
        balance = np.abs(r.energy + r.dissipated - initial) / initial
        self.assertLess(balance.max(), 1e-10)
        self.assertTrue(np.all(np.diff(r.energy) <= 1e-12 * initial))  # H never increases
        self.assertGreater(r.dissipated[-1], 0.0)

    def test_observation_at_start_is_the_initial_shape(self):
        r = self.results
        expected = initial_shape_at(self.case, r.points[0])
        self.assertNotEqual(expected, 0.0)
        self.assertAlmostEqual(r.observation[0, 0] / expected, 1.0, delta=1e-12)

    def test_summary_is_a_dict_matching_the_arrays(self):
        s = self.results.summary
        self.assertEqual(s["case"], "bass-pop")
        self.assertEqual(s["fs"], FS)
        self.assertEqual(s["observation_points_m"], list(self.results.points))
        self.assertAlmostEqual(s["energy_final_J"], self.results.energy[-1], delta=1e-15)

    def test_arrays_are_read_only(self):
        with self.assertRaises(ValueError):
            self.results.observation[0, 0] = 1.0


class EditedCases(unittest.TestCase):
    def test_fields_read_and_write_as_items_and_attributes(self):
        c = fretbuzz.load_case("bass-pop")
        self.assertIn("fs", c.keys())
        self.assertEqual(c["fs"], c.fs)
        c["K"] = 2e12
        c.alpha = 1.3
        self.assertEqual(c.K, 2e12)
        self.assertEqual(c["alpha"], 1.3)
        c.update({"duration": 0.002, "observe": [0.854, 0.5]})
        self.assertEqual(c.to_dict()["observe"], [0.854, 0.5])
        with self.assertRaises(KeyError):
            c["no_such_field"]

    def test_run_uses_the_edited_case_and_leaves_it_unchanged(self):
        c = fretbuzz.load_case("bass-pop")
        c["observe"] = [0.854, 0.3]
        c.fs = FS
        c.duration = 0.002
        r = fretbuzz.run(c)
        self.assertEqual(r.observation.shape[1], 2)
        self.assertAlmostEqual(r.observation[0, 1] / initial_shape_at(c, 0.3), 1.0, delta=1e-12)
        fretbuzz.run(c, lossless=True, observe=[0.4])
        self.assertEqual(c.observe, [0.854, 0.3])
        self.assertGreater(c.sigma.max(), 0.0)

    def test_lossless_run_conserves_energy(self):
        r = fretbuzz.run("bass-pop", fs=FS, duration=0.005, lossless=True)
        initial = r.summary["energy_initial_J"]
        self.assertTrue(r.summary["lossless"])
        self.assertLess(np.abs(r.energy - initial).max() / initial, 1e-10)
        self.assertLess(np.abs(r.dissipated).max() / initial, 1e-12)  # nothing but round-off

    def test_snapshots_start_from_the_initial_shape(self):
        c = fretbuzz.load_case("bass-pop")
        r = fretbuzz.run(c, fs=FS, duration=0.002, snapshots=5000)
        self.assertEqual(r.snapshots.shape, (len(r.snapshot_time), c.modes))
        self.assertEqual(len(r.snapshot_time), 11)
        i = c.modes // 3
        self.assertAlmostEqual(r.snapshots[0, i] / initial_shape_at(c, r.grid_x[i]), 1.0, delta=1e-10)

    def test_bad_input_names_the_parameter(self):
        with self.assertRaisesRegex(ValueError, "no-such-case"):
            fretbuzz.run("no-such-case")
        with self.assertRaisesRegex(ValueError, "fs"):
            fretbuzz.run("bass-pop", fs=-1.0)
        with self.assertRaisesRegex(ValueError, "observation point"):
            fretbuzz.run("bass-pop", fs=FS, duration=0.001, observe=[2.0])


if __name__ == "__main__":
    unittest.main()
