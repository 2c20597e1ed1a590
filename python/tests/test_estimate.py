"""fretbuzz.estimate from Python: both polarisations of a doublet decay, and refusals."""
import math
import unittest

import numpy as np

import fretbuzz


def doublet_decay(separation=2e-3, seconds=3.0, rate=16000.0, modes=12):
    """Mode j at 110 j sqrt(1 + 1e-4 j^2) Hz, sigma 0.5 + 0.3 j, amplitude 0.5 / j; its second
    polarisation `separation` higher, 0.6 of the amplitude, 0.8 of the damping."""
    t = np.arange(int(rate * seconds)) / rate
    x = np.zeros_like(t)
    truth = {}
    for j in range(1, modes + 1):
        f, sigma = 110.0 * j * math.sqrt(1 + 1e-4 * j * j), 0.5 + 0.3 * j
        for k, (fk, sk, ak, phase) in ((1, (f, sigma, 0.5 / j, 0.0)), (2, (f * (1 + separation), 0.8 * sigma, 0.3 / j, j))):
            x += ak * np.exp(-sk * t) * np.cos(2 * np.pi * fk * t + phase)
            truth[(j, k)] = (fk, sk)
    return x, rate, truth


class EstimateTest(unittest.TestCase):
    def test_both_polarisations_and_the_y_table(self):
        x, rate, truth = doublet_decay()
        e = fretbuzz.estimate(x, rate, max_partial=12, string={"L": 0.65, "mu": 6e-3, "d": 1.1e-3}, modes=20)
        p = e["partials"]
        found = {(int(m), int(k)): (f, s) for m, k, f, s in
                 zip(p["mode"], p["polarisation"], p["frequency_hz"], p["sigma_per_s"])}
        for j in range(3, 13):
            for k in (1, 2):
                f, s = found[(j, k)]
                self.assertAlmostEqual(f / truth[(j, k)][0], 1.0, delta=1e-4, msg=f"mode {j}/{k}")
                self.assertAlmostEqual(s / truth[(j, k)][1], 1.0, delta=0.15, msg=f"mode {j}/{k}")
            # The z table holds the stronger partial, the y table the weaker.
            self.assertEqual(e["mode_table"]["frequency_hz"][j - 1], found[(j, 1)][0])
            self.assertEqual(e["mode_table_y"]["frequency_hz"][j - 1], found[(j, 2)][0])
        # Beyond the measured modes y is z.
        self.assertEqual(e["mode_table_y"]["frequency_hz"][19], e["mode_table"]["frequency_hz"][19])

    def test_a_steady_tone_is_refused(self):
        t = np.arange(32000) / 16000.0
        x = 0.5 * np.sin(2 * np.pi * 98.0 * t)
        x[:160] *= 1.2
        with self.assertRaisesRegex(ValueError, "not a free decay"):
            fretbuzz.estimate(x, 16000.0)


if __name__ == "__main__":
    unittest.main()
