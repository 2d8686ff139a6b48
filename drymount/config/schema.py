"""The configuration's schema: allowed keys, result objects, the error type."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from drymount.fmu_src.friction import element_fields
from drymount.fmu_src.mount_law import AXES
from drymount.hbm.options import HBMOptions
from drymount.hbm.system import System

from drymount.config.errors import ConfigError  # noqa: F401 - re-exported
from drymount.config.limits import (  # noqa: F401 - re-exported
    MAX_HARMONICS,
    MAX_N_SAMPLES,
    MAX_POINTS,
)
from drymount.config.static import StaticSettings


MODELS = ("sdof", "quarter_car", "rigid_engine")
#: Excitation kinds allowed per model (``hbm.system.Excitation``).
EXCITATION_KINDS = {
    "sdof": ("unbalance", "force", "base"),
    "quarter_car": ("base",),
    "rigid_engine": ("base", "unbalance", "force"),
}
BACKENDS = ("fmu", "inproc")
#: Old backend names, accepted with a FutureWarning: "native" now means only the C FMU.
RENAMED_BACKENDS = {"native": "inproc"}
DIRECTIONS = ("up", "down")
SPACINGS = ("linear", "log")
# The bounds on H and N are drymount.hbm.options' MAX_HARMONICS and MAX_N_SAMPLES,
# checked by its check_harmonics / check_samples; MAX_POINTS is config.limits'.
#: Relative size below which the smallest eigenvalue of the linearised (stuck)
#: stiffness counts as zero: the mounts leave a rigid-body motion free.
SINGULAR_RTOL = 1e-10

_AXIS_LAW_KEYS = ("law", "k1", "kc", "k2", "delta", "delta_neg", "c")
#: Keys of a friction table: ``kind`` (``AxisParameters.friction_kind``, a name of the
#: friction-element registry) and the fields of every registered element (a table
#: may give only those of its kind, drymount.config.mounts).
_FRICTION_KEYS = ("kind", *(f.name for f in element_fields()))

#: Allowed keys of every table, by the path pattern used in messages and in
#: docs/config.md (``[]`` stands for an index of ``[[mounts]]``).
ALLOWED_KEYS: dict[str, tuple[str, ...]] = {
    "": ("model", "name", "description", "sdof", "quarter_car", "rigid_engine",
         "mount", "mounts", "excitation", "sweep", "hbm", "cosim", "static", "control",
         "design"),  # [design]: checked by drymount.design (explore, optimize)
    "sdof": ("mass",),
    "quarter_car": ("m_e", "m_s", "m_us", "k_s", "c_s", "k_t", "c_t"),
    "rigid_engine": ("mass", "inertia"),
    "mount": (*_AXIS_LAW_KEYS, "friction", "maxwell", "hydraulic"),
    "mount.friction": _FRICTION_KEYS,
    # Maxwell branches (spring k in series with damper c) beside the elastic law
    "mount.maxwell": ("k", "c"),
    # the hydraulic mount's fluid path (linear_branches.HydraulicParameters; the
    # rubber kr, br: the axis's own k1 and c)
    "mount.hydraulic": ("kr", "br", "Ap", "C1", "C2", "I_i", "R_i", "I_d", "R_d"),
    "mounts[]": ("name", "position", "orientation", "lambda", *AXES),
    "mounts[].<axis>": (*_AXIS_LAW_KEYS, "friction", "maxwell", "hydraulic"),
    "mounts[].<axis>.friction": _FRICTION_KEYS,
    "mounts[].<axis>.maxwell": ("k", "c"),
    "mounts[].<axis>.hydraulic": ("kr", "br", "Ap", "C1", "C2", "I_i", "R_i", "I_d",
                                  "R_d"),
    "excitation": ("kind", "amplitude"),
    "sweep": ("fmin_hz", "fmax_hz", "points", "direction", "spacing"),
    "hbm": ("harmonics", "n_samples", "tol", "max_harmonics", "ds_initial", "ds_min",
            "ds_max", "max_angle"),
    "cosim": ("backend", "freq_hz", "duration", "steps_per_period", "input"),
    # measured inputs of `drymount cosim` (drymount.measured), checked in systems.py
    "cosim.input": ("road", "speed", "engine", "units"),
    "static": ("gravity", "g", "loads", "travel", "reading"),
    # semi-active normal-force control (drymount.config.control)
    "control": ("kind", "axes", "n_min", "n_max", "rate_max", "schedule_hz",
                "schedule_n", "n_on", "n_off"),
}

#: The model-specific tables: which model each belongs to.
_MODEL_TABLES = {"sdof": "sdof", "quarter_car": "quarter_car",
                 "rigid_engine": "rigid_engine", "mount": ("sdof", "quarter_car"),
                 "mounts": ("rigid_engine",)}


# ======================================================================================
# Result objects
# ======================================================================================


@dataclass(frozen=True)
class SweepSettings:
    """Frequency band of ``drymount hbm`` and ``drymount sweep``.

    Attributes
    ----------
    fmin_hz, fmax_hz : float
        Band in Hz, 0 < fmin_hz < fmax_hz.
    points : int
        Number of frequencies of a stepped-sine sweep (>= 2). The HBM continuation
        chooses its own steps between fmin_hz and fmax_hz.
    direction : str
        ``"up"`` or ``"down"``: order of the stepped sweep.
    spacing : str
        ``"linear"`` or ``"log"``: spacing of the sweep frequencies.
    """

    fmin_hz: float = 1.0
    fmax_hz: float = 50.0
    points: int = 50
    direction: str = "up"
    spacing: str = "linear"

    def freqs_hz(self) -> np.ndarray:
        """The sweep frequencies in Hz, shape (points,), ascending."""
        if self.spacing == "log":
            return np.geomspace(self.fmin_hz, self.fmax_hz, self.points)
        return np.linspace(self.fmin_hz, self.fmax_hz, self.points)


@dataclass(frozen=True)
class HBMSettings:
    """Harmonic balance settings (``hbm.frequency_response``).

    Attributes
    ----------
    harmonics : int
        Number of harmonics H (1..MAX_HARMONICS); 1 is the thesis's single harmonic.
        Default: ``hbm.HBMOptions``'s (the one source of the HBM defaults).
    n_samples : int or None
        AFT time samples per period (>= 2H + 1); None lets ``hbm`` choose.
    tol : float or None
        Wanted accuracy relative to the peak (``hbm.HBMOptions.tol``); None: its
        default.
    max_harmonics : int or None
        Cap on H when ``tol`` raises it (``hbm.HBMOptions.max_harmonics``).
    ds_initial, ds_min, ds_max, max_angle : float or None
        Continuation step controls (scaled arc length, rad); None: the defaults of
        ``hbm.HBMOptions``.
    """

    harmonics: int = HBMOptions.harmonics
    n_samples: int | None = HBMOptions.n_samples
    tol: float | None = None
    max_harmonics: int | None = None
    ds_initial: float | None = None
    ds_min: float | None = None
    ds_max: float | None = None
    max_angle: float | None = None

    def options(self, **overrides) -> HBMOptions:
        """These settings as ``hbm.HBMOptions`` (H and N as where ``tol`` starts;
        fields left None at hbm's defaults); ``overrides`` that are not None win."""
        kw = {k: getattr(self, k) for k in (
            "harmonics", "n_samples", "tol", "max_harmonics", "ds_initial", "ds_min",
            "ds_max", "max_angle")}
        kw.update({k: v for k, v in overrides.items() if v is not None})
        kw = {k: v for k, v in kw.items() if v is not None or k == "n_samples"}
        return HBMOptions(**kw)


@dataclass(frozen=True)
class CosimSettings:
    """Co-simulation settings (``vehicle.simulate``, ``vehicle.sweep``).

    Attributes
    ----------
    backend : str
        ``"fmu"`` (one FMU instance per mount through fmpy) or ``"inproc"`` (the same
        mount law called in-process, for long sweeps; ``"native"``, its old name, is
        accepted with a FutureWarning).
    freq_hz : float or None
        Default excitation frequency of ``drymount cosim``, Hz.
    duration : float or None
        Default simulated time of ``drymount cosim``, s (None: the harness default).
    steps_per_period : int or None
        Fixed steps per excitation period (dt = 1 / (freq_hz * steps_per_period));
        None: the harness default.
    """

    backend: str = "fmu"
    freq_hz: float | None = None
    duration: float | None = None
    steps_per_period: int | None = None


@dataclass(frozen=True, eq=False)
class Config:
    """A checked configuration.

    Attributes
    ----------
    name : str
        ``name`` of the file, else the preset name or the file stem.
    description : str
    model : str
        One of ``MODELS``.
    system : hbm.system.System
        The model with its mounts and excitation, ready for ``hbm`` and ``vehicle``;
        its ``name`` and ``description`` are the configuration's, ``system.notes``
        holds ``config_name``, ``model`` and ``source``.
    sweep : SweepSettings
    hbm : HBMSettings
    cosim : CosimSettings
    source : str
        Where it came from: a file path, ``preset:<name>`` or ``<text>``.
    data : dict
        The parsed TOML document.
    static : StaticSettings
        ``[static]``: gravity and static loads (``system.static_load`` holds the
        resulting load; default none).
    control : drymount.config.control.ControlSettings or None
        The ``[control]`` table (semi-active normal force), None without one.
    """

    name: str
    description: str
    model: str
    system: System
    sweep: SweepSettings
    hbm: HBMSettings
    cosim: CosimSettings
    source: str
    data: dict = field(repr=False, default_factory=dict)
    static: StaticSettings = field(default_factory=StaticSettings)
    control: object = None
