"""Array wrappers over the mount law (``fmu_src.mount_law``) for harmonic balance.

The HBM splits every mount axis j into its linear part, handled exactly in the frequency
domain, and a nonlinear remainder evaluated in the time domain (AFT) or in closed form:

    F_j(u, v, w) = k1 u + c v  +  F_gap/cub(u)  +  F_fr(u, w)

    F_gap/cub = F_el(u) - k1 u        (vectorised per law in :mod:`hbm.laws`, looked
                                       up by the law's name)

and ``F_fr`` the Jenkins element (thesis eq. 2.10-2.13), whose periodic response is
obtained by marching the scalar return map :func:`fmu_src.mount_law.slider_update`
(one march per slider of a micro-slip axis, whose forces add up)
sample by sample from ``w = 0`` over two periods and keeping the second (PHYSICS.md
section 1: the convention for stuck bands). The elastic remainder is vectorised with
NumPy; ``tests/test_hbm_elements.py`` proves it equal to
:func:`fmu_src.mount_law.elastic_force` and :func:`fmu_src.mount_law.axis_force`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from drymount.fmu_src.mount_law import AXES, slider_bank, slider_update
from drymount.hbm.generic_march import HBM_FAST_FORMS
from drymount.hbm.laws import hbm_law
from drymount.hbm.system import System

__all__ = ["NonlinearAxes", "nonlinear_axes", "elastic_remainder",
           "jenkins_periodic", "JenkinsResponse"]

@dataclass(frozen=True, eq=False)
class NonlinearAxes:
    """The mount axes of a system that carry a nonlinear remainder, stacked.

    Attributes
    ----------
    labels : tuple of str, length n_ax
        ``<mount>_<axis>``.
    index : tuple of (int, int), length n_ax
        ``(element index, axis index)`` of each row.
    B : ndarray, shape (n_ax, n_dof)
        Rows of the elements' ``B`` maps: ``u = B q - G y``.
    G : ndarray, shape (n_ax, n_base)
    law : tuple of str, length n_ax
        Law names (keys of ``fmu_src.mount_law.ELASTIC_LAWS`` and
        ``hbm.laws.HBM_LAWS``).
    k1, kc, k2, delta, delta_neg : ndarray, shape (n_ax,)
        Elastic parameters (N/m, N/m^3, N/m, m, m).
    kf, fs : ndarray, shape (n_ax,)
        Contact stiffness (N/m) and slip force (N); ``kf = 0`` means no friction.
    w_start : ndarray, shape (n_ax,)
        Slider position the AFT march starts from, m (default 0: the HBM convention
        of PHYSICS.md section 1). Only an element that does not slip at both extrema
        of the period keeps it; see :func:`jenkins_periodic`.
    banks : tuple, length n_ax, or None
        Per axis, the ``(k_i, fs_pos_i, fs_neg_i)`` of its sliders
        (:func:`fmu_src.mount_law.slider_bank`: one for the macro-slip element,
        ``sliders`` for a micro-slip one; empty without friction). None: one
        symmetric slider ``(kf, fs, fs)`` per friction axis.
    inclined : tuple of (int, InclinedParameters)
        The axes (row index) whose friction element is the inclined one of thesis
        Ch. 5 (their ``kf`` and ``fs`` here are 0; :mod:`hbm.inclined` marches them,
        starting relaxed at ``w_start``).
    generic : tuple of (int, AxisParameters)
        The axes (row index) whose friction element has no fast form in the HBM
        (:mod:`hbm.generic_march` marches its own step; ``kf`` and ``fs`` here are 0).
    start_states : tuple, length n_ax, or None
        Per axis, the friction element's own state the march starts from (None
        entries, or None: relaxed at ``w_start``), e.g. the lowered static working
        point's (:func:`hbm.static.lowered_equilibrium`), which the one number
        ``w_start`` does not give for the inclined element or a slider bank.
    """

    labels: tuple[str, ...]
    index: tuple[tuple[int, int], ...]
    B: np.ndarray
    G: np.ndarray
    law: tuple[str, ...]
    k1: np.ndarray
    kc: np.ndarray
    k2: np.ndarray
    delta: np.ndarray
    delta_neg: np.ndarray
    kf: np.ndarray
    fs: np.ndarray
    w_start: np.ndarray | None = None
    banks: tuple | None = None
    inclined: tuple = ()
    generic: tuple = ()
    start_states: tuple | None = None

    def start_state(self, a: int):
        """The state axis row ``a``'s march starts from (None: relaxed at
        ``w_start[a]``)."""
        return None if self.start_states is None else self.start_states[a]

    def start_floats(self, a: int) -> tuple | None:
        """:meth:`start_state` as its floats (None: relaxed at ``w_start[a]``)."""
        s = self.start_state(a)
        return None if s is None else ((float(s),) if isinstance(s, (int, float))
                                       else tuple(float(x) for x in s))

    def __post_init__(self):
        if self.w_start is None:
            object.__setattr__(self, "w_start", np.zeros(len(self.labels)))
        if self.banks is None:
            object.__setattr__(self, "banks", tuple(
                ((float(k), float(f), float(f)),) if k > 0.0 else ()
                for k, f in zip(self.kf, self.fs)))
        # plain-float copies for the scalar closed forms (NumPy scalars are slow)
        for name in ("kc", "delta", "kf", "fs"):
            object.__setattr__(self, f"{name}_list", getattr(self, name).tolist())
        object.__setattr__(self, "dk_list", (self.k2 - self.k1).tolist())
        # the axes of each law, in order of appearance: (HBM forms, mask)
        names = np.array(self.law, dtype=object)
        object.__setattr__(self, "groups", tuple(
            (hbm_law(name), names == name) for name in dict.fromkeys(self.law)))

    @property
    def n(self) -> int:
        return len(self.labels)

    @property
    def friction(self) -> np.ndarray:
        """Indices of the axes with a Jenkins element, shape (n_fr,)."""
        return np.flatnonzero(self.kf > 0.0)

    @property
    def is_hysteretic(self) -> bool:
        return bool(np.any(self.kf > 0.0)) or bool(self.inclined) or \
            bool(self.generic)

    @property
    def has_closed_form(self) -> bool:
        """Whether every law has an H = 1 closed form (``hbm.laws``) and every
        friction element is a symmetric macro-slip one (the Jenkins closed form)."""
        return (not self.inclined and not self.generic
                and all(law.closed_form is not None for law, _ in self.groups)
                and all(len(b) <= 1 and b[0][1] == b[0][2] for b in self.banks
                        if b))


def nonlinear_axes(system: System, sliders=None, states=None) -> NonlinearAxes:
    """Collect the active axes of ``system`` whose law is not purely linear.

    An axis is nonlinear if it carries a friction element, a cubic law with
    ``kc != 0`` or a piecewise law with ``k2 != k1``. ``sliders`` (array_like, shape
    (n_elements, 3), m) gives the slider positions the AFT march starts from, e.g.
    those a time simulation ended with (default: all zero); ``states``
    (``{(element index, axis index): state}``) whole element states to start from
    instead (``NonlinearAxes.start_states``).
    """
    if sliders is not None:
        sliders = np.asarray(sliders, dtype=float)
        if sliders.shape != (len(system.elements), 3) or not np.all(
                np.isfinite(sliders)):
            raise ValueError(f"`sliders` must be finite with shape "
                             f"{(len(system.elements), 3)}, got {sliders.tolist()}")
    rows = []
    for ie, e in enumerate(system.elements):
        for j in e.active_axes:
            p = e.params.axes[j]
            if p.friction or p.elastic.nonlinear(p):
                rows.append((ie, j, e, p))
    n = system.n_dof
    nb = system.n_base
    return NonlinearAxes(
        labels=tuple(f"{e.name}_{AXES[j]}" for _, j, e, _ in rows),
        index=tuple((ie, j) for ie, j, _, _ in rows),
        B=np.array([e.B[j] for _, j, e, _ in rows]).reshape(len(rows), n),
        G=np.array([e.G[j] for _, j, e, _ in rows]).reshape(len(rows), nb),
        law=tuple(p.law for *_, p in rows),
        k1=np.array([p.k1 for *_, p in rows], dtype=float),
        kc=np.array([p.kc for *_, p in rows], dtype=float),
        k2=np.array([p.k2 for *_, p in rows], dtype=float),
        delta=np.array([p.delta for *_, p in rows], dtype=float),
        delta_neg=np.array([p.delta_neg for *_, p in rows], dtype=float),
        w_start=np.array([sliders[ie, j] if sliders is not None else 0.0
                          for ie, j, _, _ in rows], dtype=float),
        start_states=None if not states else tuple(
            states.get((ie, j)) for ie, j, _, _ in rows),
        **friction_columns([p for *_, p in rows]),
    )


def friction_columns(axes) -> dict:
    """The friction fields of a :class:`NonlinearAxes` of the axes ``axes`` (a list
    of ``AxisParameters``), by the element's fast form in the HBM: the sliders of
    the Jenkins forms (``kf``, ``fs``, ``banks``), the inclined element, and every
    other element for the generic march (:mod:`hbm.generic_march`)."""
    form = [p.fast_form if p.fast_form in HBM_FAST_FORMS else
            ("generic" if p.friction else None) for p in axes]
    sliders = [f in ("symmetric_slider", "slider_bank") for f in form]
    return dict(
        kf=np.array([p.kf if s else 0.0 for p, s in zip(axes, sliders)], dtype=float),
        fs=np.array([p.fs if s else 0.0 for p, s in zip(axes, sliders)], dtype=float),
        banks=tuple(slider_bank(p) if s else () for p, s in zip(axes, sliders)),
        inclined=tuple((a, p.inclined) for a, p in enumerate(axes)
                       if form[a] == "inclined"),
        generic=tuple((a, p) for a, p in enumerate(axes) if form[a] == "generic"))


def elastic_remainder(u: np.ndarray, ax: NonlinearAxes
                      ) -> tuple[np.ndarray, np.ndarray]:
    """Nonlinear part of the elastic law ``F_el(u) - k1 u`` and its tangent.

    Parameters
    ----------
    u : ndarray, shape (..., N, n_ax)
        Deflection samples (leading axes: any batch), m.
    ax : NonlinearAxes

    Returns
    -------
    f, df_du : ndarray, shape (..., N, n_ax)
        Force in N and tangent in N/m.
    """
    groups = [(law, mask) for law, mask in ax.groups
              if law.remainder is not None and np.any(mask)]
    if len(groups) == 1 and groups[0][1].all():  # one law on every axis
        law, mask = groups[0]
        f, kt = law.remainder(u, ax, mask)
        return f, kt.astype(float, copy=False)
    f = np.zeros_like(u)
    kt = np.zeros_like(u)
    for law, mask in groups:
        f[..., mask], kt[..., mask] = law.remainder(u[..., mask], ax, mask)
    return f, kt


class JenkinsResponse(NamedTuple):
    """Periodic response of one Jenkins element (:func:`jenkins_periodic`)."""

    force: np.ndarray
    stuck: np.ndarray
    last_slip: np.ndarray


def jenkins_periodic(u: np.ndarray, kf: float, fs: float, w_start: float = 0.0,
                     fs_neg: float | None = None) -> JenkinsResponse:
    """Periodic response of one Jenkins element to sampled periodic motion.

    The periodic response of marching :func:`fmu_src.mount_law.jenkins_update` over
    the samples ``u`` from ``w = 0`` over two periods and keeping the second (the
    convention of PHYSICS.md section 1). When ``max u - min u > 2 Fs / kf`` the
    element slips at both global extrema and the march is periodic from the first
    of them on, so it is done in one pass starting at the global maximum with
    ``w = u_max - Fs/kf`` (identical result, tested); otherwise the two passes are
    marched (the element sticks in the second with the offset the first left).

    Parameters
    ----------
    u : ndarray, shape (N,)
        Deflection at the samples of one period, m.
    kf, fs : float
        Contact stiffness (N/m, > 0) and slip force (N, >= 0).
    w_start : float
        Slider position the first pass starts from, m (0 by convention); it only
        matters when the element does not slip at both extrema.
    fs_neg : float or None
        Slip force in the negative direction, N (None: ``fs``, symmetric); the
        march is then :func:`fmu_src.mount_law.slider_update`, it slips at both
        extrema when ``kf (max u - min u) > fs + fs_neg`` and starts at the maximum
        with ``w = u_max - fs / kf``.

    Returns
    -------
    JenkinsResponse
        ``(force, stuck, last_slip)``:
    force : ndarray, shape (N,)
        Friction force in N.
    stuck : ndarray of bool, shape (N,)
        Whether the element sticks at each sample.
    last_slip : ndarray of int, shape (N,)
        Index (within the period) of the last slip sample before or at each sample,
        -1 if the element never slipped since the start. At a stuck sample n,
        ``w = u[last_slip[n]] -+ Fs / kf``, hence
        ``dF_n/dX = kf (du_n/dX - du_{last_slip[n]}/dX)`` (or ``kf du_n/dX`` if
        ``last_slip[n] == -1``, where ``w = w_start`` is fixed).
    """
    us = u.tolist()
    n = len(us)
    eps = fs / kf
    fn = fs if fs_neg is None else fs_neg
    i_max = max(range(n), key=us.__getitem__)
    i_min = min(range(n), key=us.__getitem__)
    if us[i_max] - us[i_min] > eps + fn / kf:
        # The element slips at both global extrema, so from the global maximum on the
        # response is periodic: start there, slipping, with w = u_max - eps (what
        # the two-pass march from w = 0 reaches there) and march one period.
        order = list(range(i_max, n)) + list(range(i_max))
        w = us[i_max] - eps
        last = i_max
    else:
        # never slips at both extrema: march a first pass from w = 0 (the offset it
        # leaves is the stuck-band convention), the second pass is then periodic
        order = list(range(n))
        w = float(w_start)
        last = -1
        for i in order:
            _, w, _, slipping = slider_update(us[i], w, kf, fs, fn)
            if slipping:
                last = i
    force = [0.0] * n
    stuck = [True] * n
    last_slip = [0] * n
    for i in order:
        f, w, _, slipping = slider_update(us[i], w, kf, fs, fn)
        force[i] = f
        if slipping:
            last = i
            stuck[i] = False
        last_slip[i] = last
    return JenkinsResponse(np.array(force), np.array(stuck, dtype=bool),
                           np.array(last_slip, dtype=int))
