#!/usr/bin/python3
"""Writes cases/bass-music-frets.toml: the Music example of the Siconos tutorials
(examples/mechanics/Music, its fretted bass 'bass_guitar/pb2') as a fretbuzz case.

    python3 scripts/music_reference_case.py [MUSIC_DIR]

The example's string, modes, neck and initial state are the data already shipped as
cases/data/bass_fretted_* (see cases/data/README.md). What this script adds is the example's
choice of contact points: not the whole neck profile but only its 20 fret tops, each one
grid point. The example finds them as the grid points where the profile jumps by more than
0.1 mm to both neighbours; the same rule is applied here to the shipped profile. Given
MUSIC_DIR (a checkout of that example), the script first checks that its pb2_h.mat and
pb2_q2.mat equal the shipped CSVs, so that the case is the example's data.
"""
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "cases" / "data"
CASE = ROOT / "cases" / "bass-music-frets.toml"
JUMP_M = 1e-4  # the example's threshold between a fret and the board's slope


def fret_tops(height):
    """Indices of the grid points standing out of the profile on both sides."""
    jumps = np.abs(np.diff(height)) > JUMP_M
    rise = np.concatenate(([False], jumps))  # a jump from the left neighbour
    fall = np.concatenate((jumps, [False]))  # a jump to the right neighbour
    above = np.concatenate(([False], height[1:] > height[:-1]))
    return np.flatnonzero(rise & fall & above)


def check_against(music_dir):
    from scipy.io import loadmat  # only needed for this check
    base = Path(music_dir) / "bass_guitar"
    h = loadmat(base / "pb2_h.mat")["h"][:, 0]
    q0 = loadmat(base / "pb2_q2.mat")["q2"][:, 0]
    shipped_h = np.loadtxt(DATA / "bass_fretted_obstacle.csv", delimiter=",")[:, 1]
    shipped_q0 = np.loadtxt(DATA / "bass_fretted_initial_modal.csv", delimiter=",")[:, 1]
    assert np.array_equal(h, shipped_h), "pb2_h.mat differs from bass_fretted_obstacle.csv"
    assert np.array_equal(q0, shipped_q0), "pb2_q2.mat differs from bass_fretted_initial_modal.csv"
    print(f"{base}: neck and initial state equal the shipped CSVs")


def main():
    if len(sys.argv) > 1:
        check_against(sys.argv[1])
    profile = np.loadtxt(DATA / "bass_fretted_obstacle.csv", delimiter=",")
    x, h = profile[:, 0], profile[:, 1]
    tops = fret_tops(h)
    assert len(tops) == 20, f"expected the 20 frets of the measured neck, found {len(tops)}"
    xs = ", ".join(f"{v:.3f}" for v in x[tops])
    hs = ", ".join(f"{v:.6g}" for v in h[tops])
    CASE.write_text(TEMPLATE.format(xs=xs, hs=hs))
    print(f"wrote {CASE.relative_to(ROOT)}: frets at x = {xs} m")


TEMPLATE = """\
# The Music example of the Siconos tutorials (examples/mechanics/Music, case 'bass_guitar/pb2',
# Apache-2.0): the fretted bass of C. Issanchou, V. Acary, F. Perignon, C. Touze,
# J.-L. Le Carrou, "Nonsmooth contact dynamics for the numerical simulation of collisions in
# musical string instruments", J. Acoust. Soc. Am. 143 (2018), run with Newton's impact law at
# the example's own rates. Written by scripts/music_reference_case.py: do not edit by hand.
# String (the example's donnees_siconos/autres_donnees.txt): L = 0.863 m, T = 191.6 N,
# mu = 6.7e-3 kg/m, 862 modes. Modes, neck and initial state: pb2_frequs.mat,
# pb2_amortissements.mat, pb2_h.mat, pb2_q2.mat, shipped as cases/data/bass_fretted_*.
# Unlike bass-rigid-frets (the whole neck profile), the contact points are the example's:
# the 20 fret tops alone, each one grid point, found by the example's rule (a jump of more
# than 0.1 mm to both neighbours).
name = "bass-music-frets"
description = "The Siconos Music example's fretted bass: its 20 frets as grid points, Newton's impact law, e = 0, Fe = 4.01 MHz"

[string]
L = 0.863        # m (autres_donnees.txt)
T = 191.6        # N
mu = 6.69e-3     # kg/m: autres_donnees.txt rounds it to 6.7e-3; the example's run.py gives 6.69e-3
modes = 862      # the example's nb_modes; dx = L / 863 = 1 mm

[modes]
table = "data/bass_fretted_modes.csv"   # pb2_frequs.mat, pb2_amortissements.mat

[obstacle]
# The 20 fret tops of pb2_h.mat (x on the grid, heights in m below the string at rest).
type = "points"
x = [{xs}]
height = [{hs}]

[excitation]
# pb2_q2.mat: the modal coordinates at t = 0 (a rounded triangle of 3.57 mm at 0.637 m),
# released at rest as the example does (its velocities are zero).
type = "modal"
file = "data/bass_fretted_initial_modal.csv"

[contact]
law = "impact"
restitution = 0  # the example runs e = 0, 0.5, 1 (its 2018 campaign 0, 0.9, 1)

[run]
# The example's rates are Fe = 1960 x 2^k Hz, its default 15680 (k = 3), where modes 74-862 lie
# above fs/2: run those with --fs 15680 --allow-aliasing (scripts/validate_music_reference.py).
# The case's own rate is the example's first above 2 nu_max = 2.37 MHz (k = 11).
fs = 4014080
duration = 0.4       # s: the example's 2018 campaign (make_runners.py)
output_rate = 15680  # one row per step of the lowest rate: every rate's rows fall on the same times

[observe]
x = [0.854, 0.501]   # the example's dofs 853 (the sensor, 9 mm from the bridge) and 500 (fret 15)

[audio]
rate = 48000
"""

if __name__ == "__main__":
    main()
