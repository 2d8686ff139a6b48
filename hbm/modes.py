"""Nonlinear modes by the extended periodic motion concept (EPMC, Krack 2015).

The autonomous system (no dynamic excitation; a static load stays) gets an artificial
negative mass-proportional damping ``-xi M q'`` that makes a damped motion periodic:

    M q'' + (C - xi M) q' + K q + sum_e B_e^T F_e(u_e) = f_static

Its periodic solutions are sought by the harmonic balance of :mod:`hbm.residual` (the
same residual, closed forms and AFT as the forced response, with the dynamic excitation
switched off, ``exc_scale = 0``). The unknowns are the normalised harmonics ``Psi``
(``X = X_static + a Psi``, with the modal amplitude ``a``), the angular frequency
``omega`` and ``xi``; two equations close the system (Krack 2015, eq. 7-8):

- amplitude normalisation: ``Psi_c1^T M Psi_c1 + Psi_s1^T M Psi_s1 = 1``, i.e. the
  modal amplitude ``a = sqrt(Q1^H M Q1)`` of the fundamental harmonic ``Q1`` (unit
  ``kg^0.5 m``; for a single DOF of mass m, ``a = sqrt(m) X1``);
- phase normalisation: ``phi_k^T M Psi_s1 = 0`` (the sine part of the fundamental has
  no component along the linearised mode ``phi_k``: the motion is referred to cosine).

``lam = log10(a)`` is the continuation parameter (log-spaced amplitudes), continued by
the arc-length continuation of :mod:`hbm.continuation`. The modal damping ratio is
``D = xi / (2 omega)`` (Krack 2015, eq. 11): for a linear system with proportional
damping exactly the modal damping ratio, ``omega`` its undamped natural frequency; for
a friction mode the ratio of the energy dissipated per cycle to ``4 pi`` times the
modal kinetic energy amplitude, ``D = W_diss / (2 pi omega^2 a^2)``.

References: M. Krack, "Nonlinear modal analysis of nonconservative systems: extension of
the periodic motion concept", Computers & Structures 154 (2015) 59-71; NLvib
(Krack and Gross 2019), analysis type 'nma'.
"""

from __future__ import annotations

import dataclasses
import math
import os
from dataclasses import dataclass

import numpy as np

from drymount.hbm.continuation import Branch, Status, continue_branch, newton
from drymount.hbm.linear import natural_frequencies
from drymount.hbm.options import HBMOptions
from drymount.hbm.residual import HarmonicBalance
from drymount.hbm.system import System

__all__ = ["NonlinearMode", "NonlinearModes", "linear_modes", "nonlinear_modes",
           "modes_at_amplitudes", "select_modes", "LinearMode",
           "default_amplitude_range"]

#: Newton's residual tolerance of the EPMC (scaled rows are O(1); the forced
#: response's 1e-10 leaves the frequency at about 1e-10 relative, the backbone tests
#: ask for that): 1e-12, 100 times round-off of a 6-DOF H = 7 residual.
TOL_RESIDUAL = 1e-12
LN10 = math.log(10.0)


@dataclass(frozen=True)
class LinearMode:
    """A mode of the system linearised at small amplitude (contacts stuck)."""

    index: int          # 1-based, ascending frequency
    label: str          # the DOF that holds the largest share of its kinetic energy
    share: float        # that share
    omega: float        # rad/s
    phi: np.ndarray     # (n,), phi^T M phi = 1
    xi: float           # phi^T C phi, 1/s (exact xi of proportional damping)


def linear_modes(system: System) -> list[LinearMode]:
    """The modes of the system linearised about small amplitude: elastic laws at
    their tangent ``k1``, friction contacts stuck (``kf`` added), labelled by the DOF
    with the largest share of the modal kinetic energy ``phi_j (M phi)_j`` (as the
    presets' Table 4.2 labels)."""
    f, V = natural_frequencies(system, stuck=True)
    _, C = system.linearized(stuck=True)
    out = []
    for i in range(len(f)):
        phi = V[:, i]
        share = phi * (system.M @ phi)
        j = int(np.argmax(share))
        out.append(LinearMode(i + 1, system.dof_names[j], float(share[j]),
                              2.0 * np.pi * float(f[i]), phi, float(phi @ C @ phi)))
    return out


