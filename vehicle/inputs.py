"""Time-domain inputs of the vehicle harness: engine forces and base (road) motion.

Every input is an object with

    force(t)          -> (n_dof,)  generalised force on the DOFs, N or N m
    base(t)           -> (n_base,) base (chassis or road) displacement y, m
    base_velocity(t)  -> (n_base,) its rate y', m/s

that enters the equations of motion of :mod:`hbm.system`

    M q'' + C q' + K q + sum_e B_e^T F_e = f(t) + K_b y + C_b y'.

``t`` may be a float or an array of shape (n_t,) (the result then gains a leading
axis of length n_t). The harness always evaluates inputs on the grid ``t0 + k*dt``
(integer ``k``), never on an accumulated time.

Inputs
------
:class:`HarmonicInput`
    The system's own harmonic excitation (``hbm.system.Excitation``: force,
    unbalance ``f0 omega^2``, or base) at one frequency.
:class:`CrankInput`
    Inertia force and roll moment of an inline four-cylinder engine (thesis eq. 1.3).
:class:`SineRoad`, :class:`SweptSineRoad`, :class:`BumpRoad`, :class:`RandomRoad`
    Road (base) displacement: sine, swept sine, a (1 - cos) bump, and a random road of
    an ISO 8608 class at a vehicle speed.
:class:`BaseSine`
    Mount base displacement sine of the 6-DOF study (0.0035 m, thesis Sec. 4.5).
:class:`SumInput`
    Sum of several inputs.

Examples
--------
>>> from drymount.fmu_src.mount_law import AxisParameters, MountParameters
>>> from drymount.hbm.systems import quarter_car
>>> mount = MountParameters.from_axial(AxisParameters(law="linear"))
>>> qc = quarter_car(70, 230, 30, 15000, 1000, 200000, 0, mount, 0.01)
>>> road = RandomRoad(qc, "C", speed=20.0, seed=1)
>>> road.base([0.0, 0.01]).shape
(2, 1)
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from drymount.hbm.crank import DEFAULT_ENGINE, CrankMechanism

__all__ = [
    "Input",
    "HarmonicInput",
    "CrankInput",
    "CrankRunUp",
    "SineRoad",
    "SweptSineRoad",
    "BumpRoad",
    "RandomRoad",
    "SuspendedRoad",
    "BaseSine",
    "SumInput",
    "ISO8608_CLASSES",
    "iso8608_gd0",
]

#: ISO 8608 road classes; Gd(n0) of class k (A = 1) is 16e-6 * 4**(k - 1) m^3.
ISO8608_CLASSES = "ABCDEFGH"
#: Reference spatial frequency of ISO 8608, cycles/m.
ISO8608_N0 = 0.1


def iso8608_gd0(road_class: str) -> float:
    """Displacement PSD Gd(n0) in m^3 (n0 = 0.1 cycles/m) of an ISO 8608 class.

    The geometric mean of the class band: 16e-6 m^3 for A, times 4 per class
    (B 64e-6, C 256e-6, ..., H 262 144e-6 m^3).
    """
    if not isinstance(road_class, str) or road_class.upper() not in ISO8608_CLASSES \
            or len(road_class) != 1:
        raise ValueError(f"`road_class` must be one of A-H, got {road_class!r}")
    k = ISO8608_CLASSES.index(road_class.upper()) + 1
    return 16e-6 * 4.0 ** (k - 1)


def _finite(value, name, *, positive=False, nonneg=False) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"`{name}` must be a number, got {value!r}") from None
    if not math.isfinite(x) or (positive and x <= 0) or (nonneg and x < 0):
        rule = " and > 0" if positive else (" and >= 0" if nonneg else "")
        raise ValueError(f"`{name}` must be finite{rule}, got {value!r}")
    return x


def _dof_index(system, dof, name) -> int:
    names = list(system.dof_names)
    if isinstance(dof, str):
        if dof not in names:
            raise ValueError(f"`{name}` must be one of {names}, got {dof!r}")
        return names.index(dof)
    if isinstance(dof, (int, np.integer)) and 0 <= dof < len(names):
        return int(dof)
    raise ValueError(f"`{name}` must be a DOF name in {names} or an index "
                     f"0..{len(names) - 1}, got {dof!r}")


def _direction(system, direction) -> np.ndarray:
    """Unit base direction (n_base,): given, the only base, or ``chassis_z``."""
    nb = system.n_base
    if nb == 0:
        raise ValueError(f"system {system.name!r} has no base (chassis/road) input; "
                         "a base-displacement input needs one")
    if direction is None:
        if nb == 1:
            return np.ones(1)
        if "chassis_z" in system.base_names:
            d = np.zeros(nb)
            d[list(system.base_names).index("chassis_z")] = 1.0
            return d
        raise ValueError(f"`direction` must be given for a system with {nb} base "
                         f"inputs {list(system.base_names)}")
    d = np.asarray(direction, dtype=float)
    if d.shape != (nb,) or not np.all(np.isfinite(d)) or not np.any(d):
        raise ValueError(f"`direction` must be {nb} finite values, not all zero, "
                         f"got {np.asarray(direction).tolist()}")
    return d


class Input:
    """Base class: zero force and zero base motion for a system's sizes.

    Subclasses override :meth:`_force` and/or :meth:`_base` (vectorised over a 1-D
    array of times). ``period`` is the repetition period in s, or None.
    """

    period: float | None = None

    def __init__(self, system):
        self.n_dof = system.n_dof
        self.n_base = system.n_base

    # -- subclass hooks, t: 1-D array ------------------------------------------
    def _force(self, t: np.ndarray) -> np.ndarray:
        return np.zeros((t.size, self.n_dof))

    def _base(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        z = np.zeros((t.size, self.n_base))
        return z, z.copy()

    # -- public API --------------------------------------------------------------
    @staticmethod
    def _grid(t):
        ta = np.asarray(t, dtype=float)
        return ta.reshape(-1), ta.ndim == 0

    def force(self, t) -> np.ndarray:
        """Generalised force f(t), shape (n_dof,) or (n_t, n_dof), N or N m."""
        ta, scalar = self._grid(t)
        out = self._force(ta)
        return out[0] if scalar else out

    def base(self, t) -> np.ndarray:
        """Base displacement y(t), shape (n_base,) or (n_t, n_base), m."""
        ta, scalar = self._grid(t)
        out = self._base(ta)[0]
        return out[0] if scalar else out

    def base_velocity(self, t) -> np.ndarray:
        """Base velocity y'(t), shape (n_base,) or (n_t, n_base), m/s."""
        ta, scalar = self._grid(t)
        out = self._base(ta)[1]
        return out[0] if scalar else out

    def evaluate(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(force, base, base_velocity)`` on a 1-D array of times."""
        ta, _ = self._grid(t)
        y, yd = self._base(ta)
        return self._force(ta), y, yd


class HarmonicInput(Input):
    """The system's harmonic excitation (``system.excitation``) at ``freq_hz``.

    Sine convention of :mod:`hbm.system`: force ``F sin(omega t)``, unbalance
    ``omega^2 U sin(omega t)`` (thesis eq. 4.2), base ``Y sin(omega t)`` with velocity
    ``omega Y cos(omega t)``.

    Parameters
    ----------
    system : hbm.system.System
    freq_hz : float
        Excitation frequency, Hz (> 0).
    excitation : hbm.system.Excitation, optional
        Overrides ``system.excitation``.
    """

    def __init__(self, system, freq_hz: float, excitation=None):
        super().__init__(system)
        self.freq_hz = _finite(freq_hz, "freq_hz", positive=True)
        self.omega = 2.0 * math.pi * self.freq_hz
        self.period = 1.0 / self.freq_hz
        exc = system.excitation if excitation is None else excitation
        self.kind = exc.kind
        if exc.kind == "base":
            self._Y = np.asarray(exc.amplitude, dtype=float).reshape(self.n_base)
            self._F = np.zeros(self.n_dof)
        else:
            self._F = np.asarray(exc.force_amplitude(self.omega), dtype=float
                                 ).reshape(self.n_dof)
            self._Y = np.zeros(self.n_base)

    def _force(self, t):
        return np.sin(self.omega * t)[:, None] * self._F[None, :]

    def _base(self, t):
        wt = self.omega * t
        return (np.sin(wt)[:, None] * self._Y[None, :],
                (self.omega * np.cos(wt))[:, None] * self._Y[None, :])


class CrankInput(Input):
    """Inertia excitation of an inline four-cylinder engine at ``speed_rpm``.

    The crank model is :class:`hbm.crank.CrankMechanism` (thesis eq. 1.3), the one the
    studies use too: with crank speed ``w`` and cranks at 0, 180, 180, 0 degrees the
    odd orders cancel and

        F_z(t)  = 4 m_rec R w^2 (A2 cos 2wt - A4 cos 4wt),   A2 = R/l, A4 = R^3/(4 l^3)
        M(t)    = m_rec R^2 w^2 (2 sin 2wt + lambda^2 sin 4wt),   lambda = R/l

    ``M`` is the roll moment on the engine block, the reaction to the inertia torque
    of the four reciprocating masses on the crankshaft. 600-6000 rpm give 20-200 Hz of
    second order.

    Parameters
    ----------
    system : hbm.system.System
    speed_rpm : float
        Crankshaft speed, rev/min (> 0).
    m_rec, R, l : float or None
        Reciprocating mass per cylinder (kg), crank radius (m) and connecting-rod
        length (m); None takes the value of ``engine``.
    engine : hbm.crank.CrankMechanism, optional
        Default :data:`hbm.crank.DEFAULT_ENGINE` (0.5 kg, 40.75 mm, 130 mm: a 1.6 l
        inline four, the project's documented engine; the thesis gives no values).
    force_dof, moment_dof : str or int or None
        DOF receiving the vertical force (default ``z``, else ``engine``, else DOF 0)
        and the roll moment (default ``beta``, the roll axis PHYSICS.md names for the
        6-DOF model, if present, else none). Pass ``moment_dof="alpha"`` for a
        crankshaft along x.
    """

    def __init__(self, system, speed_rpm: float, *, m_rec: float | None = None,
                 R: float | None = None, l: float | None = None,  # noqa: E741
                 engine: CrankMechanism | None = None, force_dof=None,
                 moment_dof=None):
        super().__init__(system)
        self.speed_rpm = _finite(speed_rpm, "speed_rpm", positive=True)
        base = DEFAULT_ENGINE if engine is None else engine
        self.engine = CrankMechanism(
            m_rec=base.m_rec if m_rec is None else m_rec,
            crank_radius=base.crank_radius if R is None else R,
            rod_length=base.rod_length if l is None else l)
        self.m_rec = self.engine.m_rec
        self.R = self.engine.crank_radius
        self.l = self.engine.rod_length
        self.A2, self.A4 = self.engine.a2, self.engine.a4
        names = list(system.dof_names)
        if force_dof is None:
            force_dof = "z" if "z" in names else ("engine" if "engine" in names else 0)
        self.force_dof = _dof_index(system, force_dof, "force_dof")
        if moment_dof is None and "beta" in names:
            moment_dof = "beta"
        self.moment_dof = (None if moment_dof is None
                           else _dof_index(system, moment_dof, "moment_dof"))
        self.omega = 2.0 * math.pi * self.speed_rpm / 60.0
        self.period = 2.0 * math.pi / (2.0 * self.omega)  # second-order period

    @property
    def second_order_hz(self) -> float:
        """Frequency of the dominant (second) order, Hz."""
        return 2.0 * self.speed_rpm / 60.0

    def _force(self, t):
        th = self.omega * t
        out = np.zeros((t.size, self.n_dof))
        out[:, self.force_dof] += self.engine.force(th, self.omega)
        if self.moment_dof is not None:
            out[:, self.moment_dof] += self.engine.roll_moment(th, self.omega)
        return out


class CrankRunUp(CrankInput):
    """The crank excitation of :class:`CrankInput` over a linear engine run-up.

    The crank speed rises linearly from ``rpm_start`` to ``rpm_end`` over
    ``duration`` s and stays there; the crank angle is its integral,
    ``theta(t) = 2 pi / 60 (rpm_start t + (rpm_end - rpm_start) t^2 / (2 duration))``,
    and the load is eq. 1.3 at the instantaneous speed (quasi-steady: the crank's
    angular acceleration adds a term of relative size ``dw/dt / w^2``, below 1e-3 for
    a run-up of more than 0.3 s from 600 rpm).
    """

    def __init__(self, system, rpm_start: float = 600.0, rpm_end: float = 6000.0,
                 duration: float = 10.0, **kw):
        super().__init__(system, rpm_start, **kw)
        self.rpm_start = self.speed_rpm
        self.rpm_end = _finite(rpm_end, "rpm_end", positive=True)
        self.duration = _finite(duration, "duration", positive=True)
        self.period = None

    def speed(self, t) -> np.ndarray:
        """Crank speed at ``t``, rev/min."""
        tc = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        return self.rpm_start + (self.rpm_end - self.rpm_start) * tc / self.duration

    def second_order(self, t) -> np.ndarray:
        """Frequency of the second engine order at ``t``, Hz."""
        return 2.0 * self.speed(t) / 60.0

    def _force(self, t):
        T, r0, r1 = self.duration, self.rpm_start, self.rpm_end
        tc = np.minimum(t, T)
        revs = (r0 * tc + (r1 - r0) * tc * tc / (2.0 * T)
                + r1 * np.maximum(t - T, 0.0)) / 60.0
        th = 2.0 * math.pi * revs
        w = 2.0 * math.pi * self.speed(t) / 60.0
        out = np.zeros((t.size, self.n_dof))
        out[:, self.force_dof] += self.engine.force(th, w)
        if self.moment_dof is not None:
            out[:, self.moment_dof] += self.engine.roll_moment(th, w)
        return out


class _RoadInput(Input):
    """Scalar profile r(t) applied along a base ``direction``."""

    def __init__(self, system, direction=None):
        super().__init__(system)
        self.direction = _direction(system, direction)

    def _profile(self, t) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError

    def _base(self, t):
        r, rd = self._profile(t)
        d = self.direction[None, :]
        return r[:, None] * d, rd[:, None] * d


class SineRoad(_RoadInput):
    """Road (base) displacement ``amplitude * sin(2 pi freq_hz t + phase)``, m."""

    def __init__(self, system, amplitude: float, freq_hz: float, *, phase: float = 0.0,
                 direction=None):
        super().__init__(system, direction)
        self.amplitude = _finite(amplitude, "amplitude")
        self.freq_hz = _finite(freq_hz, "freq_hz", positive=True)
        self.phase = _finite(phase, "phase")
        self.omega = 2.0 * math.pi * self.freq_hz
        self.period = 1.0 / self.freq_hz

    def _profile(self, t):
        ph = self.omega * t + self.phase
        return self.amplitude * np.sin(ph), self.amplitude * self.omega * np.cos(ph)


class BaseSine(SineRoad):
    """Mount base displacement sine of the 6-DOF study: ``0.0035 m * sin(omega t)``
    along ``direction`` (default: the only base, or ``chassis_z``; thesis Sec. 4.5)."""

    def __init__(self, system, freq_hz: float, amplitude: float = 0.0035, *,
                 direction=None):
        super().__init__(system, amplitude, freq_hz, direction=direction)


class SweptSineRoad(_RoadInput):
    """Swept-sine road ``amplitude * sin(phi(t))`` from ``f_start_hz`` to ``f_end_hz``.

    ``spacing="linear"``: ``phi = 2 pi (f0 t + (f1 - f0) t^2 / (2 T))``;
    ``spacing="log"``: ``phi = 2 pi f0 T / ln(f1/f0) (exp(t ln(f1/f0) / T) - 1)``.
    For ``t < 0`` the road is flat; for ``t > duration`` the sweep continues at
    ``f_end_hz`` with a continuous phase.
    """

    def __init__(self, system, amplitude: float, f_start_hz: float, f_end_hz: float,
                 duration: float, *, spacing: str = "linear", direction=None):
        super().__init__(system, direction)
        self.amplitude = _finite(amplitude, "amplitude")
        self.f0 = _finite(f_start_hz, "f_start_hz", positive=True)
        self.f1 = _finite(f_end_hz, "f_end_hz", positive=True)
        self.duration = _finite(duration, "duration", positive=True)
        if spacing not in ("linear", "log"):
            raise ValueError(f"`spacing` must be 'linear' or 'log', got {spacing!r}")
        if spacing == "log" and self.f0 == self.f1:
            spacing = "linear"
        self.spacing = spacing

    def frequency(self, t) -> np.ndarray:
        """Instantaneous frequency in Hz at ``t`` (clipped to the sweep)."""
        tc = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        if self.spacing == "linear":
            return self.f0 + (self.f1 - self.f0) * tc / self.duration
        return self.f0 * np.exp(tc * math.log(self.f1 / self.f0) / self.duration)

    def _phase(self, tc):
        T = self.duration
        if self.spacing == "linear":
            return 2.0 * math.pi * (self.f0 * tc
                                    + (self.f1 - self.f0) * tc ** 2 / (2 * T))
        g = math.log(self.f1 / self.f0)
        return 2.0 * math.pi * self.f0 * T / g * np.expm1(tc * g / T)

    def _profile(self, t):
        tc = np.clip(t, 0.0, self.duration)
        phi = self._phase(tc) + 2.0 * math.pi * self.f1 * np.maximum(t - self.duration,
                                                                     0.0)
        rate = 2.0 * math.pi * self.frequency(t)
        on = t >= 0.0
        return (np.where(on, self.amplitude * np.sin(phi), 0.0),
                np.where(on, self.amplitude * rate * np.cos(phi), 0.0))


class BumpRoad(_RoadInput):
    """A single (1 - cos) bump crossed at constant speed (the "half-cosine" bump).

    ``r(s) = height/2 (1 - cos(2 pi s / length))`` for ``0 <= s <= length`` with
    ``s = speed (t - t_start)``, zero elsewhere: the profile and its slope are
    continuous.
    """

    def __init__(self, system, height: float, length: float, speed: float, *,
                 t_start: float = 0.0, direction=None):
        super().__init__(system, direction)
        self.height = _finite(height, "height")
        self.length = _finite(length, "length", positive=True)
        self.speed = _finite(speed, "speed", positive=True)
        self.t_start = _finite(t_start, "t_start")

    def _profile(self, t):
        s = self.speed * (t - self.t_start)
        on = (s >= 0.0) & (s <= self.length)
        k = 2.0 * math.pi / self.length
        r = np.where(on, 0.5 * self.height * (1.0 - np.cos(k * s)), 0.0)
        rd = np.where(on, 0.5 * self.height * k * self.speed * np.sin(k * s), 0.0)
        return r, rd


class RandomRoad(_RoadInput):
    """Random road of an ISO 8608 class at a constant vehicle ``speed``.

    Displacement PSD ``Gd(n) = Gd(n0) (n / n0)^-2`` (waviness w = 2, n0 = 0.1
    cycles/m, ``Gd(n0) = 16e-6 * 4^(k-1)`` m^3 for class k = 1 (A) .. 8 (H)),
    synthesised as a sum of cosines with independent uniform random phases:

        r(s) = sum_i a_i cos(2 pi n_i s + phi_i),   a_i = sqrt(2 Gd(n_i) dn)

    with ``n_waves`` spatial frequencies ``n_i`` at the centres of equal bands ``dn =
    (n_max - n_min) / n_waves`` covering ``n_min``-``n_max`` (default 0.011-2.83
    cycles/m, ISO 8608's range; the centres are integer multiples of ``dn``, so the
    band ``band`` is shifted from the nominal one by less than ``dn / 2``):
    ``var r = sum a_i^2 / 2`` is the midpoint rule of the integral of Gd over
    ``band``. The profile is periodic with period ``1 / dn`` m (178 m with the
    defaults). ``s = speed t``.

    Parameters
    ----------
    system : hbm.system.System
    road_class : str
        ``"A"`` .. ``"H"``.
    speed : float
        Vehicle speed, m/s (> 0).
    seed : int
        Seed of ``numpy.random.default_rng`` for the phases (same seed, same road).
    """

    def __init__(self, system, road_class: str, speed: float, *, seed: int = 0,
                 n_min: float = 0.011, n_max: float = 2.83, n_waves: int = 500,
                 direction=None):
        super().__init__(system, direction)
        self.road_class = road_class.upper() if isinstance(road_class, str) \
            else road_class
        self.gd0 = iso8608_gd0(road_class)
        self.speed = _finite(speed, "speed", positive=True)
        self.n_min = _finite(n_min, "n_min", positive=True)
        self.n_max = _finite(n_max, "n_max", positive=True)
        if self.n_max <= self.n_min:
            raise ValueError(f"`n_max` must be > `n_min`, got {n_max!r} <= {n_min!r}")
        if not isinstance(n_waves, (int, np.integer)) or n_waves < 1:
            raise ValueError(f"`n_waves` must be an integer >= 1, got {n_waves!r}")
        if not isinstance(seed, (int, np.integer)):
            raise ValueError(f"`seed` must be an integer, got {seed!r}")
        self.seed = int(seed)
        dn = (self.n_max - self.n_min) / n_waves
        k0 = max(1, round(self.n_min / dn))
        # integer multiples of dn: the profile is periodic with period 1 / dn
        self.n = (k0 + np.arange(n_waves)) * dn
        self.dn = dn
        #: band covered by the midpoint rule, cycles/m
        self.band = ((k0 - 0.5) * dn, (k0 + n_waves - 0.5) * dn)
        self.amplitudes = np.sqrt(2.0 * self.psd(self.n) * dn)
        self.phases = np.random.default_rng(self.seed).uniform(0.0, 2.0 * math.pi,
                                                               n_waves)

    def psd(self, n) -> np.ndarray:
        """ISO 8608 displacement PSD Gd(n), m^3, at spatial frequencies n, cycles/m."""
        n = np.asarray(n, dtype=float)
        return self.gd0 * (n / ISO8608_N0) ** -2.0

    @property
    def variance(self) -> float:
        """Variance of the synthesised profile, m^2 (sum a_i^2 / 2)."""
        return float(np.sum(self.amplitudes ** 2) / 2.0)

    def _profile(self, t, chunk: int = 2048):
        r = np.empty(t.size)
        rd = np.empty(t.size)
        w = 2.0 * math.pi * self.n * self.speed  # temporal circular frequencies
        for i in range(0, t.size, chunk):
            ph = np.outer(t[i:i + chunk], w) + self.phases
            r[i:i + chunk] = np.cos(ph) @ self.amplitudes
            rd[i:i + chunk] = -(np.sin(ph) @ (self.amplitudes * w))
        return r, rd


class SuspendedRoad(RandomRoad):
    """A :class:`RandomRoad` seen through a quarter-car suspension: the chassis
    displacement under each attachment point.

    Body model (documented choice, issue 26 item 3): every chassis attachment point
    moves as the sprung mass of a quarter car on the same road (the
    ``quarter_car_halved`` suspension by default: sprung mass ``m_s`` plus the
    engine's share ``m_e``, unsprung ``m_us``, ``k_s``, ``c_s``, tyre ``k_t``,
    ``c_t``), all in phase (no wheelbase delay, no body pitch or roll), and the
    engine's dynamic reaction on the body is neglected (one-way). The profile is a
    sum of cosines, so the filter is exact: each wave is scaled and shifted by the
    suspension's road-to-body transfer function ``H(i w)`` at its frequency ``w``.
    """

    def __init__(self, system, road_class: str, speed: float, *, seed: int = 0,
                 m_s: float = 300.0, m_us: float = 30.0, k_s: float = 15000.0,
                 c_s: float = 1000.0, k_t: float = 200000.0, c_t: float = 0.0,
                 **kw):
        super().__init__(system, road_class, speed, seed=seed, **kw)
        vals = {}
        for name, value in (("m_s", m_s), ("m_us", m_us), ("k_s", k_s), ("c_s", c_s),
                            ("k_t", k_t), ("c_t", c_t)):
            vals[name] = _finite(value, name, positive=name not in ("c_s", "c_t"))
        self.suspension = vals
        w = 2.0 * math.pi * self.n * self.speed
        h = self.body_transfer(w)
        self.amplitudes = self.amplitudes * np.abs(h)
        self.phases = self.phases + np.angle(h)

    def body_transfer(self, w) -> np.ndarray:
        """Road-to-body displacement ``H(i w)`` of the quarter-car suspension."""
        p = self.suspension
        iw = 1j * np.asarray(w, dtype=float)
        ks = p["k_s"] + p["c_s"] * iw
        kt = p["k_t"] + p["c_t"] * iw
        a11 = ks - p["m_s"] * np.abs(iw) ** 2
        a22 = ks + kt - p["m_us"] * np.abs(iw) ** 2
        # [a11 -ks; -ks a22] [zs; zu] = [0; kt r]
        return ks * kt / (a11 * a22 - ks * ks)


class SumInput(Input):
    """Sum of inputs of the same system (e.g. crank excitation plus a random road)."""

    def __init__(self, inputs: Sequence[Input]):
        inputs = list(inputs)
        if not inputs:
            raise ValueError("`inputs` must hold at least one input")
        shapes = {(i.n_dof, i.n_base) for i in inputs}
        if len(shapes) != 1:
            raise ValueError(
                f"`inputs` must share (n_dof, n_base), got {sorted(shapes)}")
        self.n_dof, self.n_base = shapes.pop()
        self.inputs = inputs
        periods = {i.period for i in inputs}
        self.period = periods.pop() if len(periods) == 1 else None

    def _force(self, t):
        return sum(i._force(t) for i in self.inputs)

    def _base(self, t):
        parts = [i._base(t) for i in self.inputs]
        return sum(p[0] for p in parts), sum(p[1] for p in parts)
