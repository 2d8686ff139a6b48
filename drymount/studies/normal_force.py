"""Study ``normal-force``: single DOF, force transmissibility for a range of n0
(thesis Figs. 4.1-4.4)."""

from __future__ import annotations

from drymount.studies.family import FamilySpec, family_study

NORMAL_FORCE_SPEC = FamilySpec(
    study="normal-force",
    presets=(("original", "sdof_original"), ("halved", "sdof_halved")),
    band_hz=(1.0, 60.0),
    high_hz=30.0,  # second engine order at 900 rpm idle
    forces=(0.0, 5.0, 10.0, 20.0, 40.0, 80.0),
    forces_quick=(0.0, 10.0, 80.0),
    harmonics=(7, 1),
    harmonics_quick=(3, 1),
    ylabel="force transmissibility [-]",
    title="single DOF",
    description="Single-DOF force transmissibility (thesis eq. 4.1, unbalance "
                "excitation eq. 4.2)",
    figs=("4.1", "4.2", "4.3"),
)


def run_normal_force(out_dir, quick: bool = False, progress: bool = True) -> dict:
    """Single DOF: force transmissibility for a range of n0 (thesis Figs. 4.1-4.4).

    For the original and the halved mount (presets ``sdof_original``,
    ``sdof_halved``) and each normal force of ``NORMAL_FORCE_SPEC.forces``, HBM curves
    with H = 7 (AFT) and H = 1 (the thesis's single harmonic). Per curve: peak
    transmissibility, its frequency, the transmissibility at ``high_hz`` and the
    friction energy per cycle.

    Parameters
    ----------
    out_dir : path
        Output folder (created).
    quick : bool
        Three normal forces and H = 3 instead of 7.
    progress : bool
        Show a tqdm progress bar over the curves.

    Returns
    -------
    dict
        ``cases`` (one dict per curve: mount, n0_N, H, peak, peak_freq_hz, t_high,
        e_fr_min_J, e_fr_max_J, success, seconds, n_points), ``reference`` (original
        mount without friction), ``best_halved`` (the halved design of lowest peak),
        ``best_halved_peak_reduction`` (fraction), ``best_halved_lower_fraction``,
        ``e_fr_min_J``, ``failures``, ``files``.
    """
    return family_study(NORMAL_FORCE_SPEC, out_dir, quick, progress)