def default_amplitude_range(system: System, mode: LinearMode) -> tuple[float, float]:
    """Modal amplitudes ``(a0, a1)`` from well below to well above the nonlinearity.

    The mode's largest nonlinear-axis deflection per unit modal amplitude ``g`` and the
    axes' characteristic deflections (slip displacement ``Fs / kf``, knee ``delta``,
    ``sqrt(k1 / kc)`` of a cubic law, ``mu1 preload / kf`` of an inclined element,
    an order of magnitude): ``a0 = 0.1 u_min / g``, ``a1 = 10 u_max / g``;
    a linear system gets ``(1e-4, 1e-2)`` (its modes do not depend on amplitude)."""
    hb = HarmonicBalance(system, 1, closed_form=False)
    ax = hb.axes
    g = np.abs(ax.B @ mode.phi) if ax.n else np.zeros(0)
    chars = []
    for a in range(ax.n):
        if g[a] <= 1e-12 * max(float(g.max()), 1e-300):
            continue
        if ax.kf[a] > 0:
            chars.append(ax.fs[a] / ax.kf[a])
        for k, fp, fn in ax.banks[a]:
            chars.append(min(fp, fn) / k)
        if ax.law[a].startswith("piecewise"):
            chars.append(ax.delta[a])
        if ax.law[a] == "cubic" and ax.kc[a] > 0:
            chars.append(math.sqrt(ax.k1[a] / ax.kc[a]) if ax.k1[a] > 0 else 1e-3)
        for row, ip in ax.inclined:   # order of its slip: mu1 preload / kf
            if row == a and ip.kf > 0:
                chars.append(ip.mu1 * ip.preload / ip.kf)
    chars = [c for c in chars if c > 0 and math.isfinite(c)]
    if not chars:
        return 1e-4, 1e-2
    gm = float(g.max())
    return 0.1 * min(chars) / gm, 10.0 * max(chars) / gm


