"""The cases of ``drymount validate`` (:mod:`drymount.validation`) and what a run of
one gives: the tolerances, :class:`Case` and :data:`CASES` (the validated systems),
:class:`CaseResult` and :class:`FamilyPoint`. Split from :mod:`drymount.validation`
(which runs the cases) so that its report (:mod:`drymount.validation_report`) reads
them without importing the runner.
"""

from __future__ import annotations

from dataclasses import dataclass, field


__all__ = ["Case", "CASES", "CaseResult", "FamilyPoint", "TOL_REL_PEAK",
           "TOL_FAMILY_ORBIT", "NEGLIGIBLE_RESPONSE"]

#: Pass/fail tolerance on the largest amplitude error relative to the peak amplitude
#: (issue 5 target: 1 % of peak with H >= 7 on stable branches).
TOL_REL_PEAK = 0.01
#: Tolerance of a co-simulation started on the HBM orbit in a family band (it must
#: stay on the orbit, issue 26): 0.1 % of the peak amplitude.
TOL_FAMILY_ORBIT = 1e-3
#: DOFs whose HBM peak amplitude is below this fraction of the largest DOF peak of the
#: same kind (translation or rotation) carry no information and are not compared.
NEGLIGIBLE_RESPONSE = 1e-3

_ROTATIONS = {"alpha", "beta", "gamma"}


@dataclass(frozen=True)
class Case:
    """One validated system.

    Attributes
    ----------
    name : str
        Label in the report.
    preset : str
        Preset name (``drymount presets list``).
    fmin_hz, fmax_hz : float
        Band, Hz; it spans the resonances of the preset.
    points, quick_points : int
        Number of frequencies at full size and in ``--quick`` mode.
    directions : tuple of str
        Sweep directions; the cubic spring is swept both ways (its fold).
    harmonics : int
        H of the multi-harmonic HBM reference.
    n_samples : int or None
        AFT samples per period of that reference (None: the HBM default).
    family_hz : tuple of float
        Frequencies in the bands where a surface of an inclined element sticks for
        the whole period (a family of periodic states, :func:`_family_points`):
        co-simulated from the HBM orbit (must stay on it, ``TOL_FAMILY_ORBIT``) and
        from rest (the spread reported, not judged); in quick mode too.
    """

    name: str
    preset: str
    fmin_hz: float
    fmax_hz: float
    points: int = 16
    quick_points: int = 5
    directions: tuple[str, ...] = ("up",)
    harmonics: int = 7
    n_samples: int | None = None
    family_hz: tuple[float, ...] = ()
    #: the co-simulation's backend ("fmu"; "inproc" where the FMUs lack the kind)
    backend: str = "fmu"
    #: a third column: the exact FRF of a linear single DOF
    #: (:func:`drymount.validation_exact.exact_sdof_amplitude`); HBM and
    #: co-simulation must both be within ``TOL_REL_PEAK`` of it (of its peak)
    exact: bool = False


