"""fretbuzz.Results: the outputs of a run as NumPy arrays, with the case that made them."""
from __future__ import annotations

import os
import shutil
from typing import Any, Dict, List, Optional, Sequence

import numpy as np

from . import _core

# The files a run writes into its output directory (and results.save copies).
_RUN_FILES_SUFFIXES = (".csv", ".wav", ".h5", ".json")


def _array_names(recorded: Any) -> List[str]:
    """Every array property of the compiled RecordedRun, so arrays added there appear here."""
    return sorted(name for name, value in vars(type(recorded)).items()
                  if isinstance(value, property) and name != "summary")


class Results:
    """The outputs of a run, as read-only NumPy arrays in SI units.

    Arrays: time (s), observation (m, samples x points), points (m), energy_time (s),
    energy, contact_energy, dissipated (J), with two polarisations observation_y (m), energy_y,
    damping_y, friction (J), grid_x (m), obstacle_height (m), first_contact,
    last_contact (s, NaN: never), peak_contact_force (N/m), snapshot_time (s), snapshots (m),
    and any others the run records. summary: the run summary (as summary.json), a dict.
    case: the Case that ran (with the run's overrides). directory: where its files are, if
    it was run with out=DIR or saved. Results pickle (the arrays are copied).
    """

    def __init__(self, recorded: Any, case: _core.Case, settings: Dict[str, Any],
                 directory: Optional[os.PathLike] = None) -> None:
        self.case = case
        self.settings = dict(settings)
        self.directory = os.fspath(directory) if directory is not None else None
        self.summary: Dict[str, Any] = recorded.summary
        self._names = _array_names(recorded)
        for name in self._names:
            setattr(self, name, getattr(recorded, name))  # views; they keep `recorded` alive

    def __getstate__(self) -> Dict[str, Any]:
        return dict(self.__dict__)

    def __setstate__(self, state: Dict[str, Any]) -> None:
        self.__dict__.update(state)
        for name in self._names:
            array = getattr(self, name)
            if isinstance(array, np.ndarray):
                array.setflags(write=False)

    def __repr__(self) -> str:
        return (f"<fretbuzz.Results '{self.summary.get('case', '')}': {len(self.time)} samples x "
                f"{len(self.points)} points>")

    def _has_files(self, directory: Optional[str]) -> bool:
        return directory is not None and os.path.isfile(os.path.join(directory, "results.h5"))

    def save(self, directory: os.PathLike) -> str:
        """Writes the files of `fretbuzz run --out DIR` into directory and returns its path.

        Copies them when this run already wrote them (run(..., out=...)); otherwise runs the
        case again with the file writers attached, and takes that run's arrays so that this
        object and the files agree bit for bit. (The two runs agree to round-off, not
        bitwise: the audio writer's per-step signal changes the order of operations of the
        free-flight path.)
        """
        target = os.fspath(directory)
        if self._has_files(self.directory):
            if os.path.abspath(target) != os.path.abspath(self.directory):
                os.makedirs(target, exist_ok=True)
                for name in sorted(os.listdir(self.directory)):
                    if name.endswith(_RUN_FILES_SUFFIXES):
                        shutil.copy2(os.path.join(self.directory, name), os.path.join(target, name))
        else:
            again = _core.simulate(self.case, out=target, **self.settings)
            self.summary = again.summary
            for name in self._names:
                setattr(self, name, getattr(again, name))
        self.directory = target
        return target

    def plot(self, directory: Optional[os.PathLike] = None, *, formats: Sequence[str] = ("png",),
             animation: str = "none", **options: Any) -> List[str]:
        """Draws the figures of `fretbuzz plot` into directory (default: this run's directory).

        formats: any of "png", "pdf", "svg". animation: "none", "gif" or "mp4" (needs
        snapshots). Other options go to fretbuzz.plots.plot_directory. Returns the paths.
        """
        from . import plots

        target = os.fspath(directory) if directory is not None else self.directory
        if target is None:
            raise ValueError("plot: give a directory (this run wrote no files: run(..., out=DIR) or save(DIR))")
        if not self._has_files(target):
            self.save(target)
        return plots.plot_directory(target, formats=formats, animation=animation, **options)

    def audio(self, point: int = 0, velocity: bool = False) -> Any:
        """The sound at observation point `point`, as an IPython.display.Audio (plays in notebooks).

        From the run's WAV file when it wrote one (run(..., out=DIR)); else from the
        observation signal, which needs an output rate between 8 and 384 kHz.
        """
        from IPython.display import Audio

        if not 0 <= point < len(self.points):
            raise ValueError(f"point: must be in [0, {len(self.points) - 1}], got {point}")
        if self.directory is not None:
            names = _core.audio_file_names(velocity, list(self.points))
            path = os.path.join(self.directory, names[point])
            if os.path.isfile(path):
                return Audio(filename=path)
        if velocity:
            raise ValueError("audio: velocity sound needs run(..., out=DIR, velocity_audio=True)")
        rate = self.summary["output_rate"]
        if not 8000.0 <= rate <= 384000.0:
            raise ValueError(f"audio: the output rate {rate:g} Hz cannot be played; run with output_rate=48000 "
                             "or with out=DIR (its WAV files are resampled to the audio rate)")
        return Audio(data=np.asarray(self.observation[:, point]), rate=int(round(rate)))