class _ModeProblem:
    """The scaled EPMC equations ``fun(y) -> (R, J)`` of one mode,
    ``y = [Psi / psi_s, omega / omega_k, xi / xi_s, log10 a]``."""

    def __init__(self, hb: HarmonicBalance, mode: LinearMode):
        self.hb, self.mode = hb, mode
        m, n = hb.m, hb.n
        M = hb.M
        self.n_psi = m * n
        self.psi_s = np.tile(1.0 / np.sqrt(np.diag(M)), m)
        self.ws = mode.omega
        self.xs = 0.2 * mode.omega  # xi of a damping ratio 0.1
        self.row_s = np.tile(1.0 / (np.sqrt(np.diag(M)) * mode.omega ** 2), m)
        self.A1M = np.kron(hb.basis.D, M)
        self.X_static = np.zeros(self.n_psi)
        if hb.static is not None:
            self.X_static[:n] = hb.static.q
        self.Mphi = M @ mode.phi
        hb.exc_scale = 0.0  # autonomous: no dynamic excitation (static load stays)

    def tol_floor(self, a: float) -> float:
        """Round-off of the scaled residual at modal amplitude ``a``: with a static
        load the residual carries ``eps |f_static|`` however small the vibration
        (divided by ``a`` in the scaled rows); 0 without one."""
        es = np.abs(self.hb.e_static)
        if not np.any(es):
            return 0.0
        return 1e3 * np.finfo(float).eps * float(np.max(self.row_s * es.max())) / a

    def unpack(self, y):
        """``(X, omega, xi, a)`` of ``y``."""
        k = self.n_psi
        a = 10.0 ** y[-1]
        psi = self.psi_s * y[:k]
        return self.X_static + a * psi, self.ws * y[k], self.xs * y[k + 1], a

    def __call__(self, y):
        hb, k, n = self.hb, self.n_psi, self.hb.n
        psi = self.psi_s * y[:k]
        X, w, xi, a = self.unpack(y)
        res = hb.residual(X, w)
        AX = self.A1M @ X
        R = res.R - xi * w * AX
        Jx = res.dR_dX - (xi * w) * self.A1M
        G = np.empty(k + 2)
        G[:k] = self.row_s * R / a
        c1, s1 = psi[n:2 * n], psi[2 * n:3 * n]
        M = hb.M
        G[k] = c1 @ M @ c1 + s1 @ M @ s1 - 1.0
        G[k + 1] = self.Mphi @ s1
        J = np.zeros((k + 2, k + 3))
        J[:k, :k] = (self.row_s[:, None] * Jx) * self.psi_s
        J[:k, k] = self.row_s * (res.dR_domega - xi * AX) / a * self.ws
        J[:k, k + 1] = -self.row_s * w * AX / a * self.xs
        J[:k, k + 2] = LN10 * ((self.row_s * (Jx @ psi)) - G[:k])
        J[k, n:2 * n] = 2.0 * (M @ c1) * self.psi_s[n:2 * n]
        J[k, 2 * n:3 * n] = 2.0 * (M @ s1) * self.psi_s[2 * n:3 * n]
        J[k + 1, 2 * n:3 * n] = self.Mphi * self.psi_s[2 * n:3 * n]
        return G, J

    def guess(self, lam: float) -> np.ndarray:
        """The linearised mode in cosine at ``a = 10**lam``."""
        hb = self.hb
        psi = np.zeros((hb.m, hb.n))
        psi[1] = self.mode.phi
        y = np.empty(self.n_psi + 3)
        y[:self.n_psi] = psi.ravel() / self.psi_s
        y[self.n_psi:] = (1.0, self.mode.xi / self.xs, lam)
        return y


@dataclass
class NonlinearMode:
    """One nonlinear mode against modal amplitude (points of the continuation).

    Attributes
    ----------
    index : int
        1-based number of the linearised mode (ascending frequency, contacts stuck).
    label : str
        DOF that dominates the linearised mode's kinetic energy.
    amplitude : ndarray, shape (P,)
        Modal amplitude ``a = sqrt(Q1^H M Q1)``, kg^0.5 m.
    freq_hz : ndarray, shape (P,)
        Frequency of the periodic motion, Hz.
    xi : ndarray, shape (P,)
        Artificial damping coefficient, 1/s.
    damping_ratio : ndarray, shape (P,)
        ``xi / (2 omega)``.
    harmonics : ndarray, shape (P, 2H+1, n)
        The motion's Fourier coefficients ``[Q0, Qc1, Qs1, ..., QcH, QsH]`` (m, rad).
    slip_ratio : ndarray, shape (P, n_contacts)
        Per friction contact, peak-to-peak deflection over the period divided by the
        largest peak-to-peak a slider of its bank carries stuck (``(Fs+ + Fs-) / k``):
        above 1 the contact slips in the periodic motion.
    contacts : tuple of str
    success, status, message, n_newton
    """

    index: int
    label: str
    amplitude: np.ndarray
    freq_hz: np.ndarray
    xi: np.ndarray
    damping_ratio: np.ndarray
    harmonics: np.ndarray
    slip_ratio: np.ndarray
    contacts: tuple
    success: bool
    status: Status
    message: str
    n_newton: int = 0

    @property
    def dof_amplitude(self) -> np.ndarray:
        """Fundamental amplitude of each DOF, shape (P, n), m or rad."""
        return np.hypot(self.harmonics[:, 1], self.harmonics[:, 2])

    def kinetic_shares(self, M: np.ndarray) -> np.ndarray:
        """Each DOF's share of the fundamental's kinetic energy
        ``(Qc1_j (M Qc1)_j + Qs1_j (M Qs1)_j) / a^2``, shape (P, n)."""
        c, s = self.harmonics[:, 1], self.harmonics[:, 2]
        e = c * (c @ M) + s * (s @ M)
        return e / e.sum(axis=1, keepdims=True)

    @property
    def slipping(self) -> np.ndarray:
        """Whether each contact slips, shape (P, n_contacts)."""
        return self.slip_ratio > 1.0


