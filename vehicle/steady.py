"""Periodic steady state of a co-simulation under the system's harmonic excitation.

The master (:mod:`vehicle.master`) runs whole excitation periods of N steps (an
integer number, default 256, more if the step limit demands) until the state at the
end of a period differs from the state one period before by less than ``rtol``:

    change = max(|q_P - q_{P-1}| / max_t |q|,  |q'_P - q'_{P-1}| / max_t |q'|)

(infinity norms over the DOFs; q_P the state at the end of period P).

Then, over the last period (samples t_k = k h, k = 0..N-1, phase 0 at k = 0):

- the fundamental of each DOF by a DFT, as a phasor ``X`` with
  ``q(t) ~ Im(X exp(i omega t))`` (the sine convention of :mod:`hbm.system`), the
  amplitude ``|X|`` and the peak ``max_t |q|``;
- the transmissibility as defined by ``system.transmissibility`` (thesis eq. 4.1 and
  4.3): force kind, fundamental amplitude of the summed listed mount forces over
  ``Excitation.scalar_amplitude(omega)``; displacement kind, amplitude of ``dof`` over
  that of ``reference``, or over the base amplitude;
- the friction energy per cycle: the energy the sliders dissipated in the last period
  (the law's ``dissipated`` output, or the FMU's ``E_fr``), summed over the mounts;
- the area of the friction force-displacement loops, sum over the active axes of the
  closed trapezoidal integral of ``Ffr du`` over the last period. In a periodic state
  the two are equal (the slider work ``Fs |dw|`` is the only dissipation of a Jenkins
  element); discretely they differ by O(h^2) terms at the stick-slip transitions.

The final state (q, q', q'' and the slider positions) is returned, so a sweep
continues from it.

Conventions: a Jenkins element that never slips keeps whatever slider offset the
start-up left (PHYSICS.md section 1); amplitudes (fundamental, peak about zero) are
compared, not offsets.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from drymount.hbm.hydraulic import hydraulic_axes
from drymount.hbm.maxwell import maxwell_axes

from .inputs import HarmonicInput
from .master import DEFAULT_STEPS_PER_PERIOD, Master

__all__ = ["SteadyState", "State", "OrbitStart", "orbit_start", "steady_state",
           "run_steady", "linear_start", "DEFAULT_RTOL", "DEFAULT_MAX_PERIODS",
           "DEFAULT_MIN_PERIODS"]

#: Default tolerance on the relative period-to-period change of the state (the
#: amplitude error it leaves is below the 2.5e-4 discretisation error: measured
#: 1.5e-4 worst with 1e-4 on the linear SDOF, see vehicle.master).
DEFAULT_RTOL = 1e-5
#: Default least and largest number of periods of one steady-state run.
DEFAULT_MIN_PERIODS = 3
DEFAULT_MAX_PERIODS = 3000


@dataclass
class SteadyState:
    """Periodic steady state at one frequency.

    Attributes
    ----------
    freq_hz : float
        Excitation frequency, Hz.
    omega : float
        2 pi freq_hz, rad/s.
    dt : float
        Step, s (= 1 / (freq_hz * steps_per_period)).
    steps_per_period : int
    n_periods : int
        Periods run.
    converged : bool
        Whether ``change <= rtol`` was reached within ``max_periods``.
    change : float
        Last relative period-to-period change of the state.
    dof_names : tuple of str
    axis_labels : tuple of str
        ``<mount>_<axis>`` of every active mount axis.
    phasor : ndarray, complex, shape (n_dof,)
        Fundamental: ``q(t) ~ Im(phasor exp(i omega t))``, m or rad.
    amplitude : ndarray, shape (n_dof,)
        ``|phasor|``, m or rad.
    peak : ndarray, shape (n_dof,)
        ``max |q(t)|`` over the last period, m or rad.
    mean : ndarray, shape (n_dof,)
        Mean of q over the last period, m or rad.
    transmissibility : float
        As defined by ``system.transmissibility`` (dimensionless).
    force_amplitude : ndarray, shape (n_axes,)
        Fundamental amplitude of every active mount-axis force, N.
    friction_energy : float
        Energy dissipated by friction in the last period, all mounts, J.
    loop_area : float
        Sum over the axes of the closed integral of Ffr du over the last period, J.
    t : ndarray, shape (N,)
        Times of the last period's samples, s (phase 0 at t = 0).
    q, qd : ndarray, shape (N, n_dof)
        DOFs and rates over the last period.
    forces, friction_forces, deflections : ndarray, shape (N, n_axes)
        Mount forces (N), friction forces (N), deflections u (m) over the last period.
    q_end, qd_end, qdd_end : ndarray, shape (n_dof,)
        State at the end of the last period (start of the next).
    sliders : ndarray, shape (n_mounts, 3)
        Slider positions at the end, m.
    time : float
        Global simulation time at the end, s.
    backend : str
    n_steps : int
        Steps (mount-force evaluations) of this run.
    wall_time : float
        Seconds spent stepping.
    """

    freq_hz: float
    omega: float
    dt: float
    steps_per_period: int
    n_periods: int
    converged: bool
    change: float
    dof_names: tuple[str, ...]
    axis_labels: tuple[str, ...]
    phasor: np.ndarray
    amplitude: np.ndarray
    peak: np.ndarray
    mean: np.ndarray
    transmissibility: float
    force_amplitude: np.ndarray
    friction_energy: float
    loop_area: float
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    forces: np.ndarray
    friction_forces: np.ndarray
    deflections: np.ndarray
    q_end: np.ndarray
    qd_end: np.ndarray
    qdd_end: np.ndarray
    sliders: np.ndarray
    time: float
    backend: str
    n_steps: int
    wall_time: float
    message: str = ""
    extra: dict = field(default_factory=dict)


def fundamental(x: np.ndarray) -> np.ndarray:
    """Phasor ``X`` of the fundamental of samples ``x`` (N, ...) over one period with
    ``x(t) ~ Im(X exp(i 2 pi k / N))``."""
    N = x.shape[0]
    e = np.exp(-2j * np.pi * np.arange(N) / N)
    Q = (2.0 / N) * np.tensordot(e, x, axes=(0, 0))  # x ~ Re(Q e^{i w t})
    return 1j * Q


def fourier_coefficients(x: np.ndarray, harmonics: int) -> np.ndarray:
    """Real Fourier coefficients of samples ``x`` (N, n) over one period, in the
    harmonic-balance layout ``[static, cos1, sin1, ..., cosH, sinH]``: returns
    shape (n, 2H+1), with ``x_k ~ c0 + sum_h c_h cos(2 pi h k/N) + s_h sin(...)``."""
    N = x.shape[0]
    H = min(int(harmonics), (N - 1) // 2)
    k = np.arange(N)
    out = np.empty((x.shape[1], 2 * H + 1))
    out[:, 0] = x.mean(axis=0)
    for h in range(1, H + 1):
        out[:, 2 * h - 1] = (2.0 / N) * (np.cos(2 * np.pi * h * k / N) @ x)
        out[:, 2 * h] = (2.0 / N) * (np.sin(2 * np.pi * h * k / N) @ x)
    return out


def loop_area(u: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Closed trapezoidal integral of F du over one period, per column, J."""
    du = np.roll(u, -1, axis=0) - u
    Fm = 0.5 * (np.roll(F, -1, axis=0) + F)
    return np.sum(Fm * du, axis=0)


