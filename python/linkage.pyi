"""linkage: deformable bodies as linkage models (Ku & Ching 1991) from Python.

Node and member numbers are the scene files' 1-based numbers: row i of a node array is
node i + 1, entry i of a member array is member i + 1. Units are SI (m, N, Pa, m²).
The Rust library does all the work; solves release the GIL. See docs/PYTHON.md.
"""

from os import PathLike
from typing import Any, Callable, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str

_Path = Union[str, PathLike[str]]
_Progress = Callable[[int, int], Any]
_Nodes = Union[Sequence[int], npt.ArrayLike, None]

class SceneError(ValueError):
    """A scene that cannot be built: the message names the file and line (and the body, node
    or member) and says what to do, as `linkage check` does."""

class RunError(RuntimeError):
    """A run that stopped: a step that could not be solved, a file that could not be written.
    `results` holds the steps solved before it (None when there are none)."""

    results: Optional[Results]

class ResultsError(OSError):
    """A results folder that cannot be read (missing, torn, or not written by `linkage run`)."""

def run(path: _Path, out: _Path = "out", progress: Optional[_Progress] = None) -> Results:
    """Run the scene file `path` as `linkage run path --out out` does: writes
    `out/<scene name>/` and returns its Results. `progress(done, total)` is called as steps
    are solved. Raises SceneError (file and line), RunError, or KeyboardInterrupt on Ctrl-C."""

class Material:
    """A material: `[[materials]]` of a scene file."""

    def __init__(
        self,
        name: str,
        youngs_modulus: float,
        area: Optional[float] = None,
        continuum_modulus: Optional[float] = None,
        **keys: Any,
    ) -> None:
        """`youngs_modulus` E in Pa and `area` A in m² of its members, or instead of `area`
        `continuum_modulus` in Pa: the Young's modulus a 3D body of this material has as a
        solid (its members' area is chosen per body to give it; give one of the two). Every
        other `[[materials]]` key as a keyword (`strength`, `tensile_strength`,
        `compressive_strength` in Pa, `behaviour`, `density` in kg/m³, `failure`, `scatter`,
        `softening`)."""
    @property
    def name(self) -> str:
        """The material's name."""
    def to_dict(self) -> dict[str, Any]:
        """The `[[materials]]` table as a dict."""

class Body:
    """A deformable body: `[[bodies]]` of a scene file."""

    def __init__(
        self,
        name: str,
        nodes: Optional[npt.ArrayLike] = None,
        members: Optional[npt.ArrayLike] = None,
        material: Union[Material, str, None] = None,
        member_materials: Optional[Sequence[Union[Material, str]]] = None,
        patches: Optional[npt.ArrayLike] = None,
        **keys: Any,
    ) -> None:
        """From arrays: `nodes` (n, 2) or (n, 3) in m, row i is node i + 1; `members` (m, 2)
        of 1-based node numbers, row i is member i + 1; `patches` (k, 3) for 3D surfaces.
        Or a generator keyword (`disk`, `rectangle`, `cylindrical_shell`, `box_lattice`,
        `mesh`, `outline`). `material`: a Material or the name of one given to
        `Scene(materials=)`; `member_materials`: one per member. Every other `[[bodies]]`
        key as a keyword (`kinematics`, `solver`, `newton`, `path`, `offset`, ...)."""
    @property
    def name(self) -> str:
        """The body's name."""
    def support(self, nodes: _Nodes = None, fix: Optional[Sequence[str]] = None, **keys: Any) -> None:
        """Hold the selected nodes (1-based numbers, or a selector keyword: `nearest`,
        `inside`, `on_line`, `on_plane`, `tolerance`) in the directions `fix` ("x", "y",
        "z"); `displacement` (m) and `schedule` as in `[[bodies.supports]]`."""
    def load(self, nodes: _Nodes = None, force: Optional[npt.ArrayLike] = None, **keys: Any) -> None:
        """Load the selected nodes with `force` per node (N), or `total_force=` shared by
        them; `schedule` as in `[[bodies.loads]]`."""
    def pressure(self, pressure: float, nodes: _Nodes = None, **keys: Any) -> None:
        """A pressure (Pa, positive into the body) on the patches whose nodes are selected."""

