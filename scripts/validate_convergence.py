#!/usr/bin/python3
"""Fe-convergence of bass-pop against the paper's criterion (relative L2 error over 0.3 s
below 0.1), and a K-study towards the rigid limit, through `fretbuzz convergence`."""
import shutil
import sys

from validation_common import FIGURES, fretbuzz, scratch_dir

window = sys.argv[1] if len(sys.argv) > 1 else "0.3"
out = scratch_dir("convergence")
print(fretbuzz("convergence", "bass-pop", "--fs", "250000,500000,1000000,2000000,4000000", "--reference-fs", "8000000",
               "--window", window, "--out", out / "fs", capture=True))
shutil.copy(out / "fs" / "convergence.png", FIGURES / "convergence_fs.png")
print(fretbuzz("convergence", "bass-pop", "--fs", "1000000", "--K", "1e11,1e12,1e13,1e14", "--reference-K", "1e15",
               "--window", "0.05", "--out", out / "K", capture=True))
shutil.copy(out / "K" / "convergence.png", FIGURES / "convergence_K.png")