@dataclass
class NonlinearModes:
    """Nonlinear modes of a system (:func:`nonlinear_modes`).

    Attributes
    ----------
    system_name : str
    dof_names : tuple of str
    modes : list of NonlinearMode
    harmonics, n_samples : int
        H; AFT samples (0: the H = 1 closed forms).
    """

    system_name: str
    dof_names: tuple
    modes: list
    harmonics: int
    n_samples: int
    M: np.ndarray | None = None

    def dominant(self, mode: NonlinearMode) -> list[str]:
        """Per point, the DOF with the largest share of the fundamental's kinetic
        energy (the mode's ``label`` at small amplitude; another DOF where the mode
        changes character or interacts with another mode)."""
        if not len(mode.amplitude):
            return []
        share = mode.kinetic_shares(self.M)
        return [self.dof_names[j] for j in np.argmax(share, axis=1)]

    @property
    def success(self) -> bool:
        return all(m.success for m in self.modes)

    @property
    def freq_hz(self) -> np.ndarray:
        """Frequencies of every point of every mode, Hz (concatenated)."""
        return np.concatenate([m.freq_hz for m in self.modes]) if self.modes \
            else np.zeros(0)

    @property
    def message(self) -> str:
        return "; ".join(f"mode {m.index} ({m.label}): {m.message}" for m in self.modes)

    def columns(self) -> list[str]:
        H = self.harmonics
        cols = ["mode", "label", "dominant", "amplitude", "freq_hz", "damping_ratio",
                "xi"]
        cols += [f"{d}_amp" for d in self.dof_names]
        names = ["0"] + [f"{p}{k}" for k in range(1, H + 1) for p in ("c", "s")]
        cols += [f"{d}_{h}" for h in names for d in self.dof_names]
        contacts = self.modes[0].contacts if self.modes else ()
        cols += [f"{c}_slip" for c in contacts]
        return cols

    def to_csv(self, path: str | os.PathLike) -> None:
        """One row per mode and amplitude: ``mode, label, dominant`` (the DOF that
        dominates the point's kinetic energy), ``amplitude (kg^0.5 m),
        freq_hz, damping_ratio, xi (1/s), <dof>_amp`` (fundamental, m or rad), the
        harmonics ``<dof>_0, <dof>_c1, <dof>_s1, ...`` (m or rad) and ``<contact>_slip``
        (above 1: slips). The first line is a ``# `` comment with the method."""
        meth = "closed forms" if self.n_samples == 0 else f"AFT N={self.n_samples}"
        comment = (f"# drymount modes {self.system_name}: EPMC, H={self.harmonics} "
                   f"({meth}); success={self.success} ({self.message}); amplitude = "
                   f"sqrt(Q1^H M Q1) kg^0.5 m; damping_ratio = xi/(2 omega); "
                   f"<contact>_slip > 1: the contact slips")
        from drymount.hbm.io import atomic_path
        with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8") as fh:
            fh.write(comment + "\n")
            fh.write(",".join(self.columns()) + "\n")
            for m in self.modes:
                dom = self.dominant(m)
                for i in range(len(m.amplitude)):
                    vals = [str(m.index), m.label, dom[i]]
                    num = [m.amplitude[i], m.freq_hz[i], m.damping_ratio[i], m.xi[i],
                           *m.dof_amplitude[i], *m.harmonics[i].ravel(),
                           *m.slip_ratio[i]]
                    vals += [f"{v:.12g}" for v in num]
                    fh.write(",".join(vals) + "\n")

    def plot(self, path=None):
        """Frequency and damping ratio against modal amplitude (log axis), one curve
        per mode labelled by its dominant axis; saved to ``path`` if given. Returns
        the matplotlib Figure."""
        import matplotlib
        if path is not None:
            matplotlib.use("Agg", force=False)
        import matplotlib.pyplot as plt
        fig, (a1, a2) = plt.subplots(2, 1, sharex=True, figsize=(7, 6.5))
        for m in self.modes:
            lab = f"mode {m.index} ({m.label})"
            a1.semilogx(m.amplitude, m.freq_hz, label=lab)
            a2.semilogx(m.amplitude, 100.0 * m.damping_ratio, label=lab)
        a1.set_ylabel("frequency [Hz]")
        a2.set_ylabel("modal damping ratio xi/(2 omega) [%]")
        a2.set_xlabel("modal amplitude sqrt(Q1^H M Q1) [kg^0.5 m]")
        a1.set_title(f"{self.system_name}: nonlinear modes (EPMC, H = "
                     f"{self.harmonics})")
        for a in (a1, a2):
            a.grid(True, which="both", alpha=0.3)
        a1.legend(fontsize=8)
        fig.tight_layout()
        if path is not None:
            fig.savefig(path, dpi=120)
            plt.close(fig)
        return fig


