#!/usr/bin/python3
"""Executes a notebook with nbclient (Debian: python3-nbclient, python3-ipykernel), as CI
does for examples/notebook/*.ipynb; fails if any cell raises. Usage: run_notebook.py NB."""
import sys

import nbclient
import nbformat

notebook = nbformat.read(sys.argv[1], as_version=4)
nbclient.NotebookClient(notebook, timeout=240, kernel_name="python3").execute()
print(f"{sys.argv[1]}: {len(notebook.cells)} cells executed")
