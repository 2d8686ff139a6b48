"""The ``[design]`` section of a configuration: variables, objectives, constraints.

Example (single DOF, the normal force of the thesis's Sec. 4.2)::

    [design]
    method = "lhs"              # "grid", "lhs" (Latin hypercube) or "sobol"
    samples = 64                # lhs/sobol; a power of 2 for sobol
    seed = 1
    harmonics = 1               # HBM harmonics per design (default: [hbm])
    band_hz = [1.0, 60.0]       # band of each design's HBM curve (default: [sweep])

    [[design.variables]]
    path = "mount.friction.n0"  # any numeric field by its path (drymount.paths)
    bounds = [0.5, 120.0]       # or values = [5.0, 10.0, 20.0]

    [[design.objectives]]
    name = "peak_T"
    quantity = "transmissibility"   # "transmissibility", "force" or "displacement"
    measure = "peak"                # "peak" (max over the band) or "rms"
    band_hz = [1.0, 60.0]

    [[design.constraints]]
    quantity = "displacement"       # value <= max
    dof = "x"
    band_hz = [1.0, 60.0]
    max = 0.004                     # m

Orientation variables turn a mount about a body axis: ``path =
"mounts[2].orientation"``, ``rotate_about = "y"``, bounds in degrees. Box constraints
keep positions inside a box: ``kind = "box"``, ``path = "mounts[*].position"``,
``min = [x, y, z]``, ``max = [x, y, z]`` (m).

:func:`design_space` checks the section and returns a :class:`DesignSpace`; every
problem names its field (``design.variables[1].bounds``), the value and what is
allowed, as :class:`drymount.config.ConfigError`.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from enum import Enum

import numpy as np

from drymount.paths import FieldPath, PathError, expand, get_value, set_value

__all__ = ["Quantity", "Measure", "Method", "Variable", "Metric", "BoxConstraint",
           "DesignSpace", "apply_values", "current_values", "DESIGN_KEYS"]


class Method(str, Enum):
    """How ``drymount explore`` samples the space."""
    GRID = "grid"
    LHS = "lhs"
    SOBOL = "sobol"


class Quantity(str, Enum):
    """What an objective or a response constraint measures on an HBM curve."""
    TRANSMISSIBILITY = "transmissibility"   # the system's T (thesis eq. 4.1 / 4.3), -
    FORCE = "force"                         # transmitted force amplitude T * F_exc, N
    DISPLACEMENT = "displacement"           # max |q(t)| of one DOF, m or rad


class Measure(str, Enum):
    """How the curve over a band becomes one number."""
    PEAK = "peak"   # largest value at the curve's points in the band
    RMS = "rms"     # RMS over the band, equal weight per Hz, upper envelope at folds


ROTATIONS = ("alpha", "beta", "gamma")
AXES = {"x": 0, "y": 1, "z": 2}
DEFAULT_GRID_POINTS = 5
DEFAULT_SAMPLES = 64
DEFAULT_CHUNK = 8
#: Most designs of one exploration (``samples``, or the grid's product of ``points``
#: and list lengths): 0.03-3 s each, 1e5 designs are 1 hour to 3 days on one core.
MAX_DESIGNS = 100_000

DESIGN_KEYS = {
    "design": ("method", "samples", "seed", "harmonics", "band_hz", "chunk",
               "variables", "objectives", "constraints"),
    "variables[]": ("path", "name", "bounds", "values", "points", "rotate_about",
                    "mode"),
    "objectives[]": ("name", "quantity", "measure", "band_hz", "dof", "sense"),
    "constraints[]": ("name", "kind", "quantity", "measure", "band_hz", "dof", "max",
                      "path", "min"),
}


@dataclass(frozen=True)
class Variable:
    """One design variable.

    Attributes
    ----------
    name : str
        Column name in the tables (default: the path, or ``<path>.rot_<axis>_deg``).
    paths : tuple of FieldPath
        The field(s) it sets; with ``[*]`` every match gets the same value.
    lower, upper : float
        Bounds (continuous variable); NaN for a list variable.
    values : tuple of float
        The allowed values of a list variable (empty for a continuous one).
    points : int
        Values per continuous variable on a grid.
    rotate_about : str or None
        ``"x"``, ``"y"`` or ``"z"``: the value is an angle in degrees turning the
        mount's orientation about that body axis.
    scale : bool
        The value multiplies the file's values of the fields (a stiffness scale:
        ``paths`` = every k1 and k2) instead of replacing them.
    """

    name: str
    paths: tuple
    lower: float = math.nan
    upper: float = math.nan
    values: tuple = ()
    points: int = DEFAULT_GRID_POINTS
    rotate_about: str | None = None
    scale: bool = False

    @property
    def path(self) -> FieldPath:
        """The first of ``paths``."""
        return self.paths[0]

    @property
    def is_list(self) -> bool:
        return bool(self.values)

    def from_unit(self, u: float) -> float:
        """The value at ``u`` in [0, 1) (a list variable picks item floor(u n))."""
        if self.is_list:
            n = len(self.values)
            return float(self.values[min(int(u * n), n - 1)])
        return float(self.lower + u * (self.upper - self.lower))

    def grid(self) -> np.ndarray:
        if self.is_list:
            return np.asarray(self.values, dtype=float)
        return np.linspace(self.lower, self.upper, self.points)


@dataclass(frozen=True)
class Metric:
    """An objective (minimised unless ``sense = "max"``) or a response constraint
    (``value <= limit``; margin = limit - value).

    ``dof`` is the DOF name of a displacement (None otherwise); ``unit`` is for
    labels."""

    name: str
    quantity: Quantity
    measure: Measure
    band_hz: tuple
    dof: str | None = None
    sense: str = "min"
    limit: float = math.nan
    unit: str = "-"


@dataclass(frozen=True)
class BoxConstraint:
    """Every addressed position (3 numbers, m) inside [lower, upper] per axis; the
    margin is the smallest distance to a face (negative outside)."""

    name: str
    path: FieldPath
    lower: tuple
    upper: tuple
    unit: str = "m"


@dataclass(frozen=True)
class DesignSpace:
    """A checked ``[design]`` section (see the module docstring)."""

    method: Method
    samples: int
    seed: int
    harmonics: int
    band_hz: tuple
    chunk: int
    variables: tuple
    objectives: tuple
    constraints: tuple   # Metric (response) and BoxConstraint items

    @property
    def names(self) -> dict:
        """Column names: variables, objectives, constraint margins."""
        return {"variables": [v.name for v in self.variables],
                "objectives": [o.name for o in self.objectives],
                "constraints": [c.name for c in self.constraints]}

    def size(self) -> int:
        """Number of designs ``drymount explore`` evaluates."""
        if self.method is Method.GRID:
            return int(np.prod([len(v.grid()) for v in self.variables]))
        return self.samples


# ======================================================================================
# Applying design values to a document
# ======================================================================================


def _rotation(axis: str, deg: float) -> np.ndarray:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    i, j = [(1, 2), (2, 0), (0, 1)][AXES[axis]]
    R = np.eye(3)
    R[i, i], R[i, j], R[j, i], R[j, j] = c, -s, s, c
    return R


def current_values(doc: dict, variables) -> tuple:
    """The values the document itself gives the variables (0 for a rotation; the
    first match of a ``[*]`` path; NaN where the field is absent)."""
    out = []
    for var in variables:
        if var.rotate_about is not None or var.scale:
            out.append(0.0 if var.rotate_about is not None else 1.0)
            continue
        try:
            out.append(float(get_value(doc, expand(doc, var.path)[0])))
        except (PathError, TypeError, ValueError):
            out.append(math.nan)
    return tuple(out)


def apply_values(doc: dict, variables, values) -> dict:
    """A copy of ``doc`` with each variable set to its value.

    A scale variable multiplies the values ``doc`` gives its fields. A rotation
    variable turns the orientation rows (axial, radial1, radial2 unit vectors in body
    axes) by the angle about the body axis: ``O' = O R^T``, starting from the file's
    orientation or the model's default (axial = z).
    """
    from drymount.hbm.systems import DEFAULT_ORIENTATION

    new = copy.deepcopy(doc)
    for var, x in zip(variables, values, strict=True):
        for parts in (p for path in var.paths for p in expand(new, path)):
            if var.scale:
                set_value(new, parts, float(get_value(doc, parts)) * float(x))
                continue
            if var.rotate_about is None:
                set_value(new, parts, float(x))
                continue
            try:
                rows = np.asarray(get_value(new, parts), dtype=float)
            except PathError:
                rows = np.asarray(DEFAULT_ORIENTATION, dtype=float)
            if rows.shape != (3, 3):
                raise PathError(f"`{var.path}` must be a 3x3 orientation to turn, "
                                f"got {rows.tolist()}")
            set_value(new, parts,
                      (rows @ _rotation(var.rotate_about, x).T).tolist())
    return new
