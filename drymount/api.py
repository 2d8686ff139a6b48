"""The public Python API of drymount (imported as ``drymount``).

Units are SI throughout: frequencies in Hz, displacements in m (rad for rotations),
forces in N (N m for moments), times in s. Defaults are the CLI's: a value not given
comes from the configuration's ``[sweep]``, ``[hbm]`` and ``[cosim]`` tables, then
from the defaults documented in ``docs/config.md`` (co-simulation backend ``"fmu"``,
like ``drymount cosim`` and ``drymount sweep``).

Example::

    import drymount

    model = drymount.load("sdof_original")                  # a preset or a TOML file
    for n0 in (10.0, 40.0):
        m = model.replace("mount.friction.n0", n0)          # N
        curve = drymount.hbm(m, 1.0, 30.0, progress=False)  # Hz
        p = curve.peak()                                     # peak transmissibility
        print(f"n0 = {n0:g} N: T = {p.value:.3f} at {p.freq_hz:.2f} Hz")
    curve.to_csv("sdof_hbm.csv")
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["Model", "Peak", "Curve", "CosimResult", "load", "hbm", "sweep", "cosim",
           "modes"]


@dataclass(frozen=True)
class Model:
    """A checked configuration: a system with its mounts, excitation and run settings.

    Make one with :func:`load`; change fields with :meth:`replace` or :meth:`with_`
    (a new Model; the original is left unchanged).

    Attributes
    ----------
    config : drymount.config.Config
        The checked configuration (``config.system`` is the ``hbm.system.System``).
    """

    config: object

    @property
    def name(self) -> str:
        """The configuration's name (output file names start with it)."""
        return self.config.name

    @property
    def system(self):
        """The ``hbm.system.System`` (mass, damping, stiffness in kg, N s/m, N/m)."""
        return self.config.system

    @property
    def dof_names(self) -> tuple:
        """Names of the degrees of freedom (``x``; ``z``, ``alpha``, ...)."""
        return tuple(self.config.system.dof_names)

    def replace(self, path: str, value) -> Model:
        """This model with the field at ``path`` set to ``value`` (SI units), checked
        like a file (e.g. ``replace("mounts[2].axial.friction.n0", 180.0)``, N);
        ``[*]`` sets every item. Raises ``drymount.config.ConfigError`` naming the
        field, the value and what is allowed."""
        return self.with_({path: value})

    def with_(self, changes: dict | None = None, /, *assignments: str) -> Model:
        """This model with several fields changed: a mapping ``{path: value}`` and/or
        ``"PATH=VALUE"`` strings (the CLI's ``--set`` syntax), applied in order."""
        from drymount.paths import override_config

        pairs = list((changes or {}).items()) + list(assignments)
        return Model(override_config(self.config, pairs))


@dataclass(frozen=True)
class Peak:
    """The maximum of a curve.

    Attributes
    ----------
    freq_hz : float
        Frequency of the maximum, Hz.
    value : float
        The maximum (transmissibility: dimensionless; a DOF: m or rad).
    quantity : str
        ``"transmissibility"`` or ``"<dof> peak"`` (max |q(t)| over a period).
    unit : str
        ``""`` (dimensionless), ``"m"`` or ``"rad"``.
    """

    freq_hz: float
    value: float
    quantity: str
    unit: str


def _dof_unit(dof: str) -> str:
    return "rad" if dof in ("alpha", "beta", "gamma") else "m"


