"""`fretbuzz clean STUDY [--keep-maps N]` on a studio's study folder: removes the maps a killed
studio left unfinished and, with --keep-maps, all but the newest N finished maps (their
reports in exports/ stay: each holds its own sounds). Only the WAVs a map wrote are removed,
and a map's folder only once empty. Refused, exit 1 naming its process, while a studio works
in the folder; exit 2 when maps/ or exports/ is a symbolic link (it is never followed)."""
from __future__ import annotations

import argparse
import os
import sys
from typing import List, Optional

from ..setup_bench import InputError
from . import _count
from .study import lock_folder, prune_maps


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="fretbuzz clean", description="Prune a study folder's maps.")
    parser.add_argument("study", help="the study folder")
    parser.add_argument("--keep-maps", type=_count, metavar="N", help="keep only the newest N finished maps")
    args = parser.parse_args(argv)
    folder = os.path.realpath(args.study)
    try:
        fd = lock_folder(folder)
        try:
            unfinished, old = prune_maps(folder, args.keep_maps)
        finally:
            os.close(fd)
    except InputError as e:  # a link where the study keeps its own folder: refused, nothing removed
        print(f"fretbuzz clean: {e}", file=sys.stderr)
        return 2
    except OSError as e:  # StudyBusy among them, naming the studio's process
        print(f"fretbuzz clean: {e}", file=sys.stderr)
        return 1
    print(f"fretbuzz: removed {unfinished} unfinished map{'' if unfinished == 1 else 's'} and {old} old "
          f"map{'' if old == 1 else 's'} from {args.study}", file=sys.stderr)
    return 0