class State(NamedTuple):
    """Integrator state: DOFs (m or rad), their rates and accelerations."""

    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray


def linear_start(system, freq_hz: float) -> State:
    """State (q, q', q'') at phase 0 of the steady response of the linearised system
    (mounts at k1 and c, friction sliders free): a good start for slow transients."""
    omega = 2.0 * math.pi * freq_hz
    K, C = system.linearized(stuck=False)
    Kb, Cb = system.linearized_base(stuck=False)
    exc = system.excitation
    if exc.kind == "base":
        rhs = (Kb + 1j * omega * Cb) @ np.asarray(exc.amplitude, dtype=float)
    else:
        rhs = np.asarray(exc.force_amplitude(omega), dtype=complex)
    A = K - omega ** 2 * system.M + 1j * omega * C
    mx = maxwell_axes(system)
    if mx is not None:   # the Maxwell branches' complex stiffness (hbm.maxwell)
        Km = mx.stiffness(omega)
        A = A + mx.B.T @ (Km[:, None] * mx.B)
        if exc.kind == "base":
            rhs = rhs + mx.B.T @ (Km * (mx.G @ np.asarray(exc.amplitude, float)))
    hy = hydraulic_axes(system)
    if hy is not None:   # the hydraulic fluid's complex stiffness (hbm.hydraulic)
        Kh = hy.stiffness(omega)
        A = A + hy.B.T @ (Kh[:, None] * hy.B)
        if exc.kind == "base":
            rhs = rhs + hy.B.T @ (Kh * (hy.G @ np.asarray(exc.amplitude, float)))
    try:
        X = np.linalg.solve(A, rhs)
    except np.linalg.LinAlgError:
        n = system.n_dof
        return State(np.zeros(n), np.zeros(n), np.zeros(n))
    return State(X.imag.copy(), omega * X.real, -omega ** 2 * X.imag)


