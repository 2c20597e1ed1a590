# Type stubs of the compiled part of fretbuzz (python/bindings/*.cpp).
import os
from typing import Any, Callable, Dict, List, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str

Number = Union[int, float, np.floating, np.integer]
Numbers = Union[Sequence[Number], npt.NDArray[Any]]

class InputError(ValueError): ...
class SolverError(RuntimeError): ...

class Case:
    """A simulation case; fields as attributes or items, every edit validated, all or nothing."""
    name: str
    description: str
    L: float
    T: float
    mu: float
    frequencies: npt.NDArray[np.float64]
    sigma: npt.NDArray[np.float64]
    obstacle_height: npt.NDArray[np.float64]
    initial_displacement: npt.NDArray[np.float64]
    initial_velocity: npt.NDArray[np.float64]
    K: float
    alpha: float
    fs: float
    duration: float
    output_rate: Optional[float]
    audio_rate: float
    observe: List[float]
    @property
    def modes(self) -> int: ...
    @property
    def grid_x(self) -> npt.NDArray[np.float64]: ...
    @property
    def source_text(self) -> str: ...
    def __init__(self, **fields: Any) -> None: ...
    @staticmethod
    def from_toml(text: str, data_dir: Union[str, os.PathLike[str], None] = None) -> Case: ...
    def __getitem__(self, key: str) -> Any: ...
    def __setitem__(self, key: str, value: Any) -> None: ...
    def __contains__(self, key: str) -> bool: ...
    def keys(self) -> List[str]: ...
    def to_dict(self) -> Dict[str, Any]: ...
    def update(self, values: Dict[str, Any]) -> None: ...
    def make_lossless(self) -> None: ...
    def validate(self) -> None: ...
    def copy(self) -> Case: ...
    def __copy__(self) -> Case: ...
    def __deepcopy__(self, memo: Dict[int, Any]) -> Case: ...

class Progress:
    fraction: float
    simulated_s: float
    elapsed_s: float
    remaining_s: float

class RecordedRun:
    time: npt.NDArray[np.float64]
    observation: npt.NDArray[np.float64]
    points: npt.NDArray[np.float64]
    energy_time: npt.NDArray[np.float64]
    energy: npt.NDArray[np.float64]
    contact_energy: npt.NDArray[np.float64]
    dissipated: npt.NDArray[np.float64]
    observation_y: npt.NDArray[np.float64]
    energy_y: npt.NDArray[np.float64]
    damping_y: npt.NDArray[np.float64]
    friction: npt.NDArray[np.float64]
    grid_x: npt.NDArray[np.float64]
    obstacle_height: npt.NDArray[np.float64]
    first_contact: npt.NDArray[np.float64]
    last_contact: npt.NDArray[np.float64]
    peak_contact_force: npt.NDArray[np.float64]
    snapshot_time: npt.NDArray[np.float64]
    snapshots: npt.NDArray[np.float64]
    summary: Dict[str, Any]

def load_case(name_or_path: str) -> Case: ...
def cases() -> Dict[str, str]: ...
def audio_file_names(velocity: bool, points: Sequence[float]) -> List[str]: ...
def simulate(case: Case, *, snapshots: Number = 0.0, screen: bool = True, free_flight: bool = True,
             out: Union[str, os.PathLike[str], None] = None, velocity_audio: bool = False,
             snapshot_until: Optional[Number] = None,
             progress: Optional[Callable[[Progress], Any]] = None, fade_in: Optional[Number] = None,
             fade_out: Optional[Number] = None) -> RecordedRun: ...

class SweepProgress:
    """How far a sweep has gone (sweep(..., progress=callback))."""
    done: int
    total: int
    failed: int
    resumed: int
    elapsed_s: float
    remaining_s: float
    def __init__(self, done: int, total: int, failed: int, resumed: int, elapsed_s: float,
                 remaining_s: float) -> None: ...

class SweepSpec:
    """A sweep spec: a case and the values to run it over (picklable)."""
    text: str
    source_name: str
    parameter_keys: List[str]
    audio: bool
    max_runs: int
    @staticmethod
    def load(path: str, max_runs: int = ...) -> SweepSpec: ...
    @staticmethod
    def parse(text: str, source_name: str = ..., base_dir: str = ..., max_runs: int = ...) -> SweepSpec: ...
    def __len__(self) -> int: ...
    def check(self, progress: Optional[Callable[[int, int], Any]] = ...) -> None: ...
    def case(self, index: int) -> Case: ...
    def run_row(self, index: int, audio_dir: str = ...) -> str: ...

class SweepStore:
    """The row files and tables of a sweep in a directory."""
    def __init__(self, spec: SweepSpec, dir: str, resume: bool = ...) -> None: ...
    def missing(self) -> List[int]: ...
    def audio_dir(self, index: int) -> str: ...
    def record(self, row_json: str) -> None: ...
    def failed(self) -> int: ...
    def write_table(self) -> None: ...

def sweep_metric_names() -> List[str]: ...
def run_sweep_local(spec: SweepSpec, out: str, jobs: int = ..., resume: bool = ...,
                    progress: Optional[Callable[[SweepProgress], Any]] = ...) -> Dict[str, Any]: ...