def _contacts(hb: HarmonicBalance):
    """``(labels, [(axis, [(k, fs_pos, fs_neg), ...]), ...])`` of the friction
    axes marched by slider banks (macro- and micro-slip; not the inclined element)."""
    ax = hb.axes
    rows = [(a, ax.banks[a]) for a in range(ax.n) if ax.banks[a]]
    return tuple(ax.labels[a] for a, _ in rows), rows


def _slip_ratio(hb: HarmonicBalance, X: np.ndarray, rows) -> np.ndarray:
    """Peak-to-peak deflection over the stuck capacity of each contact's bank (the
    largest over its sliders; a slider at periodic motion sticks throughout iff the
    peak-to-peak deflection is below ``(Fs+ + Fs-) / k``)."""
    if not rows:
        return np.zeros(0)
    u = hb.basis.E @ hb.axis_coefficients(X)  # (N, n_ax)
    out = np.empty(len(rows))
    for i, (a, bank) in enumerate(rows):
        p2p = float(u[:, a].max() - u[:, a].min())
        out[i] = max(p2p * k / (fp + fn) for k, fp, fn in bank)
    return out


def _branch_mode(prob: _ModeProblem, ys, br, rows, labels) -> NonlinearMode:
    hb, mode = prob.hb, prob.mode
    pts = [prob.unpack(y) for y in ys]
    X = np.array([p[0] for p in pts]).reshape(len(pts), hb.m, hb.n) if pts else \
        np.zeros((0, hb.m, hb.n))
    w = np.array([p[1] for p in pts])
    xi = np.array([p[2] for p in pts])
    a = np.array([p[3] for p in pts])
    slip = np.array([_slip_ratio(hb, x.ravel(), rows) for x in X]).reshape(
        len(pts), len(rows))
    with np.errstate(divide="ignore", invalid="ignore"):
        D = xi / (2.0 * w)
    return NonlinearMode(mode.index, mode.label, a, w / (2 * np.pi), xi, D, X, slip,
                         labels, br.success, br.status, br.message, br.n_newton)


def _check_amplitudes(amplitude_range) -> tuple[float, float] | None:
    if amplitude_range is None:
        return None
    try:
        a0, a1 = (float(v) for v in amplitude_range)
    except (TypeError, ValueError):
        raise ValueError(f"`amplitude_range` must be two modal amplitudes "
                         f"(kg^0.5 m), got {amplitude_range!r}") from None
    if not (math.isfinite(a0) and math.isfinite(a1) and 0 < a0 < a1):
        raise ValueError(f"`amplitude_range` must satisfy 0 < A0 < A1 (finite, "
                         f"kg^0.5 m), got {amplitude_range!r}")
    return a0, a1


