"""Inclined two-surface friction element of thesis Chapter 5 (Fig. 5.4, eq. 5.1-5.10).

Standard library only (ships inside the FMU). The derivation, the sign conventions and
the corrections to the printed equations are in docs/physics.md ("Inclined
two-surface friction element").

Quarter model, inertia ignored. The engine-side part ("red") moves by ``x`` along the
mount axis (positive = into the wedge). It touches the wedge ("blue") on a surface
inclined at ``theta`` to the plate; the wedge slides on the flat plate ("turquoise",
chassis side) and is pushed towards the red part by springs of stiffness ``k`` with a
preload ``P`` at ``x = 0``. With ``s, c = sin(theta), cos(theta)``:

    a  = x c / s           wedge travel (eq. 5.4), rigid contact in the normal direction
    d1 = x / s             relative slide on the inclined surface (eq. 5.5-5.6 fixed)
    f1 = kf  (d1 - w1)     stuck, |f1| <= mu1 N        (eq. 5.7 with a slider w1)
    f2 = kf2 (a  - w2)     stuck, |f2| <= mu2 N2       (eq. 5.8 with a slider w2)
    f1 = +-mu1 N, f2 = +-mu2 N2 while slipping         (eq. 5.9, 5.10 with the sign)
    N  = (c f1 + f2 + k a + P) / s                     (eq. 5.3 solved, with P)
    N2 = (f1 + c (f2 + k a + P)) / s  = F              (eq. 5.1 = eq. 5.2)

In each stick/slip combination every force is affine in ``x``. The exact return map
(:func:`inclined_update`) walks a monotonic increment from regime to regime: it finds
the deflection at which a stuck surface reaches its slip limit, switches regime there
and continues (a slipping surface re-sticks when its slip rate would reverse, which
the regime choice at each event handles). ``mu = inf`` makes a surface bonded.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

__all__ = ["InclinedParameters", "InclinedStep", "ContactLost", "inclined_update",
           "inclined_forces", "InclinedState", "relaxed_state", "relaxed_force",
           "stuck_stiffness", "step_derivatives", "INCLINED_FIELDS", "axis_step",
           "axis_normal_forces"]

#: The element's parameters as fields of a mount axis (``fmu_src.mount_law.
#: AxisParameters``): the axis's ``kf`` is the inclined surface's contact stiffness.
INCLINED_FIELDS = ("theta_deg", "k", "kf", "kf2", "mu1", "mu2", "preload")

_MAX_EVENTS = 64
_REL_TOL = 1e-12
#: at-limit slack in units of a contact force's rounding kf * ulp(x)
_RES_ULPS, _EPS = 64.0, 2.220446049250313e-16


class ContactLost(ValueError):
    """The motion asks for a negative normal force (a surface would lift off)."""


def _num(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and not math.isnan(x)


@dataclass(frozen=True)
class InclinedParameters:
    """Parameters of the inclined two-surface element (SI units, ``theta_deg`` in deg).

    Attributes
    ----------
    theta_deg : float
        Angle of the inclined surface to the plate, degrees, in (0, 90].
    k : float
        Stiffness of the elastic pieces pushing the wedge, N/m, >= 0.
    kf, kf2 : float
        Tangential contact stiffness of the inclined and of the flat surface, N/m, > 0.
    mu1, mu2 : float
        Friction coefficients, >= 0 (``math.inf``: the surface is bonded).
    preload : float
        Force of the elastic pieces at x = 0, N, >= 0.
    """

    theta_deg: float = 60.0
    k: float = 20000.0
    kf: float = 60000.0
    kf2: float = 60000.0
    mu1: float = 0.3
    mu2: float = 0.3
    preload: float = 200.0

    def __post_init__(self):
        problems = self.problems()
        if problems:
            raise ValueError("invalid inclined element: " + "; ".join(problems))

    def problems(self, prefix: str = "") -> list[str]:
        """Every problem, each naming the field, its value and the rule."""
        out = []
        rules = (("theta_deg", lambda v: 0 < v <= 90, "in (0, 90] degrees"),
                 ("k", lambda v: 0 <= v < math.inf, "finite and >= 0"),
                 ("kf", lambda v: 0 < v < math.inf, "finite and > 0"),
                 ("kf2", lambda v: 0 < v < math.inf, "finite and > 0"),
                 ("mu1", lambda v: v >= 0, ">= 0 (inf = bonded)"),
                 ("mu2", lambda v: v >= 0, ">= 0 (inf = bonded)"),
                 ("preload", lambda v: 0 <= v < math.inf, "finite and >= 0"))
        for name, ok, rule in rules:
            value = getattr(self, name)
            if not (_num(value) and ok(value)):
                out.append(f"`{prefix}{name}` must be {rule}, got {value!r}")
        if not out:
            worst = self.self_locking_margin()
            if worst <= 1e-9:
                out.append(f"`{prefix}theta_deg` = {self.theta_deg!r} self-locks the "
                           f"wedge with mu1 = {self.mu1!r}, mu2 = {self.mu2!r} (the "
                           f"normal force of a slipping regime has determinant "
                           f"{worst:.3g} <= 0): increase theta or lower mu1/mu2")
        return out

    @property
    def sc(self) -> tuple[float, float]:
        """``(sin theta, cos theta)``; cos is exactly 0 at 90 degrees."""
        if self.theta_deg == 90:
            return 1.0, 0.0
        t = math.radians(self.theta_deg)
        return math.sin(t), math.cos(t)

    def self_locking_margin(self) -> float:
        """Smallest determinant of the slipping regimes' systems (must be > 0)."""
        s, c = self.sc
        dets = []
        m1 = 0.0 if math.isinf(self.mu1) else self.mu1   # a bonded surface never slips
        m2 = 0.0 if math.isinf(self.mu2) else self.mu2
        for sig1 in (1, -1):
            for sig2 in (1, -1):
                d1 = s - sig1 * m1 * c
                d2 = s - sig2 * m2 * c
                dets += [d1, d2, d1 * d2 - sig1 * sig2 * m1 * m2]
        return min(dets)