class OrbitStart(NamedTuple):
    """Start of a run on a harmonic-balance orbit: the DOFs, their rates and
    accelerations at phase 0 (m or rad, absolute as the master's ``q``) and the
    friction elements' states there, ``{(mount index, axis index): state}``
    (:func:`orbit_start`)."""

    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    elements: dict


def orbit_start(system, coefficients, freq_hz: float, n_samples: int) -> OrbitStart:
    """The :class:`OrbitStart` of the HBM solution ``coefficients`` (n_dof, 2H+1;
    one row of :attr:`hbm.result.FrequencyResponse.coefficients`, computed with
    ``n_samples`` AFT samples) at ``freq_hz``.

    The DOFs follow from the Fourier series at t = 0; the inclined elements' states
    from their periodic march on the orbit (:func:`hbm.inclined.
    orbit_element_states`): where one of their surfaces sticks for the whole period
    the orbit is one member of a family, and only its stuck slider tells which. The
    other friction elements keep the master's sliders (their amplitude does not
    depend on them)."""
    from drymount.hbm.inclined import orbit_element_states
    from drymount.hbm.residual import HarmonicBalance

    c = np.asarray(coefficients, dtype=float)
    if c.ndim != 2 or c.shape[0] != system.n_dof or c.shape[1] % 2 != 1 \
            or not np.all(np.isfinite(c)):
        raise ValueError(f"`coefficients` must be finite with shape ({system.n_dof}, "
                         f"2H+1), got shape {c.shape}")
    H = (c.shape[1] - 1) // 2
    omega = 2.0 * math.pi * float(freq_hz)
    k = np.arange(1, H + 1)
    cos, sin = c[:, 1::2], c[:, 2::2]
    q = c[:, 0] + cos.sum(axis=1)
    qd = omega * (sin @ k)
    qdd = -omega ** 2 * (cos @ (k * k))
    hb = HarmonicBalance(system, H, int(n_samples))
    return OrbitStart(q, qd, qdd, orbit_element_states(hb, c.T.ravel()))


def _transmissibility(system, omega, amp_q, phasor_F_axes, axis_index) -> float:
    tr = system.transmissibility
    if tr.kind == "force":
        total = 0j
        for (e, j) in tr.forces:
            i = axis_index.get((e, j))
            if i is not None:
                total = total + phasor_F_axes[i]
        den = system.excitation.scalar_amplitude(omega)
        return abs(total) / den if den > 0 else float("nan")
    if tr.reference is not None:
        den = amp_q[tr.reference]
    else:
        den = system.excitation.scalar_amplitude(omega)
    return float(amp_q[tr.dof] / den) if den > 0 else float("nan")