class Curve:
    """A frequency response: harmonic balance (:func:`hbm`) or a co-simulated
    stepped-sine sweep (:func:`sweep`).

    Attributes
    ----------
    result : hbm.FrequencyResponse or vehicle.SweepResult
        Everything computed (coefficients, stability, convergence, ...).
    kind : str
        ``"hbm"`` or ``"sweep"``.
    """

    def __init__(self, result, kind: str):
        self.result = result
        self.kind = kind

    @property
    def freq_hz(self) -> np.ndarray:
        """Frequency of each point, Hz, shape (n_points,)."""
        return np.asarray(self.result.freq_hz)

    @property
    def transmissibility(self) -> np.ndarray:
        """Transmissibility of each point as the system defines it (force or
        displacement ratio of fundamental amplitudes), dimensionless, (n_points,)."""
        return np.asarray(self.result.transmissibility)

    @property
    def amplitude(self) -> np.ndarray:
        """Fundamental amplitude of each DOF, m or rad, shape (n_points, n_dof)."""
        return np.asarray(self.result.amplitude)

    @property
    def dof_names(self) -> tuple:
        """Names of the DOFs (columns of :attr:`amplitude`)."""
        return tuple(self.result.dof_names)

    @property
    def success(self) -> bool:
        """HBM: the curve reached fmax; sweep: every point reached a steady state."""
        return bool(self.result.success)

    def peak(self, dof: str | None = None) -> Peak:
        """The maximum over the curve: of the transmissibility (``dof=None``, what
        the CLI prints; an HBM curve's located between its points to 1e-6 Hz, a
        sweep's largest point), or of the per-point peak ``max |q(t)|`` of ``dof`` (m or
        rad). NaN points (gaps between segments) are skipped."""
        located = getattr(self.result, "transmissibility_peak", None)
        if dof is None and located is not None:  # an HBM curve: its located peak
            return Peak(float(located.freq_hz), float(located.transmissibility),
                        "transmissibility", "")
        if dof is None:
            y, quantity, unit = self.transmissibility, "transmissibility", ""
        else:
            if dof not in self.dof_names:
                raise ValueError(f"`dof` must be one of {list(self.dof_names)} or "
                                 f"None, got {dof!r}")
            y = np.asarray(self.result.peak)[:, self.dof_names.index(dof)]
            quantity, unit = f"{dof} peak", _dof_unit(dof)
        if not np.any(np.isfinite(y)):
            return Peak(float("nan"), float("nan"), quantity, unit)
        i = int(np.nanargmax(y))
        return Peak(float(self.freq_hz[i]), float(y[i]), quantity, unit)

    def to_csv(self, path) -> Path:
        """Write the curve as CSV (the CLI's format: ``freq_hz``, ``<dof>_amp``,
        ``<dof>_peak``, ``transmissibility``, ...; a ``# `` units line first)."""
        from drymount.io import atomic_path

        with atomic_path(path) as tmp:
            self.result.to_csv(tmp)
        return Path(path)

    def plot(self, path=None):
        """Plot the curve (titled, units on the axes); saved to ``path`` if given.
        Returns the matplotlib Figure (of an HBM curve and of a sweep alike)."""
        from matplotlib.figure import Figure

        if path is None:
            drawn = self.result.plot()
        else:
            from drymount.io import atomic_path

            with atomic_path(path) as tmp:
                drawn = self.result.plot(path=tmp)
        # FrequencyResponse.plot returns its first Axes, SweepResult.plot the Figure
        return drawn if isinstance(drawn, Figure) else drawn.figure


class CosimResult:
    """A co-simulated time history (:func:`cosim`).

    Attributes
    ----------
    history : vehicle.TimeHistory
        ``t`` (s), ``q`` (m, rad), ``qd``, mount ``forces`` (N), ``deflections`` (m),
        ``friction_energy`` (J).
    """

    def __init__(self, history):
        self.history = history

    @property
    def t(self) -> np.ndarray:
        """Time of each step from the start of the run, s, shape (n_t,)."""
        return self.history.t

    @property
    def q(self) -> np.ndarray:
        """DOFs, m or rad, shape (n_t, n_dof)."""
        return self.history.q

    @property
    def forces(self) -> np.ndarray:
        """Force of every active mount axis, N (positive = tension), (n_t, n_axes)."""
        return self.history.forces

    def peak(self, dof: str) -> Peak:
        """The maximum of ``|q(t)|`` of ``dof`` over the run, m or rad (its
        ``freq_hz`` is NaN: a time history has no frequency axis)."""
        names = list(self.history.dof_names)
        if dof not in names:
            raise ValueError(f"`dof` must be one of {names}, got {dof!r}")
        y = np.abs(self.history.q[:, names.index(dof)])
        i = int(np.argmax(y))
        return Peak(float("nan"), float(y[i]), f"{dof} peak", _dof_unit(dof))

    def spectra(self, skip: float = 0.0, segment_s: float | None = None):
        """PSDs of the mount forces (N^2/Hz) and DOF accelerations ((m/s^2)^2/Hz)
        by Welch's method after ``skip`` s (:func:`drymount.spectra.spectra`); a
        :class:`drymount.spectra.Spectra` with ``to_csv`` and ``plot``."""
        from drymount.spectra import spectra

        return spectra(self.history, skip=skip, segment_s=segment_s)

    def to_csv(self, path) -> Path:
        """Write time, DOFs and mount forces as CSV (a ``# `` units line first)."""
        return self.history.to_csv(path)

    def plot(self, path=None, dofs=None):
        """Plot the DOFs against time; saved to ``path`` if given. Returns the
        matplotlib Figure."""
        return self.history.plot(path=path, dofs=dofs)