class InclinedStep(NamedTuple):
    """State after a deflection increment of :func:`inclined_update`.

    ``force`` the element's force along the mount axis (N, = N2), ``f1``/``f2`` the
    friction forces (N), ``n1``/``n2`` the normal forces N and N2 (N), ``w1``/``w2``
    the slider positions (m), ``slip1``/``slip2`` whether each surface slips at the
    end, ``tangent`` dF/dx at the end (N/m, in the direction of the increment),
    ``dissipated`` the friction energy of the increment (J).
    """

    force: float
    f1: float
    f2: float
    n1: float
    n2: float
    w1: float
    w2: float
    slip1: bool
    slip2: bool
    tangent: float
    dissipated: float


def _solve(x, w1, w2, reg, p, s, c):
    """Forces ``(f1, f2, N, N2)`` at ``x`` in regime ``reg`` = (sig1, sig2); sig 0 =
    stuck. Rows: stuck ``f_i = g_i``; slipping ``f1 = sig1 mu1 N``, ``f2 = sig2 mu2
    N2`` with ``N = (c f1 + f2 + q)/s``, ``N2 = (f1 + c f2 + c q)/s``."""
    q = p.k * x * c / s + p.preload
    sig1, sig2 = reg
    if sig1 == 0:
        a11, a12, b1 = 1.0, 0.0, p.kf * (x / s - w1)
    else:
        m = sig1 * p.mu1
        a11, a12, b1 = s - m * c, -m, m * q
    if sig2 == 0:
        a21, a22, b2 = 0.0, 1.0, p.kf2 * (x * c / s - w2)
    else:
        m = sig2 * p.mu2
        a21, a22, b2 = -m, s - m * c, m * c * q
    det = a11 * a22 - a12 * a21
    f1 = (b1 * a22 - a12 * b2) / det
    f2 = (a11 * b2 - a21 * b1) / det
    return f1, f2, (c * f1 + f2 + q) / s, (f1 + c * f2 + c * q) / s


def inclined_forces(x: float, w1: float, w2: float, p: InclinedParameters,
                    reg=(0, 0)) -> tuple[float, float, float, float]:
    """Forces ``(f1, f2, N, N2)`` at ``x`` in a given regime (both stuck by default)."""
    s, c = p.sc
    return _solve(x, w1, w2, reg, p, s, c)


_SLOPES: dict = {}


def _affine(x, w1, w2, reg, p, s, c):
    """Values at ``x`` and slopes d/dx of ``(f1, f2, N, N2)`` in regime ``reg``."""
    v0 = _solve(x, w1, w2, reg, p, s, c)
    # the sliders only shift the intercept: slopes from the pair x = 0, 1 with w = 0,
    # constants of (parameters, regime), computed once (the same floats every time)
    key = (p, reg)
    slopes = _SLOPES.get(key)
    if slopes is None:
        if len(_SLOPES) > 4096:   # many designs in one process: start over
            _SLOPES.clear()
        v0z = _solve(0.0, 0.0, 0.0, reg, p, s, c)
        v1z = _solve(1.0, 0.0, 0.0, reg, p, s, c)
        slopes = _SLOPES[key] = tuple(b - a for a, b in zip(v0z, v1z))
    return v0, slopes