def check_convergence_settings(rtol, min_periods: int, max_periods: int) -> None:
    """ValueError naming the argument unless ``rtol > 0`` and
    ``1 <= min_periods <= max_periods`` (integers)."""
    if not (isinstance(rtol, (int, float)) and rtol > 0):
        raise ValueError(f"`rtol` must be > 0, got {rtol!r}")
    if not (isinstance(min_periods, int) and isinstance(max_periods, int)
            and 1 <= min_periods <= max_periods):
        raise ValueError(f"`min_periods`, `max_periods` must be integers with "
                         f"1 <= min_periods <= max_periods, got {min_periods!r}, "
                         f"{max_periods!r}")


def run_steady(master: Master, freq_hz: float, *,
               steps_per_period: int | None = None, rtol: float = DEFAULT_RTOL,
               min_periods: int = DEFAULT_MIN_PERIODS,
               max_periods: int = DEFAULT_MAX_PERIODS, start="continue"
               ) -> SteadyState:
    """Run ``master`` at ``freq_hz`` until the period-to-period change < ``rtol``.

    ``start``: ``"continue"`` (the master's current state and sliders), ``"rest"``,
    ``"linear"`` (:func:`linear_start`; sliders kept), a :class:`SteadyState`
    (its end state and sliders) or an :class:`OrbitStart` (on an HBM orbit,
    :func:`orbit_start`; the in-process backend where it sets element states).
    See the module docstring for the outputs.
    """
    if not (isinstance(freq_hz, (int, float, np.floating)) and math.isfinite(freq_hz)
            and freq_hz > 0):
        raise ValueError(f"`freq_hz` must be finite and > 0, got {freq_hz!r}")
    freq_hz = float(freq_hz)
    check_convergence_settings(rtol, min_periods, max_periods)
    N, h, E_start = _begin(master, freq_hz, steps_per_period, start)
    steps0 = master.backend.steps
    wall0 = master.wall_time
    change = math.inf
    converged = False
    for _ in range(max_periods):
        period = master.run_period()
        change = _period_change(period)
        if period.index >= min_periods and change <= rtol:
            converged = True
            break
        if period.index < max_periods:
            E_start = period.energy
    return _analyse(master, period, freq_hz, h, E_start, change, converged, rtol,
                    steps0, wall0)


def _begin(master: Master, freq_hz: float, steps_per_period, start):
    """Set the start state of a run at ``freq_hz`` and begin its periods (see
    :func:`run_steady`); returns ``(N, h, E_start)``."""
    system = master.system
    spp = DEFAULT_STEPS_PER_PERIOD if steps_per_period is None else steps_per_period
    N = master.steps_per_period(freq_hz, spp)
    h = 1.0 / (freq_hz * N)
    n = system.n_dof
    # committed friction energy before the run (read before new sliders are set: the
    # FMU's E_fr output includes the trial dissipation of the current inputs)
    E_start = master.backend.energy()
    if isinstance(start, SteadyState):
        master.set_state(start.q_end, start.qd_end, start.qdd_end, start.sliders)
    elif isinstance(start, OrbitStart):  # on a harmonic-balance orbit
        master.set_state(start.q, start.qd, start.qdd, elements=start.elements)
    elif start == "rest":  # at rest at the static working point (0 if unloaded)
        master.set_state(master.q_static, np.zeros(n), np.zeros(n))
    elif start == "linear":
        q, qd, qdd = linear_start(system, freq_hz)
        master.set_state(q + master.q_static, qd, qdd)
    elif start != "continue":
        raise ValueError(f"`start` must be 'continue', 'rest', 'linear', a "
                         f"SteadyState or an OrbitStart, got {start!r}")
    master.begin_periodic(HarmonicInput(system, freq_hz), N, h)
    return N, h, E_start


def _period_change(period) -> float:
    """Relative change of the state over one period (module docstring)."""
    q_scale = float(np.abs(period.q).max())
    v_scale = float(np.abs(period.qd).max())
    dq = float(np.abs(period.q_end - period.q[0]).max())
    dv = float(np.abs(period.qd_end - period.qd[0]).max())
    return max(dq / q_scale if q_scale > 0 else (0.0 if dq == 0 else math.inf),
               dv / v_scale if v_scale > 0 else (0.0 if dv == 0 else math.inf))