def load(spec, *overrides: str) -> Model:
    """A :class:`Model` from a TOML file or a preset name (``drymount presets list``),
    with optional ``"PATH=VALUE"`` overrides (the CLI's ``--set``)."""
    from drymount.paths import load_with_overrides

    if isinstance(spec, Model):
        return spec.with_(None, *overrides)
    return Model(load_with_overrides(spec, overrides))


def _model(model) -> Model:
    return model if isinstance(model, Model) else load(model)


def _band(m: Model, fmin_hz, fmax_hz) -> tuple[float, float]:
    s = m.config.sweep
    fmin = s.fmin_hz if fmin_hz is None else float(fmin_hz)
    fmax = s.fmax_hz if fmax_hz is None else float(fmax_hz)
    if not 0 < fmin < fmax:
        raise ValueError(f"the band must satisfy 0 < fmin_hz < fmax_hz, got "
                         f"fmin_hz = {fmin:g} Hz, fmax_hz = {fmax:g} Hz")
    return fmin, fmax


def hbm(model, fmin_hz: float | None = None, fmax_hz: float | None = None, *,
        harmonics: int | None = None, n_samples: int | None = None,
        tol: float | None = None, max_harmonics: int | None = None,
        ds_initial: float | None = None, ds_min: float | None = None,
        ds_max: float | None = None, max_angle: float | None = None,
        progress: bool = True) -> Curve:
    """Harmonic-balance frequency response (``drymount hbm``).

    Parameters
    ----------
    model : Model, or a TOML file or preset name
    fmin_hz, fmax_hz : float, optional
        Band, Hz (default: the configuration's ``[sweep]``).
    harmonics : int, optional
        Harmonics H in 1..50, fixed (default: ``[hbm] harmonics``, where the
        ``tol`` adaptation starts, as ``drymount hbm``).
    n_samples : int, optional
        AFT samples per period, 2H + 1..8192, fixed (default: ``[hbm] n_samples``,
        adapted likewise).
    tol, max_harmonics, ds_initial, ds_min, ds_max, max_angle : optional
        Accuracy and step controls (``drymount hbm --tol`` ...; default: ``[hbm]``
        of the configuration, else ``hbm.HBMOptions``'s): the wanted accuracy
        relative to the peak, the cap on H of its adaptation (1..50), the arc-length
        steps (scaled) and the largest tangent angle (rad).
    progress : bool
        Progress bar on stderr.

    Raises
    ------
    drymount.hbm.options.OptionsError
        (a ValueError) An argument out of its range, naming it, its value and what
        is allowed; raised before any work.
    """
    import drymount.hbm as _hbm

    m = _model(model)
    fmin, fmax = _band(m, fmin_hz, fmax_hz)
    opts = _hbm_options(m, harmonics, n_samples, tol=tol, max_harmonics=max_harmonics,
                        ds_initial=ds_initial, ds_min=ds_min, ds_max=ds_max,
                        max_angle=max_angle)
    return Curve(_hbm.frequency_response(m.system, fmin, fmax, harmonics=harmonics,
                                         n_samples=n_samples, options=opts,
                                         progress=progress), "hbm")


def _check_resolution(m: Model, harmonics, n_samples) -> tuple[int, int | None]:
    """H and N of a run (the arguments over ``[hbm]``), checked by hbm.options' one
    check (the argument's name, or the configuration field a value came from)."""
    from drymount.hbm.options import check_harmonics, check_samples

    h = m.config.hbm
    if harmonics is not None:
        check_harmonics(harmonics)
    H = h.harmonics if harmonics is None else harmonics
    N = h.n_samples if n_samples is None else n_samples
    if N is not None and (harmonics is not None or n_samples is not None):
        check_samples(N, H, "n_samples" if n_samples is not None else "hbm.n_samples")
    return H, N


