"""Study ``quarter-car``: engine on a quarter car, displacement transmissibility for a
range of n0 (thesis Figs. 4.6-4.9)."""

from __future__ import annotations

from drymount.studies.family import FamilySpec, family_study

QUARTER_CAR_SPEC = FamilySpec(
    study="quarter-car",
    presets=(("original", "quarter_car_original"), ("halved", "quarter_car_halved")),
    band_hz=(0.5, 50.0),
    high_hz=30.0,
    forces=(0.0, 10.0, 30.0, 60.0, 120.0, 250.0),
    forces_quick=(0.0, 30.0, 250.0),
    harmonics=(5,),
    harmonics_quick=(3,),
    ylabel="displacement transmissibility engine/sprung [-]",
    title="engine on a quarter car",
    description="Quarter-car displacement transmissibility engine over sprung mass "
                "(thesis eq. 4.3, road displacement input)",
    figs=("4.6", "4.7", "4.8"),
)


def run_quarter_car(out_dir, quick: bool = False, progress: bool = True) -> dict:
    """Quarter car: displacement transmissibility for a range of n0 (Figs. 4.6-4.9).

    Presets ``quarter_car_original`` and ``quarter_car_halved``; HBM with H = 5
    (quick: 3 forces, H = 3). Returns the same keys as
    :func:`drymount.studies.run_normal_force`.
    """
    return family_study(QUARTER_CAR_SPEC, out_dir, quick, progress)