def select_modes(system: System, mode) -> list[LinearMode]:
    """The linearised modes ``mode`` names ('all', a 1-based number, or the DOF
    that dominates it); ValueError naming the value and what is allowed."""
    lin = linear_modes(system)
    if mode is None or mode == "all":
        chosen = lin
    elif isinstance(mode, str) and mode in system.dof_names:
        chosen = [m for m in lin if m.label == mode]
        if not chosen:
            raise ValueError(f"`mode` {mode!r}: no linearised mode is dominated by "
                             f"that DOF (labels: {[m.label for m in lin]})")
    else:
        try:
            k = int(mode)
        except (TypeError, ValueError):
            k = 0
        if isinstance(mode, bool) or not 1 <= k <= len(lin) or k != mode and \
                str(k) != str(mode):
            raise ValueError(f"`mode` must be 'all', 1..{len(lin)} or a DOF name "
                             f"{list(system.dof_names)}, got {mode!r}")
        chosen = [lin[k - 1]]
    for m in chosen:
        if not m.omega > 0:
            raise ValueError(f"mode {m.index} ({m.label}) is a rigid-body mode "
                             f"(0 Hz): no nonlinear mode to continue")
    return chosen


def nonlinear_modes(system: System, mode="all", amplitude_range=None, *,
                    harmonics: int | None = None, n_samples: int | None = None,
                    closed_form: bool | None = None,
                    options: HBMOptions | None = None) -> NonlinearModes:
    """Nonlinear modes by EPMC, continued in log modal amplitude.

    Parameters
    ----------
    system : System
    mode : 'all', int or str
        'all', the 1-based number of a linearised mode (ascending frequency,
        contacts stuck), or the DOF name that dominates it.
    amplitude_range : (float, float), optional
        Modal amplitudes ``a0 < a1``, kg^0.5 m (default
        :func:`default_amplitude_range`, per mode).
    harmonics, n_samples, closed_form, options
        As :func:`hbm.analysis.frequency_response` (H default ``options.harmonics``,
        fixed: no ``tol`` adaptation here; the step controls of ``options`` apply to
        the scaled unknowns, a decade of amplitude being 1).

    Returns
    -------
    NonlinearModes
        A mode whose continuation stalled has ``success`` False, its points so far
        and the reason.

    Raises
    ------
    ValueError
        Bad ``mode`` or ``amplitude_range`` (before any work).
    """
    opts = HBMOptions() if options is None else options
    H = opts.harmonics if harmonics is None else harmonics
    rng = _check_amplitudes(amplitude_range)
    chosen = select_modes(system, mode)
    settings = _settings(opts)
    out, hb = [], None
    for lm in chosen:
        hb, prob, labels, rows = _setup(system, lm, H, n_samples, closed_form, opts)
        a0, a1 = rng if rng is not None else default_amplitude_range(system, lm)
        try:
            br = _trace(prob, a0, a1, settings)
        except KeyboardInterrupt as exc:   # the points so far, for the caller
            br = getattr(exc, "branch", None) or Branch()
            br.message = f"interrupted at a = {10 ** br.y[-1][-1]:.4g}" if br.y \
                else "interrupted"
            out.append(_branch_mode(prob, br.y, br, rows, labels))
            exc.partial_result = _result(system, out, H, hb)
            raise
        out.append(_branch_mode(prob, br.y, br, rows, labels))
    return _result(system, out, H, hb)