def _hbm_options(m: Model, harmonics, n_samples, **controls):
    """The checked ``hbm.HBMOptions`` of a run: ``controls`` not None over ``[hbm]``."""
    from drymount.hbm.options import check_harmonics

    _check_resolution(m, harmonics, n_samples)
    if controls.get("max_harmonics") is not None:
        check_harmonics(controls["max_harmonics"], "max_harmonics")
    return m.config.hbm.options(**controls)  # HBMOptions checks the others


def modes(model, mode="all", amplitude_range=None, *, harmonics: int | None = None,
          n_samples: int | None = None):
    """Nonlinear modes by EPMC (``drymount modes``): frequency (Hz) and modal damping
    ratio ``xi / (2 omega)`` of each mode against modal amplitude
    ``a = sqrt(Q1^H M Q1)`` (kg^0.5 m; m for a single DOF of 1 kg).

    Parameters
    ----------
    model : Model, or a TOML file or preset name
    mode : 'all', int or str
        'all', a 1-based mode number (ascending linearised frequency, contacts
        stuck) or the DOF that dominates the mode (e.g. ``"z"``).
    amplitude_range : (float, float), optional
        Modal amplitudes ``A0 < A1``, kg^0.5 m (default: per mode, 0.1 to 10 times
        the deflections where the nonlinearities act).
    harmonics, n_samples : int, optional
        H and AFT samples (default: ``[hbm]`` of the configuration).

    Returns
    -------
    hbm.modes.NonlinearModes
        ``modes`` (one :class:`hbm.modes.NonlinearMode` each: ``amplitude``,
        ``freq_hz``, ``damping_ratio``, ``harmonics``, ``slipping``), ``to_csv``,
        ``plot``.
    """
    from drymount.hbm.modes import nonlinear_modes

    m = _model(model)
    H, N = _check_resolution(m, harmonics, n_samples)
    return nonlinear_modes(m.system, mode, amplitude_range, harmonics=H, n_samples=N,
                           options=m.config.hbm.options())


def _fmu_kw(backend: str, fmu_path) -> dict:
    if backend != "fmu":
        return {}
    from drymount.fmu_build import default_fmu_path, ensure_fmu

    if fmu_path is not None:  # a user's FMU (PythonFMU or native): used as it is,
        return {"fmu_path": Path(fmu_path).resolve()}  # never rebuilt (issue 11)
    return {"fmu_path": ensure_fmu(default_fmu_path())}


def sweep(model, fmin_hz: float | None = None, fmax_hz: float | None = None, *,
          points: int | None = None, direction: str | None = None,
          spacing: str | None = None, backend: str | None = None, workers: int = 1,
          steps_per_period: int | None = None, fmu_path=None,
          progress: bool = True) -> Curve:
    """Stepped-sine sweep of co-simulated steady states (``drymount sweep``).

    Parameters
    ----------
    model : Model, or a TOML file or preset name
    fmin_hz, fmax_hz : float, optional
        Band, Hz (default: ``[sweep]``).
    points, direction, spacing : optional
        Number of frequencies, ``"up"``/``"down"``, ``"linear"``/``"log"``
        (default: ``[sweep]``).
    backend : {"fmu", "inproc"}, optional
        Default ``[cosim] backend`` (``"fmu"`` unless the file says otherwise).
    workers : int
        Processes.
    steps_per_period : int, optional
        Fixed steps per period (default: ``[cosim]``, else the harness's choice).
    fmu_path : path-like, optional
        The mount FMU of the ``fmu`` backend (default: built if missing).
    progress : bool
    """
    import drymount.vehicle as vehicle

    from drymount.config import SweepSettings

    m = _model(model)
    c = m.config
    fmin, fmax = _band(m, fmin_hz, fmax_hz)
    s = SweepSettings(fmin, fmax, points or c.sweep.points,
                      direction or c.sweep.direction, spacing or c.sweep.spacing)
    backend = backend or c.cosim.backend
    spp = steps_per_period or c.cosim.steps_per_period
    kw = _fmu_kw(backend, fmu_path) | ({"steps_per_period": spp} if spp else {})
    return Curve(vehicle.sweep(m.system, s.freqs_hz(), direction=s.direction,
                               backend=backend, workers=workers, progress=progress,
                               **kw), "sweep")


