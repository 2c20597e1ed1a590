#!/usr/bin/python3
"""Executes a notebook with nbclient (Debian: python3-nbclient, python3-ipykernel), as CI
does for examples/notebook/*.ipynb. Usage: run_notebook.py NB [EXECUTED.ipynb].

The kernel is this interpreter (a kernel spec made for sys.executable), so the notebook
sees the packages this Python sees: run with a virtual environment's python, it uses the
fretbuzz installed there. Fails if a cell raises, if no cell shows an image (the plots are
drawn inline), or if a cell prints a warning."""
import json
import os
import sys
import tempfile

import nbclient
import nbformat


def kernel_for_this_interpreter(folder):
    """A kernel spec named 'this-python' in folder/kernels, running sys.executable."""
    spec = os.path.join(folder, "kernels", "this-python")
    os.makedirs(spec)
    with open(os.path.join(spec, "kernel.json"), "w") as f:
        json.dump({"argv": [sys.executable, "-Xfrozen_modules=off", "-m", "ipykernel_launcher", "-f", "{connection_file}"],
                   "display_name": f"Python ({sys.executable})", "language": "python"}, f)
    os.environ["JUPYTER_PATH"] = folder + os.pathsep + os.environ.get("JUPYTER_PATH", "")
    return "this-python"


def main(path, executed=None):
    notebook = nbformat.read(path, as_version=4)
    with tempfile.TemporaryDirectory(prefix="fretbuzz-kernel-") as folder:
        name = kernel_for_this_interpreter(folder)
        nbclient.NotebookClient(notebook, timeout=240, kernel_name=name).execute()
    if executed:
        nbformat.write(notebook, executed)
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.get("outputs", [])]
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    warnings = [o["text"] for o in outputs if o.get("output_type") == "stream" and o.get("name") == "stderr"
                and "Warning" in o.get("text", "")]
    if not images:
        sys.exit(f"{path}: no cell shows an image (the plot cell must draw inline)")
    if warnings:
        sys.exit(f"{path}: a cell printed a warning: {warnings[0]}")
    print(f"{path}: {len(notebook.cells)} cells executed with {sys.executable}, {len(images)} image(s) shown")


if __name__ == "__main__":
    main(*sys.argv[1:3])