def _trace(prob: _ModeProblem, a0: float, a1: float, settings) -> Branch:
    """The branch of one mode from modal amplitude ``a0`` to ``a1``: a first
    solution by Newton from the linearised mode, then arc length in log10 a."""
    lam0, lam1 = math.log10(a0), math.log10(a1)
    settings = dataclasses.replace(settings, tol_residual=max(settings.tol_residual,
                                                              prob.tol_floor(a0)))
    y0, ok, its, msg = newton(prob, prob.guess(lam0), _start_settings(settings),
                              fixed=prob.n_psi + 2)
    if not ok:
        return Branch(status=Status.NO_START, n_newton=its,
                      message=f"no periodic motion at a = {a0:.4g} ({msg})")
    br = continue_branch(prob, y0, lam1, settings, lam_start=lam0)
    br.n_newton += its
    if br.success:
        br.message = "reached the end of the amplitude range"
    else:
        br.message = br.message.replace("lam = ", "log10 a = ")
    return br


def _result(system, out, H, hb) -> NonlinearModes:
    return NonlinearModes(system.name, tuple(system.dof_names), out, int(H),
                          0 if hb is None or hb.closed_form else hb.n_samples,
                          system.M)


def _settings(opts: HBMOptions):
    return dataclasses.replace(opts.continuation_settings(),
                               tol_residual=min(opts.tol_residual, TOL_RESIDUAL))


def _start_settings(settings):
    """More Newton iterations for a first solution from the linearised mode."""
    return dataclasses.replace(settings, max_newton=max(4 * settings.max_newton, 50))


def _setup(system, lm, H, n_samples, closed_form, opts):
    """``(hb, problem, contact labels, contact rows)`` of one mode."""
    N = opts.n_samples if n_samples is None else n_samples
    hb = HarmonicBalance(system, H, N, closed_form)
    labels, rows = _contacts(hb)
    return hb, _ModeProblem(hb, lm), labels, rows


def modes_at_amplitudes(system: System, amplitudes, mode="all", *,
                        harmonics: int | None = None, n_samples: int | None = None,
                        closed_form: bool | None = None,
                        options: HBMOptions | None = None) -> NonlinearModes:
    """The EPMC solutions at given modal amplitudes (natural parametrisation).

    Each amplitude (ascending, kg^0.5 m) is solved by Newton from the secant
    prediction of the two before (the first from the linearised mode). Does not
    follow a turn in amplitude; stops a mode at its first failure (``success``
    False, the points so far). Other parameters as :func:`nonlinear_modes`.
    """
    a = np.atleast_1d(np.asarray(amplitudes, dtype=float))
    if a.ndim != 1 or a.size == 0 or not np.all(np.isfinite(a)) or np.any(a <= 0) \
            or np.any(np.diff(a) <= 0):
        raise ValueError(f"`amplitudes` must be ascending finite modal amplitudes "
                         f"> 0 (kg^0.5 m), got {amplitudes!r}")
    opts = HBMOptions() if options is None else options
    H = opts.harmonics if harmonics is None else harmonics
    chosen = select_modes(system, mode)
    settings = _start_settings(_settings(opts))
    out, hb = [], None
    for lm in chosen:
        hb, prob, labels, rows = _setup(system, lm, H, n_samples, closed_form, opts)
        br, ys = Branch(), []
        settings_k = dataclasses.replace(settings, tol_residual=max(
            settings.tol_residual, prob.tol_floor(float(a[0]))))
        for lam in np.log10(a):
            g = prob.guess(lam) if not ys else ys[-1].copy()
            if len(ys) >= 2:
                g = ys[-1] + (ys[-1] - ys[-2]) * (lam - ys[-1][-1]) / (
                    ys[-1][-1] - ys[-2][-1])
            g[-1] = lam
            y, ok, its, msg = newton(prob, g, settings_k, fixed=prob.n_psi + 2)
            br.n_newton += its
            if not ok:
                br.status = Status.NO_CONVERGENCE
                br.message = f"no convergence at a = {10 ** lam:.6g} ({msg})"
                break
            ys.append(y)
        else:
            br.success, br.message = True, "solved at every amplitude"
        out.append(_branch_mode(prob, ys, br, rows, labels))
    return _result(system, out, H, hb)
