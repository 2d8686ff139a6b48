"""The Jenkins friction element (``friction_kind = "jenkins"``): macro-slip,
non-symmetric and micro-slip (Iwan), thesis Sec. 2.2 and its future work (Sec. 6.2).

Macro-slip: a spring ``kf`` in series with a Coulomb slider of slip force
``Fs = mu * n`` (``n`` the normal force, ``n0`` unless the FMU's input sets it; a
negative one means lost contact, Fs = 0). Its state is the slider position ``w``; the
update for a displacement increment is the exact return map

    trial = kf (u_new - w);  if |trial| > Fs:  w = u_new - sign(trial) Fs / kf

(rate independent, exact when u is monotonic inside the increment; eq. 2.10-2.13). The
energy the slider dissipates in an increment is ``Fs * |w_new - w|``.

Non-symmetric friction (``fs_ratio``): the slider slips at ``+Fs`` in the positive and
at ``-fs_ratio * Fs`` in the negative direction (:func:`slider_update`).

Micro-slip (``sliders`` = S > 1): an Iwan element, S Jenkins elements in parallel,
fitted to the macro-slip element (kf, Fs): slider i = 0..S-1 has stiffness kf / S and
slip displacement eps_i = eps r_i, r_i = 1 + spread ((2 i + 1) / S - 1), so its slip
force is Fs r_i / S. The r_i are uniform on [1 - spread, 1 + spread] with mean 1: the
total stiffness is kf, the full-slip force is Fs, and spread = 0 is the macro-slip
element. Its state is the tuple of the S slider positions (:func:`iwan_update`).

The three variants are one registered element (:data:`JENKINS`) whose fields choose
the variant: :func:`_bind` picks the step once per parameter set. Standard library
only: this module ships inside the FMU.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from .friction import ElementStep, Field, FrictionElement, finite_rule

__all__ = ["JENKINS", "MAX_SLIDERS", "SliderStep", "jenkins_update", "slider_update",
           "contact_normal_forces",
           "slider_bank", "iwan_update"]

#: Largest number of sliders of a micro-slip (Iwan) element.
MAX_SLIDERS = 64

_new = tuple.__new__   # one C call per NamedTuple (mount_law._new)


class SliderStep(NamedTuple):
    """Return map of the macro-slip element (:func:`jenkins_update`)."""

    force: float
    w_new: float
    tangent: float
    slipping: bool


def jenkins_update(u: float, w: float, kf: float, fs: float) -> SliderStep:
    """Return map of the macro-slip element for a new deflection ``u``.

    Parameters
    ----------
    u : float
        Deflection across the element at the end of the increment, m.
    w : float
        Committed slider position, m.
    kf : float
        Contact stiffness, N/m (> 0).
    fs : float
        Slip force mu * n0, N (>= 0).

    Returns
    -------
    SliderStep
        ``(force, w_new, tangent, slipping)``: friction force in N, slider position
        after the increment in m, consistent tangent in N/m (kf when stuck, 0 when
        slipping) and whether it slips.

    Notes
    -----
    Exact whenever u is monotonic inside the increment (thesis eq. 2.10-2.13). It is
    :func:`slider_update` with ``fs_pos = fs_neg = fs`` (the same operations).
    """
    return slider_update(u, w, kf, fs, fs)


def slider_update(u: float, w: float, kf: float, fs_pos: float, fs_neg: float
                  ) -> SliderStep:
    """Return map of a Jenkins element with non-symmetric slip forces.

    As :func:`jenkins_update`, but the slider slips at ``+fs_pos`` when pulled in the
    positive direction and at ``-fs_neg`` in the negative one (both N, >= 0).
    """
    trial = kf * (u - w)
    if trial > fs_pos:
        return _new(SliderStep, (fs_pos, u - fs_pos / kf, 0.0, True))
    if trial < -fs_neg:
        return _new(SliderStep, (-fs_neg, u + fs_neg / kf, 0.0, True))
    return _new(SliderStep, (trial, w, kf, False))


def slider_bank(p, fs: float | None = None
                ) -> tuple[tuple[float, float, float], ...]:
    """``(k_i, fs_pos_i, fs_neg_i)`` of every slider of axis ``p``'s element.

    ``fs`` overrides the slip force ``mu n0`` (the normal-force input). One slider
    ``(kf, Fs, fs_ratio Fs)`` for the macro-slip element; for ``sliders`` = S > 1
    the Iwan fit of the module docstring: ``k_i = kf / S``, ``fs_pos_i = Fs r_i / S``.
    """
    if fs is None:
        fs = p.mu * p.n0
    n = p.sliders
    k = p.kf / n
    out = []
    for i in range(n):
        r = 1.0 + p.spread * ((2 * i + 1) / n - 1.0)
        out.append((k, fs * r / n, fs * r * p.fs_ratio / n))
    return tuple(out)


def iwan_update(u: float, w: tuple[float, ...], bank) -> ElementStep:
    """Return map of the micro-slip (Iwan) element: parallel sliders of ``bank``.

    ``w`` holds the committed slider positions (m), ``bank`` the
    ``(k_i, fs_pos_i, fs_neg_i)`` of :func:`slider_bank`. Returns the
    :class:`ElementStep`: the force (N), the new positions (a tuple), the sum of the
    stuck sliders' stiffnesses, whether any slider slips, the sum of each slider's
    slip force times its slide (J).
    """
    f = kt = diss = 0.0
    slipping = False
    w_new = []
    for wi, (k, fp, fn) in zip(w, bank):
        trial = k * (u - wi)
        if trial > fp:
            wn = u - fp / k
            f += fp
            diss += fp * (wn - wi)
            slipping = True
        elif trial < -fn:
            wn = u + fn / k
            f -= fn
            diss += fn * (wi - wn)
            slipping = True
        else:
            wn = wi
            f += trial
            kt += k
        w_new.append(wn)
    return _new(ElementStep, (f, tuple(w_new), kt, 0.0, slipping, diss))


def _macro(p):
    """Step of the symmetric macro-slip element (the hot path: no bank)."""
    kf, mu = p.kf, p.mu

    def step(w, u, v, n, dt):
        fs = mu * n if n > 0.0 else 0.0
        f, w_new, k, slipping = jenkins_update(u, w, kf, fs)
        return _new(ElementStep, (f, w_new, k, 0.0, slipping, fs * abs(w_new - w)))
    return step


def _nonsymmetric(p):
    """Step of the macro-slip element with ``fs_ratio`` != 1."""
    kf, mu, ratio = p.kf, p.mu, p.fs_ratio

    def step(w, u, v, n, dt):
        fs = mu * n if n > 0.0 else 0.0
        fn = fs * ratio
        f, w_new, k, slipping = slider_update(u, w, kf, fs, fn)
        return _new(ElementStep, (f, w_new, k, 0.0, slipping,
                                  (fs if w_new > w else fn) * abs(w_new - w)))
    return step


def _iwan(p):
    """Step of the micro-slip (Iwan) element, ``sliders`` > 1."""
    mu = p.mu

    def step(w, u, v, n, dt):
        return iwan_update(u, w, slider_bank(p, mu * n if n > 0.0 else 0.0))
    return step


def _bind(p):
    if p.sliders > 1:
        return _iwan(p)
    return _nonsymmetric(p) if p.fs_ratio != 1.0 else _macro(p)


def _state_size(p) -> int:
    return p.sliders


def _start(p, w: float = 0.0):
    return tuple([float(w)] * p.sliders) if p.sliders > 1 else float(w)


def _position(w) -> float:
    """The mean slider position; exactly the common one when all are equal."""
    if isinstance(w, tuple):
        first = w[0]
        if all(x == first for x in w):
            return first
        return math.fsum(w) / len(w)
    return w


def contact_normal_forces(p, w, n: float) -> tuple[float, float]:
    """The contact's normal force ``Fs / mu`` (``Fs = mu max(n, 0)``; ``n0`` if
    mu = 0) and 0, as the C port computes it."""
    if p.mu > 0:
        return (p.mu * n if n > 0.0 else 0.0) / p.mu, 0.0
    return p.n0, 0.0


def _is_int(n) -> bool:
    return isinstance(n, int) and not isinstance(n, bool)


JENKINS = FrictionElement(
    name="jenkins",
    summary="macro-slip (Jenkins) element: spring kf in series with a Coulomb slider "
            "Fs = mu n; micro-slip (Iwan) with sliders > 1, non-symmetric with "
            "fs_ratio != 1",
    fields=(
        Field("kf", "Real", "N/m", 60000.0, "finite and > 0 when friction is on",
              finite_rule("> 0"), "contact stiffness of the friction element, > 0 "
              "if friction", required=True, always=True, rule_off="finite and >= 0",
              check_off=finite_rule(">= 0")),
        Field("mu", "Real", "1", 1.0, "finite and >= 0", finite_rule(">= 0"),
              "friction coefficient, >= 0 (slip force Fs = mu * n)", always=True),
        Field("n0", "Real", "N", 0.0, "finite and >= 0", finite_rule(">= 0"),
              "normal force on the contact, >= 0; start value of n_<axis>",
              required=True, always=True),
        Field("sliders", "Integer", None, 1,
              f"an integer from 1 to {MAX_SLIDERS} (the number of Jenkins elements "
              f"of the micro-slip element)",
              lambda n: _is_int(n) and 1 <= n <= MAX_SLIDERS,
              "number of Jenkins elements of the micro-slip (Iwan) element, 1 to 64 "
              "(1: macro-slip)", always=True),
        Field("spread", "Real", "1", 0.0,
              "finite and in [0, 1) (half-width of the sliders' slip displacements "
              "/ eps)", lambda x: finite_rule(">= 0")(x) and x < 1.0,
              "half-width of the sliders' uniform slip-displacement distribution / "
              "(Fs/kf), in [0, 1)", always=True),
        Field("fs_ratio", "Real", "1", 1.0, "finite and >= 0", finite_rule(">= 0"),
              "slip force in the negative direction / the positive one, >= 0 (1: "
              "symmetric friction)", always=True),
    ),
    bind=_bind,
    state_size=_state_size,
    start=_start,
    position=_position,
    stuck_stiffness=lambda p: p.kf,
    normal_forces=contact_normal_forces,
    # the HBM's closed forms and vector law know the symmetric macro-slip element;
    # its per-slider AFT march any bank of sliders
    fast_form=lambda p: "symmetric_slider" if p.sliders == 1 and p.fs_ratio == 1.0
    else "slider_bank",
    c_port="ml_jenkins",
    # every slider of the state may be set (the micro-slip bank's in slider order)
    slider_slots=lambda p: tuple(range(p.sliders)),
)