def _consistent(vals, slopes, reg, at_limit, d, p, s, c) -> bool:
    """Whether regime ``reg`` can continue from a point with forces ``vals`` in
    direction ``d`` (+1/-1)."""
    f1, f2, n1, n2 = vals
    df1, df2, dn1, dn2 = slopes
    for i, (f, df, n, dn, mu, kfi, da) in enumerate((
            (f1, df1, n1, dn1, p.mu1, p.kf, 1.0 / s),
            (f2, df2, n2, dn2, p.mu2, p.kf2, c / s))):
        sig = reg[i]
        if sig == 0:
            if at_limit[i]:
                g = 1.0 if f >= 0 else -1.0
                if d * (g * df - mu * dn) > 1e-9 * (abs(df) + mu * abs(dn) + 1e-30):
                    return False
        else:
            dw = da - df / kfi
            if d * sig * dw < -1e-12 * (abs(da) + abs(df) / kfi):
                return False
    return True


def _choose(x, w1, w2, d, p, s, c):
    """The regime that continues from ``x`` (committed sliders) in direction ``d``."""
    vals = _solve(x, w1, w2, (0, 0), p, s, c)
    f1, f2, n1, n2 = vals
    lim = (p.mu1 * n1, p.mu2 * n2)
    at_limit = []
    # within rounding of the element's force scale (the friction forces are computed
    # from spring forces of that size: a normal force near 0 makes L tiny, not exact)
    scale = abs(f1) + abs(f2) + p.preload
    # ... and within the resolution of a contact force kf (x/s - w): kf ulp(x), which
    # exceeds the relative tolerance for stiff contacts (kf = 1e9 N/m: issue 26)
    res = (p.kf * (abs(x / s) + abs(w1)), p.kf2 * (abs(x * c / s) + abs(w2)))
    for f, L, r in zip((f1, f2), lim, res):
        tol = max(_REL_TOL * max(abs(f), abs(L), scale, 1e-9), _RES_ULPS * _EPS * r)
        at_limit.append(not math.isinf(L) and abs(f) >= L - tol)
    options = [(0,), (0,)]
    for i, f in enumerate((f1, f2)):
        if at_limit[i]:
            options[i] = (0, 1 if f >= 0 else -1)
    for reg in ((a, b) for a in options[0] for b in options[1]):
        slopes = _affine(x, w1, w2, reg, p, s, c)[1]
        if _consistent(vals, slopes, reg, at_limit, d, p, s, c):
            return reg
    raise ContactLost(f"no consistent stick/slip state at x = {x!r} m "
                      f"(N = {n1:.6g} N, N2 = {n2:.6g} N)")


def _sliders(x, vals, reg, w1, w2, p, s, c):
    f1, f2 = vals[0], vals[1]
    if reg[0]:
        w1 = x / s - f1 / p.kf
    if reg[1]:
        w2 = x * c / s - f2 / p.kf2
    return w1, w2


def _next_event(x, x1, d, vals, slopes, reg, p):
    """First deflection between x and x1 where a stuck surface reaches its limit."""
    best = x1
    for i, mu in ((0, p.mu1), (1, p.mu2)):
        if reg[i] or math.isinf(mu):
            continue
        f, df = vals[i], slopes[i]
        n, dn = vals[2 + i], slopes[2 + i]
        for g in (1.0, -1.0):
            phi, dphi = g * f - mu * n, g * df - mu * dn   # <= 0 while stuck
            if d * dphi > 0:
                xe = x - phi / dphi
                if (xe - best) * d < 0:
                    best = xe if (xe - x) * d > 0 else x
    return best


