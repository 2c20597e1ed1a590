#!/usr/bin/python3
"""Cases and results cross process boundaries (they pickle): the bass 'pop' at four contact
stiffnesses K, run in parallel with concurrent.futures, each for 10 ms at its own 4 MHz.
Prints the steps with contact and the largest contact energy for each K.

Run: PYTHONPATH=build/python/module /usr/bin/python3 examples/python/parallel_stiffness.py
"""
import concurrent.futures
import warnings

import fretbuzz

warnings.simplefilter("error", fretbuzz.FretbuzzWarning)  # the example runs without one


def pop(k):
    r = fretbuzz.run("bass-pop", K=k, duration=0.01)
    return k, r.summary["contact_steps"], float(r.contact_energy.max())


if __name__ == "__main__":
    with concurrent.futures.ProcessPoolExecutor(max_workers=2) as pool:
        rows = list(pool.map(pop, [1e10, 1e11, 1e12, 1e13]))
    for k, steps, held in rows:
        print(f"K = {k:.0e}: {steps} steps with contact, contact energy up to {held:.3e} J")
    assert all(steps > 0 for _, steps, _ in rows)