def _analyse(master: Master, period, freq_hz: float, h: float, E_start, change: float,
             converged: bool, rtol: float, steps0: int, wall0: float) -> SteadyState:
    """The :class:`SteadyState` of the last period ``period``."""
    system, L = master.system, master.layout
    N, n_periods = period.q.shape[0], period.index
    omega = 2.0 * math.pi * freq_hz
    q, F, Ffr, u = period.q, period.forces, period.friction_forces, period.deflections
    X = fundamental(q)
    XF = fundamental(F) if L.m else np.zeros(0, dtype=complex)
    axis_index = {(e, j): i for (i, e, j) in L.axes()}
    amp = np.abs(X)
    tr = _transmissibility(system, omega, amp, XF, axis_index)
    msg = (f"converged after {n_periods} periods (change {change:.2e})" if converged
           else f"not converged after {n_periods} periods: change {change:.2e} > "
                f"rtol {rtol:.1e}")
    return SteadyState(
        freq_hz=freq_hz, omega=omega, dt=h, steps_per_period=N, n_periods=n_periods,
        converged=converged, change=change, dof_names=tuple(system.dof_names),
        axis_labels=tuple(system.axis_labels()), phasor=X, amplitude=amp,
        peak=np.abs(q).max(axis=0), mean=q.mean(axis=0), transmissibility=tr,
        force_amplitude=np.abs(XF),
        friction_energy=float(np.sum(period.energy - E_start)),
        loop_area=float(np.sum(loop_area(u, Ffr))) if L.m else 0.0,
        t=np.arange(N) * h, q=q, qd=period.qd, forces=F, friction_forces=Ffr,
        deflections=u, q_end=master.q.copy(), qd_end=master.qd.copy(),
        qdd_end=master.qdd.copy(), sliders=master.sliders(), time=master.time,
        backend=master.backend_name, n_steps=master.backend.steps - steps0,
        wall_time=master.wall_time - wall0, message=msg)


def steady_state(system, freq_hz: float, *, backend: str = "inproc",
                 steps_per_period: int | None = None, rtol: float = DEFAULT_RTOL,
                 min_periods: int = DEFAULT_MIN_PERIODS,
                 max_periods: int = DEFAULT_MAX_PERIODS, start="linear",
                 fmu_path=None, fmu_start_values=None) -> SteadyState:
    """Periodic steady state of ``system`` under its harmonic excitation at
    ``freq_hz`` (see the module docstring).

    Parameters
    ----------
    system : hbm.system.System
    freq_hz : float
        Excitation frequency, Hz.
    backend : {"inproc", "fmu"}
    steps_per_period : int, optional
        Least steps per period (default 256; more if the step limit demands).
    rtol : float
        Tolerance on the relative period-to-period change (default 1e-5).
    min_periods, max_periods : int
    start : {"linear", "rest"}, SteadyState or OrbitStart
        Initial state: the linearised system's steady response (default; sliders at
        zero), rest, the end of a previous steady state (state and sliders), or an
        HBM orbit (:func:`orbit_start`).
    fmu_path : path-like, optional

    Returns
    -------
    SteadyState

    Examples
    --------
    >>> from drymount.fmu_src.mount_law import AxisParameters, MountParameters
    >>> from drymount.hbm.systems import sdof
    >>> s = sdof(70.0, MountParameters.from_axial(AxisParameters(law="linear")),
    ...          "unbalance", 0.01)
    >>> ss = steady_state(s, 5.0, backend="inproc")
    >>> bool(ss.converged)
    True
    """
    if start == "continue":
        start = "rest"
    with Master(system, backend, fmu_path=fmu_path,
                fmu_start_values=fmu_start_values) as m:
        return run_steady(m, freq_hz, steps_per_period=steps_per_period, rtol=rtol,
                          min_periods=min_periods, max_periods=max_periods,
                          start=start)