def inclined_update(x: float, x_old: float, w1: float, w2: float,
                    p: InclinedParameters) -> InclinedStep:
    """Exact return map of the element from ``x_old`` to ``x`` (monotonic inside).

    ``w1``, ``w2`` are the committed sliders at ``x_old``. Raises
    :class:`ContactLost` when the motion needs N < 0 or N2 < 0 on a surface that
    can slip.
    """
    s, c = p.sc
    d = 1.0 if x >= x_old else -1.0
    xc, diss = x_old, 0.0
    reg = (0, 0)
    for _ in range(_MAX_EVENTS):
        reg = _choose(xc, w1, w2, d, p, s, c)
        vals, slopes = _affine(xc, w1, w2, reg, p, s, c)
        xe = _next_event(xc, x, d, vals, slopes, reg, p)
        end = _solve(xe, w1, w2, reg, p, s, c)
        _check_contact(xe, end, p)
        nw1, nw2 = _sliders(xe, end, reg, w1, w2, p, s, c)
        # slip energy: f affine and w linear in x on the segment -> trapezoid exact
        diss += 0.5 * ((vals[0] + end[0]) * (nw1 - w1)
                       + (vals[1] + end[1]) * (nw2 - w2))
        w1, w2, xc = nw1, nw2, xe
        if xe == x:
            break
    else:
        raise ContactLost(f"more than {_MAX_EVENTS} stick/slip events between "
                          f"{x_old!r} and {x!r} m")
    f1, f2, n1, n2 = end
    tangent = slopes[3]
    return InclinedStep(n2, f1, f2, n1, n2, w1, w2, reg[0] != 0, reg[1] != 0,
                        tangent, diss)


def _check_contact(x, vals, p):
    f1, f2, n1, n2 = vals
    for name, n, mu in (("N", n1, p.mu1), ("N2", n2, p.mu2)):
        scale = abs(f1) + abs(f2) + p.preload + 1e-9
        if n < -_REL_TOL * scale and not math.isinf(mu):
            raise ContactLost(f"the inclined element loses contact at x = {x!r} m: "
                              f"{name} = {n:.6g} N < 0 (raise the preload or k)")


# --------------------------------------------------------------------------------------
# The element as the friction element of a mount axis (fmu_src.mount_law.axis_force):
# its state, the relaxed state at a deflection, and the derivatives of one increment.
#
# Sign convention on an axis: the element is pressed into the wedge when the mount is
# compressed, x = -u (u = engine minus chassis deflection along the axis, negative in
# compression), and it pushes the two sides apart, F = -N2 (a positive axis force is
# tension). With the axis pointing up from the chassis to the engine, the engine's
# weight presses the wedge in, as in the thesis's Fig. 5.4.
# --------------------------------------------------------------------------------------


class InclinedState(NamedTuple):
    """Committed state of the element on a mount axis: the sliders ``w1``, ``w2`` (m,
    element coordinates) and the committed axis deflection ``uc`` (m; the element's
    ``x = -uc``), where the next increment starts."""

    w1: float
    w2: float
    uc: float


def relaxed_state(p: InclinedParameters, u: float) -> InclinedState:
    """The element at axis deflection ``u`` (m) with both surfaces unloaded (f1 = f2
    = 0): ``w1 = x / sin``, ``w2 = x cos / sin``, ``x = -u``. The harness's one-number
    slider value of the axis (``w_<axis>``) is ``uc``; setting it relaxes the element
    there."""
    s, c = p.sc
    u = float(u)
    return InclinedState(-u / s, -u * c / s, u)


def relaxed_force(u: float, p: InclinedParameters) -> tuple[float, float]:
    """Axis force (N) and tangent dF/du (N/m) of the element relaxed at axis
    deflection ``u`` (f1 = f2 = 0): ``F = -N2 = -cos (k x cos / sin + P) / sin``,
    ``x = -u`` (eq. 5.1-5.3 with the sliders unloaded); the static working point's law
    (``hbm.static``)."""
    s, c = p.sc
    return -c * (-p.k * u * c / s + p.preload) / s, p.k * c * c / (s * s)


def axis_step(u: float, state: InclinedState, p: InclinedParameters
              ) -> tuple[InclinedStep, InclinedState]:
    """The element's increment on an axis from ``state`` to axis deflection ``u``:
    the :class:`InclinedStep` in element coordinates (``x = -u``; the axis force is
    ``-step.force``, its tangent dF/du is ``step.tangent``) and the new state."""
    st = inclined_update(-u, -state.uc, state.w1, state.w2, p)
    return st, InclinedState(st.w1, st.w2, u)


def axis_normal_forces(state: InclinedState, p: InclinedParameters
                       ) -> tuple[float, float]:
    """Normal forces ``(N, N2)`` in N of the element in ``state``: the stuck-regime
    forces at the committed deflection reproduce every regime's (a slipping surface's
    slider sits at ``d_i - f_i / kf_i``)."""
    _, _, n1, n2 = inclined_forces(-state.uc, state.w1, state.w2, p)
    return n1, n2