CASES = (
    Case("sdof_friction", "sdof_halved", 2.0, 14.0),
    Case("quarter_car_friction", "quarter_car_halved", 1.0, 16.0),
    # Three friction elements: with the default 64 AFT samples the sampled stick-slip
    # reversals cost up to 0.57 % of peak (measured, beta at 6.2 Hz); 256 samples
    # bring the largest error to 0.05 %.
    Case("six_dof_friction", "six_dof_halved", 3.0, 18.0, points=15, quick_points=4,
         harmonics=7, n_samples=256),
    # Steps of 0.25 Hz (quick: 0.6 Hz) keep the up sweep on the upper branch well
    # into the bistable band (4.3-8.9 Hz): it then jumps as on a test rig.
    Case("sdof_cubic", "sdof_cubic", 3.0, 12.0, points=37, quick_points=16,
         directions=("up", "down")),
    # Micro-slip (Iwan, 8 sliders) with non-symmetric friction (issue 14 item 3):
    # quick mode measured 0.061 % of peak (H = 7), 0.36 % with H = 1.
    Case("sdof_microslip", "sdof_microslip", 2.0, 14.0),
    # Maxwell branches beside the friction element (issue 28): the HBM adds their
    # complex stiffness per harmonic exactly, the co-simulation steps their strokes
    # exactly for the step's linear path; the friction is marched as in sdof_halved.
    Case("sdof_maxwell_friction", "sdof_maxwell", 2.0, 14.0),
    # The inclined element of Ch. 5 at 60 degrees (varying normal force), a friction
    # kind of the FrictionMount FMU's axis: HBM against co-simulation, both through the
    # general path (the element relaxed at the static working point under the weight).
    # Where its flat surface sticks for the whole period (5.2-5.5 and 8.6-9.1 Hz,
    # HBM H = 7) the periodic state is a family: the member depends on the start.
    Case("sdof_inclined_60deg", "sdof_inclined", 3.0, 14.0, points=12, quick_points=3,
         family_hz=(5.5, 9.0)),
    # ... and on the quarter car (road input, the weight of the bodies): measured
    # 0.25 % of peak (engine at 9 Hz, where its stick-slip pattern changes), 13 s.
    # The flat surface sticks for the whole period at 8.5-9 Hz (HBM H = 7, N = 64):
    # from the orbit and from rest both within 0.07 % of the local amplitude there.
    Case("quarter_car_inclined", "quarter_car_inclined", 1.0, 16.0, family_hz=(9.0,)),
    # The hydraulic mount (issue 28 item 3): the HBM adds the fluid's complex
    # stiffness per harmonic exactly, the co-simulation steps the fluid exactly for
    # the step's linear path; linear, so both are the SDOF's exact FRF up to the
    # leapfrog's O(h^2). In-process (the FMUs give the same numbers bit for bit). The
    # third column: the exact FRF from the chamber equations (validation_exact).
    Case("sdof_hydraulic", "sdof_hydraulic", 2.0, 30.0, harmonics=3,
         backend="inproc", exact=True),
)


@dataclass
class CaseResult:
    """Result of one case.

    Attributes
    ----------
    case : Case
    rows : list of dict
        One per (direction, frequency, DOF): ``direction``, ``freq_hz``, ``dof``,
        ``amp_cosim``, ``amp_hbm``, ``amp_hbm1`` (m or rad), ``err`` and ``err_h1``
        (relative to the DOF's peak HBM amplitude), ``stable`` (HBM point stable),
        ``compared`` (counts toward pass/fail).
    max_err, max_err_h1 : float
        Largest compared error of H and of H = 1.
    passed : bool
    seconds : float
        Wall time of the case.
    curves : dict
        Per direction: frequencies and amplitudes for the plot.
    dense : dict
        The plot's continuous HBM curves over the band (arc-length continuation at
        the case's H and N, and at H = 1): ``{H: (freq_hz, amplitude, stable)}``.
    family : list of FamilyPoint
        The family-band points (``Case.family_hz``; their rows are in ``rows`` with
        direction ``orbit``, compared, and ``rest``, reported only).
    max_err_orbit, max_err_rest : float
        Largest error of the family points started on the HBM orbit and from rest.
    """

    case: Case
    rows: list = field(default_factory=list)
    max_err: float = float("nan")
    max_err_h1: float = float("nan")
    passed: bool = False
    seconds: float = 0.0
    curves: dict = field(default_factory=dict)
    message: str = ""
    dof_names: tuple = ()
    dense: dict = field(default_factory=dict)
    family: list = field(default_factory=list)
    max_err_orbit: float = float("nan")
    max_err_rest: float = float("nan")
    #: ``Case.exact``: largest |A_hbm - A_exact| and |A_cosim - A_exact| over the
    #: compared points, relative to the exact peak of the DOF (nan without)
    max_err_exact_hbm: float = float("nan")
    max_err_exact_cosim: float = float("nan")


@dataclass(frozen=True)
class FamilyPoint:
    """One frequency in a family band (``Case.family_hz``), one DOF.

    ``stuck``: per inclined element, which surfaces stick for the whole period on
    the HBM orbit (:attr:`hbm.result.FrequencyResponse.stuck`); ``amp_*`` the
    fundamental amplitudes (m or rad) and ``mean_*`` the mean positions of the HBM
    orbit and of the co-simulations started on it (``orbit``) and at rest at the
    static working point (``rest``); ``err_*`` relative to the DOF's peak HBM
    amplitude over the band (the dense curve's)."""

    freq_hz: float
    dof: str
    stuck: tuple
    amp_hbm: float
    amp_orbit: float
    amp_rest: float
    err_orbit: float
    err_rest: float
    mean_hbm: float
    mean_orbit: float
    mean_rest: float