class Scene:
    """A scene: what a scene file says, checked and ready to run."""

    def __init__(
        self,
        name: str,
        bodies: Sequence[Body],
        steps: int = 1,
        materials: Optional[Sequence[Material]] = None,
        **keys: Any,
    ) -> None:
        """A scene named `name` (its output folder) of `bodies` with `steps` load steps.
        Every other top-level key as a keyword: `contact`, `obstacles`, `output`, `gravity`,
        `gravity_schedule`. Relative file names resolve against the current folder. Raises
        SceneError."""
    @staticmethod
    def load(path: _Path, values: Optional[Mapping[str, Any]] = None) -> Scene:
        """Read and check the scene file `path`; `values` sets dotted keys as one variant of
        a `[sweep]` would (`{"materials.rubber.youngs_modulus": 2e7}`). Raises SceneError
        with the file and line."""
    @staticmethod
    def from_dict(scene: Mapping[str, Any], path: Optional[_Path] = None) -> Scene:
        """A scene from a dict of the scene file's keys; `path` is where it would be
        (relative file names resolve against its folder)."""
    def to_dict(self) -> dict[str, Any]:
        """The scene as a dict of the scene file's keys (absent keys left out)."""
    def to_toml(self, path: _Path) -> None:
        """Write the scene file that `linkage run` runs, and beside it the paper files of
        bodies from arrays (`<body>.nodes`, `<body>.links`)."""
    def run(self, out: Optional[_Path] = None, progress: Optional[_Progress] = None) -> Results:
        """Solve every step: in memory without `out` (nothing written), else into
        `out/<name>/` as `linkage run` does. The GIL is released; Ctrl-C raises
        KeyboardInterrupt within 50 ms. Raises RunError when a step cannot be solved."""
    @property
    def name(self) -> str: ...
    @property
    def steps(self) -> int: ...
    @property
    def path(self) -> str:
        """The scene file it was read from (or would be written to)."""
    @property
    def text(self) -> str:
        """The scene's TOML."""
    @property
    def bodies(self) -> list[str]:
        """The body names, in scene order."""
    def describe(self) -> str:
        """The model's size in one line, as `linkage check` prints it."""

class Results:
    """A run's results: the stored steps (step 0 is the undeformed state) and the summary."""

    @staticmethod
    def load(dir: _Path) -> Results:
        """Read a results folder `DIR/<scene name>` (JSON or NPZ). Raises ResultsError."""
    @property
    def steps(self) -> list[Step]:
        """The stored steps, ascending."""
    @property
    def summary(self) -> Optional[dict[str, Any]]:
        """`summary.json` as a dict, or None."""
    @property
    def failure(self) -> Optional[str]:
        """Why the run stopped early, or None."""
    @property
    def folder(self) -> Optional[str]:
        """The results folder, or None for a run in memory."""
    def step(self, step: int) -> Step:
        """Step number `step` (ValueError when it was not stored)."""
    def __len__(self) -> int: ...
    def __eq__(self, other: object) -> bool:
        """Equal when the stored steps are equal number for number."""

class Step:
    """One stored step."""

    @property
    def number(self) -> int:
        """The step number (0: undeformed)."""
    @property
    def load_factor(self) -> float:
        """Load factor (loads reach 1 at the last step)."""
    @property
    def time(self) -> Optional[float]:
        """Time in s in a dynamic scene; None in a quasi-static one."""
    @property
    def names(self) -> list[str]:
        """The body names, in scene order."""
    @property
    def bodies(self) -> list[BodyResult]:
        """Every body's results, in scene order."""
    def body(self, name: str) -> BodyResult:
        """The results of the body `name` (ValueError naming the bodies when absent)."""

class BodyResult:
    """One body at one step. Node arrays: (nodes, d), row i is node i + 1; member arrays:
    (members,), entry i is member i + 1."""

    @property
    def name(self) -> str: ...
    @property
    def displacements(self) -> npt.NDArray[np.float64]:
        """m, (nodes, d)."""
    @property
    def positions(self) -> npt.NDArray[np.float64]:
        """Deformed positions, m, (nodes, d)."""
    @property
    def axial_forces(self) -> npt.NDArray[np.float64]:
        """N, tension positive, (members,)."""
    @property
    def strains(self) -> npt.NDArray[np.float64]:
        """Tension positive, (members,)."""
    @property
    def stresses(self) -> npt.NDArray[np.float64]:
        """Pa, tension positive, (members,)."""
    @property
    def reactions(self) -> npt.NDArray[np.float64]:
        """Force from the supports, N, (nodes, d); zero rows at unsupported nodes."""
    @property
    def supported_nodes(self) -> npt.NDArray[np.int64]:
        """1-based numbers of the supported nodes."""
    @property
    def loads(self) -> npt.NDArray[np.float64]:
        """Applied force at this step, N, (nodes, d)."""
    @property
    def contacts(self) -> npt.NDArray[np.float64]:
        """Contact force each node receives, N, (nodes, d); zero rows elsewhere."""
    @property
    def contact_list(self) -> list[dict[str, Any]]:
        """Each contact: node, with, depth, force, normal, normal_force, tangential_force,
        state, slip."""
    @property
    def overloaded(self) -> npt.NDArray[np.int64]:
        """1-based numbers of members beyond their strength."""
    @property
    def broken(self) -> npt.NDArray[np.int64]:
        """1-based numbers of members broken so far."""
    @property
    def breaks(self) -> list[dict[str, Any]]:
        """The breaks of this step."""
    def to_dict(self) -> dict[str, Any]:
        """The body's step as `steps/NNNN.json` holds it."""

def running() -> int:
    """The number of solve threads still running: a run interrupted by Ctrl-C raises at once,
    and its thread stops after the step it is in."""