def stuck_stiffness(p: InclinedParameters) -> float:
    """dF/du with both surfaces stuck, N/m (the element's stiffest regime)."""
    s, c = p.sc
    return (_solve(1.0, 0.0, 0.0, (0, 0), p, s, c)[3]
            - _solve(0.0, 0.0, 0.0, (0, 0), p, s, c)[3])


def step_derivatives(x: float, x_old: float, w1: float, w2: float,
                     p: InclinedParameters, st: InclinedStep | None = None):
    """Derivatives of one increment of :func:`inclined_update`.

    Returns ``rows`` = ``(dF, dN, dw1, dw2)``, each a 4-tuple of the derivatives with
    respect to ``(x, x_old, w1, w2)`` (``F`` = N2 the force, ``N`` the inclined
    surface's normal force, ``w1``, ``w2`` the sliders after the increment).

    Exact: in the final stick/slip regime the forces are affine in ``x`` and the
    stuck surfaces' sliders (a slipping surface's slider only follows, ``w_i = d_i(x)
    - f_i / kf_i``), and where no surface re-sticks inside the increment a stuck
    surface's slider is its committed value, so nothing depends on ``x_old``. An
    increment in which a surface slips and re-sticks is differentiated by central
    differences of the map instead (the map is piecewise affine: exact unless an event
    lies within the difference step).
    """
    if st is None:
        st = inclined_update(x, x_old, w1, w2, p)
    reg = (1 if st.slip1 else 0, 1 if st.slip2 else 0)
    restuck = (not st.slip1 and st.w1 != w1) or (not st.slip2 and st.w2 != w2)
    if restuck:
        return _fd_derivatives(x, x_old, w1, w2, p)
    # regime signs only matter for slipping surfaces: take them from the end forces
    sreg = (0 if not reg[0] else (1 if st.f1 >= 0 else -1),
            0 if not reg[1] else (1 if st.f2 >= 0 else -1))
    return _regime_derivatives(p, sreg)


_REGIME_CACHE: dict = {}


def _regime_derivatives(p: InclinedParameters, sreg):
    """The rows of :func:`step_derivatives` in regime ``sreg``: constants of the
    regime (every force is affine there), computed once per (parameters, regime)."""
    key = (p, sreg)
    rows = _REGIME_CACHE.get(key)
    if rows is not None:
        return rows
    if len(_REGIME_CACHE) > 4096:   # many designs in one process: start over
        _REGIME_CACHE.clear()
    s, c = p.sc
    base = _solve(0.0, 0.0, 0.0, sreg, p, s, c)
    dx = [b - a for a, b in zip(base, _solve(1.0, 0.0, 0.0, sreg, p, s, c))]
    dw1 = ([b - a for a, b in zip(base, _solve(0.0, 1.0, 0.0, sreg, p, s, c))]
           if not sreg[0] else [0.0] * 4)
    dw2 = ([b - a for a, b in zip(base, _solve(0.0, 0.0, 1.0, sreg, p, s, c))]
           if not sreg[1] else [0.0] * 4)
    rows_f = [(dx[i], 0.0, dw1[i], dw2[i]) for i in range(4)]   # f1, f2, N, N2
    w_rows = []
    for i, (kfi, da) in enumerate(((p.kf, 1.0 / s), (p.kf2, c / s))):
        if sreg[i]:
            f = rows_f[i]
            w_rows.append((da - f[0] / kfi, 0.0, -f[2] / kfi, -f[3] / kfi))
        else:
            w_rows.append((0.0, 0.0, 1.0, 0.0) if i == 0 else (0.0, 0.0, 0.0, 1.0))
    rows = (rows_f[3], rows_f[2], w_rows[0], w_rows[1])
    _REGIME_CACHE[key] = rows
    return rows


def _fd_derivatives(x, x_old, w1, w2, p):
    """Central differences of the map (an increment with a re-stick event)."""
    args = [x, x_old, w1, w2]
    scale = max(abs(x), abs(x_old), abs(w1), abs(w2), 1e-6)
    h = 1e-7 * scale
    cols = []
    for j in range(4):
        hi, lo = list(args), list(args)
        hi[j] += h
        lo[j] -= h
        a = inclined_update(*hi, p)
        b = inclined_update(*lo, p)
        cols.append([(fa - fb) / (2 * h) for fa, fb in
                     zip((a.force, a.n1, a.w1, a.w2), (b.force, b.n1, b.w1, b.w2))])
    return tuple(tuple(cols[j][i] for j in range(4)) for i in range(4))