def _inputs(m: Model, freq, road, speed, engine, units):
    """The input of a run: measured road/engine inputs (given, else the
    configuration's ``[cosim.input]``) plus the harmonic excitation at ``freq`` (if
    given); None means the harmonic excitation alone."""
    import drymount.vehicle as vehicle

    from drymount.measured import configured_inputs, engine_input, road_input

    conf = configured_inputs(m.config)
    road = road if road is not None else conf.road
    engine = engine if engine is not None else conf.engine
    speed = speed if speed is not None else conf.speed
    units = {**conf.units, **(units or {})}
    parts = []
    if road is not None:
        parts.append(road_input(m.system, road, speed=speed, units=units))
    if engine is not None:
        parts.append(engine_input(m.system, engine, units=units))
    if not parts:
        return None
    if freq is not None:
        parts.append(vehicle.HarmonicInput(m.system, freq))
    return parts


def _check_span(part, duration: float) -> None:
    from drymount.measured import MeasuredInputError

    try:
        part.check_span(duration)
    except ValueError as exc:
        raise MeasuredInputError(f"{exc} (give a shorter `duration`)") from None


def cosim(model, freq_hz: float | None = None, *, duration: float | None = None,
          backend: str | None = None, steps_per_period: int | None = None,
          dt: float | None = None, road=None, speed: float | None = None,
          engine=None, units: dict | None = None, fmu_path=None) -> CosimResult:
    """Co-simulated time history from rest (``drymount cosim``).

    Parameters
    ----------
    model : Model, or a TOML file or preset name
    freq_hz : float, optional
        Frequency of the system's harmonic excitation, Hz (default
        ``[cosim] freq_hz``); needed unless a measured ``road`` or ``engine`` input
        is given.
        With a measured input, the harmonic excitation is added only when
        ``freq_hz`` is passed here.
    duration : float, optional
        Simulated time, s (default: with a measured input, the record's span (the
        shortest one); else ``[cosim] duration``, else 1 s).
    backend : {"fmu", "inproc"}, optional
        Default ``[cosim] backend``.
    steps_per_period : int, optional
        dt = 1 / (freq_hz steps_per_period) (default ``[cosim]``).
    dt : float, optional
        Step, s (wins over ``steps_per_period``; default: the harness's choice).
    road : path-like, optional
        Measured road profile or base displacement CSV
        (:func:`drymount.measured.road_input`). ``road``, ``speed``, ``engine`` and
        ``units`` default to the configuration's ``[cosim.input]``.
    speed : float, optional
        Vehicle speed, m/s, for a road profile over distance.
    engine : path-like, optional
        Measured engine forces/moments or accelerations CSV
        (:func:`drymount.measured.engine_input`).
    units : dict, optional
        Units of CSV columns whose header has none (``{"elevation": "mm"}``).
    fmu_path : path-like, optional
    """
    import drymount.vehicle as vehicle

    m = _model(model)
    c = m.config.cosim
    freq = freq_hz if freq_hz is not None else c.freq_hz
    parts = _inputs(m, freq_hz, road, speed, engine, units)
    if parts is None and freq is None:
        raise ValueError(f"give `freq_hz`, a `road` or an `engine` input (the "
                         f"configuration {m.config.source} has no [cosim] freq_hz)")
    backend = backend or c.backend
    if duration is None and parts is not None:
        duration = min(p.span[1] for p in parts if hasattr(p, "span"))
    elif duration is None:
        duration = c.duration if c.duration is not None else 1.0
    for p in parts or ():
        if hasattr(p, "check_span"):
            _check_span(p, duration)
    spp = steps_per_period or c.steps_per_period
    if dt is None and spp is not None and freq is not None:
        dt = 1.0 / (freq * spp)
    inputs = None if parts is None else (
        parts[0] if len(parts) == 1 else vehicle.SumInput(parts))
    kw = _fmu_kw(backend, fmu_path)
    if m.config.control is not None:  # [control]: scheduled on the excitation frequency
        kw["control"] = m.config.control.controllers(m.system, lambda t: freq)
    th = vehicle.simulate(m.system, freq if parts is None else freq_hz, duration,
                          backend=backend, dt=dt, inputs=inputs, **kw)
    return CosimResult(th)
