#!/usr/bin/python3
"""A case from TOML text, run from Python with the files of `fretbuzz run --out`: an ideal
string plucked against a flat barrier above it (side = "above"). Prints the summary's
provenance (version, case hash) and what full scale means in audio.wav, and checks that the
barrier above only ever pushes the string down.

Run: PYTHONPATH=build/python/module /usr/bin/python3 examples/python/pluck_and_listen.py
(or with fretbuzz installed by pip).
"""
import json
import os
import tempfile

import warnings

import numpy as np

import fretbuzz

warnings.simplefilter("error", fretbuzz.FretbuzzWarning)  # the example runs without one

CASE = """name = "barrier-above"
[string]
L = 0.65
T = 80.0
mu = 1e-3
modes = 200
ideal = true
[modes.damping]
model = "law"
eta0 = 0.8
eta2 = 2e-4
[obstacle]
type = "flat"
side = "above"
height = 5e-4
[excitation]
type = "triangle"
position = 0.15
amplitude = -1e-3
[contact]
K = 1e11
alpha = 1.5
[run]
fs = 96000
duration = 0.2
output_rate = 48000
[observe]
x = [0.5]
"""

case = fretbuzz.Case.from_toml(CASE)
with tempfile.TemporaryDirectory() as tmp:
    out = os.path.join(tmp, "run")
    r = fretbuzz.run(case, out=out)
    summary = json.load(open(os.path.join(out, "summary.json")))
    p = summary["provenance"]
    print(f"fretbuzz {p['fretbuzz_version']}, case {p['case_name']} sha256 {p['case_sha256'][:12]}...")
    audio = summary["audio"][0]
    print(f"{audio['file']}: full scale = {audio['full_scale']:.3e} {audio['full_scale_unit']}")
    print(f"{summary['contact_steps']} steps with contact; highest point reached "
          f"{1e3 * r.observation.max():.3f} mm (barrier at 0.5 mm)")
    # The string starts below the barrier and is pushed down: it never goes far above it.
    assert summary["contact_steps"] > 0
    assert r.observation.max() < 5e-4 + 1e-4
    # Full scale is about the loudest displacement at the point (the WAV is resampled and faded in).
    assert 0.5 < audio["full_scale"] / np.abs(r.observation[:, 0]).max() < 1.5
