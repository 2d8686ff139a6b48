"""Linear, rate-dependent mount elements in closed form: Maxwell branches and the
hydraulic (inertia-track + decoupler) mount. The law layer's frequency-domain truth,
imported by the HBM, ``characterise`` and the fitting code. Standard library only.

Conventions (those of the mount law): ``u`` is the mount's deflection (m), ``v`` its
rate (m/s) and the force ``F`` (N) the one the mount exerts against ``u`` (a
restoring force: positive for a positive deflection of a spring). A harmonic
deflection ``u(t) = Re(U exp(j omega t))`` gives, at steady state, the force
``Re(K*(omega) U exp(j omega t))``: ``K*`` is the complex (dynamic) stiffness, N/m,
``K' = Re K*`` the storage and ``K'' = Im K*`` the loss stiffness, the loss angle
``atan2(K'', K')``.

Maxwell branches
----------------
A Maxwell branch is a spring ``k_i`` (N/m) in series with a damper ``c_i`` (N s/m),
the branch as a whole in parallel with the mount's elastic law. Its internal
coordinate ``w_i`` (the damper's stroke, m) obeys

    c_i dw_i/dt = k_i (u - w_i),      F_i = k_i (u - w_i) = c_i dw_i/dt.

With ``u = U exp(j omega t)``: ``W_i = k_i U / (k_i + j omega c_i)`` and

    K*_i(omega) = k_i j omega c_i / (k_i + j omega c_i)
               = k_i (omega tau_i)^2 / (1 + (omega tau_i)^2)
                 + j k_i omega tau_i / (1 + (omega tau_i)^2),   tau_i = c_i / k_i,

a storage stiffness rising from 0 (a Maxwell branch carries no static force) to
``k_i`` and a loss stiffness peaking at ``k_i / 2`` at ``omega = 1 / tau_i``. A
branch with ``k_i = 0`` is absent (contributes nothing); ``c_i = 0`` with
``k_i > 0`` is a spring in series with nothing, also no force. Branches add:
:func:`maxwell_complex_stiffness`.

Hydraulic mount (linear inertia-track + decoupler model)
--------------------------------------------------------
The lumped model of Flower (1985, SAE 850975), in the form of Singh, Kim & Ravindra
(1992, J. Sound Vib. 158(2), 219-243) and Kim & Singh (1993, ASME J. Dyn. Sys.
Meas. Control 115, 482-487; 1995, J. Sound Vib. 179(3), 427-453); Geisberger,
Khajepour & Golnaraghi (2002, Int. J. Vehicle Design 29(1/2)) identify the same
lumped parameters on a production mount. The main rubber (stiffness ``kr`` N/m,
damping ``br`` N s/m) carries the load and acts as a piston of effective area
``Ap`` (m^2) on the upper chamber (compliance ``C1``, m^5/N, pressure ``p1`` Pa
above the static level). Fluid flows from the upper to the lower chamber
(compliance ``C2``, pressure ``p2``) through two parallel passages: the inertia
track (fluid inertia ``I_i`` kg/m^4, resistance ``R_i`` N s/m^5, flow ``q_i``
m^3/s) and the decoupler (``I_d``, ``R_d``, ``q_d``; in the linear model the
decoupler is a second, short and wide, fluid passage: its gap's amplitude limit is
the nonlinear effect this model leaves out). Continuity of each chamber and the
momentum balance of each passage:

    C1 dp1/dt = Ap du/dt - q_i - q_d          (the piston displaces Ap du)
    C2 dp2/dt = q_i + q_d
    I_i dq_i/dt + R_i q_i = p1 - p2
    I_d dq_d/dt + R_d q_d = p1 - p2
    F = kr u + br du/dt + Ap p1               (rubber plus the pressure on Ap)

Frequency domain (all quantities ``X exp(j omega t)``). The passages' impedances
``Z_i = R_i + j omega I_i``, ``Z_d = R_d + j omega I_d`` act in parallel,
``Q = (P1 - P2) / Z`` with ``Z = Z_i Z_d / (Z_i + Z_d)``. The lower chamber gives
``P2 = Q / (j omega C2)``, hence ``P1 = Q (Z + 1 / (j omega C2))``; the upper
chamber, ``j omega C1 P1 = j omega Ap U - Q``. Eliminating ``Q``:

    P1 / U = Ap (1 + j omega C2 Z) / (C1 + C2 + j omega C1 C2 Z)

(multiply the upper-chamber balance by ``C2 / (1 + j omega C2 Z)``), and

    K*(omega) = kr + j omega br + Ap^2 (1 + j omega C2 Z) / (C1 + C2 + j omega C1 C2 Z).

Checks: omega -> 0 (``Z`` finite): ``K* -> kr + Ap^2 / (C1 + C2)``, the static
stiffness of the rubber and the two chambers' compliances in series with the piston
(the chambers equalise: ``p1 = p2 = Ap u / (C1 + C2)``). omega -> inf (``Z`` ~ j
omega I, the passages blocked by their inertia): ``K* -> kr + j omega br + Ap^2 /
C1``, the fluid locked in the upper chamber.

The notch and the peak. Lossless passages (``R_i = R_d = br = 0``) have ``Z = j
omega I`` with the parallel inertia ``I = I_i I_d / (I_i + I_d)`` (``I = I_i``
without the decoupler), and

    K*(omega) = kr + Ap^2 (1 - omega^2 I C2) / (C1 + C2 - omega^2 I C1 C2),

real: it has a pole (the fluid column's resonance between the two compliances in
series, the peak of ``|K*|`` and of the loss angle) at

    omega_p^2 = (C1 + C2) / (I C1 C2)

and a zero (the notch of ``|K*|``, the mount's anti-resonance, below the peak) at

    omega_n^2 = (kr (C1 + C2) + Ap^2) / (I C2 (kr C1 + Ap^2)).

(:func:`hydraulic_notch_peak`.) Small resistances move them by second order in the
damping. With the decoupler present (``I_d < I_i``) the parallel inertia is small
and both move up: the decoupler bypasses the inertia track at small amplitudes,
which is what it is for. The model is exactly linear: ``characterise`` and the HBM
use :func:`hydraulic_complex_stiffness` per harmonic; the time march uses the same
equations (four states ``p1, p2, q_i, q_d``; the FMU keeps them as its state).

Parameter conventions of :class:`HydraulicParameters`: all finite and ``>= 0``;
``Ap > 0``, ``C1 > 0``, ``C2 > 0``, ``I_i > 0`` (a fluid mount needs a piston, two
compliant chambers and an inertia track); ``I_d = 0`` means no decoupler (its
``R_d`` is then not used), otherwise ``I_d > 0``.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from typing import NamedTuple

__all__ = ["maxwell_complex_stiffness", "HydraulicParameters", "HYDRAULIC_FIELDS",
           "check_hydraulic", "hydraulic_complex_stiffness", "hydraulic_notch_peak",
           "MAX_MAXWELL", "maxwell_step", "FLUID_STATE", "fluid_matrices",
           "fluid_propagator", "fluid_relaxed", "fluid_step"]


def _is_seq(x) -> bool:
    return isinstance(x, Iterable) and not isinstance(x, (str, bytes))


def _finite(name: str, value, rule: str) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} = {value!r}: must be a number, {rule}") from None
    if not math.isfinite(x):
        raise ValueError(f"{name} = {value!r}: must be finite, {rule}")
    return x


def _maxwell_one(k: Sequence[float], c: Sequence[float], omega: float) -> complex:
    total = 0j
    for ki, ci in zip(k, c):
        if ki == 0.0 or ci == 0.0:
            continue
        jwc = 1j * omega * ci
        total += ki * jwc / (ki + jwc)
    return total


def maxwell_complex_stiffness(k, c, omega):
    """Complex stiffness (N/m) of Maxwell branches in parallel.

    ``sum_i k_i j omega c_i / (k_i + j omega c_i)``; a branch with ``k_i = 0`` (or
    ``c_i = 0``) contributes nothing (see the module docstring).

    Parameters
    ----------
    k, c : sequence of float
        The branches' spring stiffnesses (N/m) and damping coefficients (N s/m),
        same length, each finite and >= 0.
    omega : float or sequence of float
        Circular frequency (rad/s), or several.

    Returns
    -------
    complex, or list of complex (one per ``omega``) when ``omega`` is a sequence.
    """
    k = [_finite(f"maxwell k[{i}]", x, "finite and >= 0") for i, x in enumerate(k)]
    c = [_finite(f"maxwell c[{i}]", x, "finite and >= 0") for i, x in enumerate(c)]
    if len(k) != len(c):
        raise ValueError(f"maxwell k has {len(k)} entries and c has {len(c)}: "
                         "one (k, c) pair per branch")
    for name, vals in (("k", k), ("c", c)):
        for i, x in enumerate(vals):
            if x < 0.0:
                raise ValueError(f"maxwell {name}[{i}] = {x!r}: must be >= 0")
    if _is_seq(omega):
        return [_maxwell_one(k, c, float(w)) for w in omega]
    return _maxwell_one(k, c, float(omega))


class HydraulicParameters(NamedTuple):
    """The linear hydraulic mount (module docstring): SI units.

    kr : main rubber stiffness, N/m
    br : main rubber damping, N s/m
    Ap : effective piston area of the main rubber, m^2
    C1 : upper chamber compliance, m^5/N
    C2 : lower chamber compliance, m^5/N
    I_i : inertia-track fluid inertia, kg/m^4
    R_i : inertia-track resistance, N s/m^5
    I_d : decoupler fluid inertia, kg/m^4 (0: no decoupler)
    R_d : decoupler resistance, N s/m^5
    """

    kr: float
    br: float
    Ap: float
    C1: float
    C2: float
    I_i: float
    R_i: float
    I_d: float = 0.0
    R_d: float = 0.0


HYDRAULIC_FIELDS: tuple[tuple[str, str, str], ...] = (
    ("kr", "N/m", "main rubber stiffness"),
    ("br", "N.s/m", "main rubber damping"),
    ("Ap", "m2", "effective piston area of the main rubber"),
    ("C1", "m5/N", "upper chamber compliance"),
    ("C2", "m5/N", "lower chamber compliance"),
    ("I_i", "kg/m4", "inertia-track fluid inertia"),
    ("R_i", "N.s/m5", "inertia-track flow resistance"),
    ("I_d", "kg/m4", "decoupler fluid inertia (0: no decoupler)"),
    ("R_d", "N.s/m5", "decoupler flow resistance"),
)
"""``(field, unit, description)`` of each :class:`HydraulicParameters` field."""

_POSITIVE = ("Ap", "C1", "C2", "I_i")


def check_hydraulic(p: HydraulicParameters) -> HydraulicParameters:
    """``p`` with float fields, or ValueError naming the field, value and rule."""
    vals = {}
    for name, _unit, _desc in HYDRAULIC_FIELDS:
        rule = "finite and > 0" if name in _POSITIVE else "finite and >= 0"
        x = _finite(f"hydraulic {name}", getattr(p, name), rule)
        if x < 0.0 or (name in _POSITIVE and x == 0.0):
            raise ValueError(f"hydraulic {name} = {x!r}: must be {rule[11:]}")
        vals[name] = x
    return HydraulicParameters(**vals)


def _passage_impedance(p: HydraulicParameters, omega: float) -> complex:
    """Impedance Z (Pa s/m^3) of the inertia track in parallel with the decoupler."""
    zi = complex(p.R_i, omega * p.I_i)
    if p.I_d == 0.0:
        return zi
    zd = complex(p.R_d, omega * p.I_d)
    s = zi + zd
    return 0j if s == 0 else zi * zd / s


def _hydraulic_one(p: HydraulicParameters, omega: float) -> complex:
    z = _passage_impedance(p, omega)
    jw = 1j * omega
    fluid = p.Ap * p.Ap * (1.0 + jw * p.C2 * z) / (p.C1 + p.C2 + jw * p.C1 * p.C2 * z)
    return p.kr + jw * p.br + fluid


def hydraulic_complex_stiffness(params: HydraulicParameters, omega):
    """Complex stiffness (N/m) of the linear hydraulic mount (module docstring):

    ``kr + j omega br + Ap^2 (1 + j omega C2 Z) / (C1 + C2 + j omega C1 C2 Z)``,
    ``Z`` the inertia track's impedance ``R_i + j omega I_i`` in parallel with the
    decoupler's ``R_d + j omega I_d``.

    Parameters
    ----------
    params : HydraulicParameters
    omega : float or sequence of float
        Circular frequency (rad/s), or several.

    Returns
    -------
    complex, or list of complex (one per ``omega``) when ``omega`` is a sequence.
    """
    p = check_hydraulic(params)
    if _is_seq(omega):
        return [_hydraulic_one(p, float(w)) for w in omega]
    return _hydraulic_one(p, float(omega))


def hydraulic_notch_peak(params: HydraulicParameters) -> tuple[float, float]:
    """``(omega_n, omega_p)`` (rad/s): the notch and the peak of ``|K*|`` of the
    lossless mount (``R_i = R_d = br = 0``; module docstring), the parallel inertia
    of the two passages in place of ``I``."""
    p = check_hydraulic(params)
    inertia = p.I_i if p.I_d == 0.0 else p.I_i * p.I_d / (p.I_i + p.I_d)
    c1, c2, ap2 = p.C1, p.C2, p.Ap * p.Ap
    wp2 = (c1 + c2) / (inertia * c1 * c2)
    wn2 = (p.kr * (c1 + c2) + ap2) / (inertia * c2 * (p.kr * c1 + ap2))
    return math.sqrt(wn2), math.sqrt(wp2)



# --------------------------------------------------------------------------------------
# Time domain: the exact step of a Maxwell branch
# --------------------------------------------------------------------------------------

#: Maxwell branches per mount axis in the FMU (fields ``maxwell_k1..3``,
#: ``maxwell_c1..3``; a branch with ``k = 0`` or ``c = 0`` is absent).
MAX_MAXWELL = 3


def maxwell_step(k: float, c: float, uc: float, w0: float, u: float,
                 dt: float) -> tuple[float, float, float]:
    """One increment of a Maxwell branch, exact for the linear ODE.

    The branch's damper stroke ``w`` obeys ``c dw/dt = k (u(t) - w)``; over the
    increment of ``dt`` seconds the deflection moves linearly from the committed
    ``uc`` to ``u`` (the FMU's inputs are the end-of-step values, the path between
    two communication points a straight line, as the friction elements read it).
    With ``tau = c / k``, ``x = dt / tau``, ``e = exp(-x)`` the exact solution is

        w(dt) = u - (u - uc) (1 - e) / x + (w0 - uc) e

    and the force ``F = k (u - w) = k ((uc - w0) e + (u - uc) (1 - e) / x)``, its
    tangent ``dF/du = k (1 - e) / x`` (``1 - e`` by ``expm1``: exact also for
    ``x`` near 0). ``dt = 0`` is a jump (the damper does not move: ``F = k (u -
    w0)``, ``dF/du = k``). An absent branch (``k = 0`` or ``c = 0``) carries no force
    and follows ``u``.

    Returns ``(F, w, dF/du)``.
    """
    if k == 0.0 or c == 0.0:
        return 0.0, u, 0.0
    if dt <= 0.0:
        return k * (u - w0), w0, k
    x = dt * k / c
    g = -math.expm1(-x)            # 1 - e
    e = 1.0 - g
    ratio = g / x                  # (1 - e) / x
    f = k * ((uc - w0) * e + (u - uc) * ratio)
    return f, u - f / k, k * ratio


# --------------------------------------------------------------------------------------
# Time domain: the exact step of the hydraulic mount's fluid (the axis steps it,
# mount_law._fluid_step; the native C port is fmu_src/native/hydraulic.c)
# --------------------------------------------------------------------------------------

#: Floats of the fluid state: ``x1 = C1 p1 - Ap u`` (m^3, the upper chamber's volume
#: change less the piston's), ``p2`` (Pa), ``q_i``, ``q_d`` (m^3/s).
FLUID_STATE = 4


def fluid_matrices(p: HydraulicParameters):
    """``(A, b)`` of the fluid states ``x = (x1, p2, q_i, q_d)`` (:data:`FLUID_STATE`),
    ``dx/dt = A x + b u``: with ``p1 = (x1 + Ap u) / C1`` the module docstring's
    equations read ``dx1/dt = -q_i - q_d``, ``dp2/dt = (q_i + q_d) / C2``,
    ``I dq/dt = p1 - p2 - R q`` per passage (no decoupler, ``I_d = 0``: ``q_d``
    stays 0)."""
    a = [[0.0, 0.0, -1.0, -1.0],
         [0.0, 0.0, 1.0 / p.C2, 1.0 / p.C2],
         [1.0 / (p.C1 * p.I_i), -1.0 / p.I_i, -p.R_i / p.I_i, 0.0],
         [0.0, 0.0, 0.0, 0.0]]
    b = [0.0, 0.0, p.Ap / (p.C1 * p.I_i), 0.0]
    if p.I_d > 0.0:
        a[3] = [1.0 / (p.C1 * p.I_d), -1.0 / p.I_d, 0.0, -p.R_d / p.I_d]
        b[3] = p.Ap / (p.C1 * p.I_d)
    else:
        a[0][3] = a[1][3] = 0.0
    return a, b


def _matmul(x, y):
    n = len(x)
    return [[math.fsum(x[i][k] * y[k][j] for k in range(n)) for j in range(n)]
            for i in range(n)]


def _expm(m):
    """exp(m) of a small square matrix (lists): power-of-two balancing (exact), then
    scaling and squaring of an 18-term Taylor series at norm <= 1/4 (truncation
    below 1e-25 relative)."""
    n = len(m)
    d = [1.0] * n
    a = [row[:] for row in m]
    for _ in range(20):   # Parlett-Reinsch balancing with powers of two
        done = True
        for i in range(n):
            c = math.fsum(abs(a[k][i]) for k in range(n) if k != i)
            r = math.fsum(abs(a[i][k]) for k in range(n) if k != i)
            if c == 0.0 or r == 0.0:
                continue
            f = 1.0
            while c < r / 2.0:
                c, r, f = c * 2.0, r / 2.0, f * 2.0
            while c > r * 2.0:
                c, r, f = c / 2.0, r * 2.0, f / 2.0
            if f != 1.0:
                done = False
                d[i] *= f
                for k in range(n):
                    a[i][k] /= f
                    a[k][i] *= f
        if done:
            break
    norm = max(math.fsum(abs(x) for x in row) for row in a)
    s = 0
    while norm > 0.25:
        norm /= 2.0
        s += 1
    scale = 2.0 ** -s
    a = [[x * scale for x in row] for row in a]
    out = [[1.0 if i == j else 0.0 for j in range(n)] for i in range(n)]
    term = [row[:] for row in out]
    for k in range(1, 19):
        term = _matmul(term, a)
        term = [[x / k for x in row] for row in term]
        out = [[out[i][j] + term[i][j] for j in range(n)] for i in range(n)]
    for _ in range(s):
        out = _matmul(out, out)
    # undo the balancing: exp(D^-1 M D) = D^-1 exp(M) D with a = D^-1 m D
    return [[out[i][j] * d[i] / d[j] for j in range(n)] for i in range(n)]


def fluid_propagator(p: HydraulicParameters, dt: float):
    """``(Phi, g0, g1)`` of one step of ``dt`` seconds: with the deflection linear in
    time from ``uc`` to ``u`` (rate ``r = (u - uc) / dt``) the fluid state goes to
    ``x = Phi x0 + g0 uc + g1 r`` exactly (the exponential of the augmented system
    ``d(x, u, r)/dt = (A x + b u, r, 0)``)."""
    a, b = fluid_matrices(p)
    n = FLUID_STATE
    m = [[0.0] * (n + 2) for _ in range(n + 2)]
    for i in range(n):
        for j in range(n):
            m[i][j] = a[i][j] * dt
        m[i][n] = b[i] * dt
    m[n][n + 1] = dt
    e = _expm(m)
    phi = [row[:n] for row in e[:n]]
    g0 = [e[i][n] for i in range(n)]
    g1 = [e[i][n + 1] for i in range(n)]   # the coefficient of the rate r
    return phi, g0, g1


def fluid_relaxed(p: HydraulicParameters, u: float) -> tuple[float, ...]:
    """The fluid at rest at the deflection ``u``: no flow, both chambers at
    ``p = Ap u / (C1 + C2)``, so ``x1 = C1 p - Ap u``."""
    pr = p.Ap * u / (p.C1 + p.C2)
    return (p.C1 * pr - p.Ap * u, pr, 0.0, 0.0)


def fluid_step(p: HydraulicParameters, prop, x0, uc: float, u: float, dt: float):
    """One increment of the fluid (``prop``: :func:`fluid_propagator` of ``dt``, None
    at ``dt = 0``, a jump: the fluid does not move). Returns ``(F, x, dF/du)``: the
    pressure force ``Ap p1 = Ap (x1 + Ap u) / C1`` on the piston, the new state, and
    its tangent."""
    ap, c1 = p.Ap, p.C1
    if prop is None or dt <= 0.0:
        x = tuple(x0)
        return ap * (x[0] + ap * u) / c1, x, ap * ap / c1
    phi, g0, g1 = prop
    r = (u - uc) / dt
    x = tuple(math.fsum((phi[i][0] * x0[0], phi[i][1] * x0[1], phi[i][2] * x0[2],
                         phi[i][3] * x0[3], g0[i] * uc, g1[i] * r))
              for i in range(FLUID_STATE))
    f = ap * (x[0] + ap * u) / c1
    return f, x, ap * (ap + g1[0] / dt) / c1
