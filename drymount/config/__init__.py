"""Configuration files: TOML -> a checked :class:`Config` holding a model System.

A configuration describes one of the thesis's three systems (``model = "sdof"``,
``"quarter_car"`` or ``"rigid_engine"``), its mount law(s), its harmonic excitation, and
the settings of the runs (frequency sweep, harmonic balance, co-simulation). The field
names are those of :class:`fmu_src.mount_law.AxisParameters` and of the builders of
:mod:`hbm.systems`; units are SI. ``docs/config.md`` documents every field.

Example (the single DOF of the thesis, Sec. 2.1.1, with a friction element)::

    model = "sdof"
    name = "my_mount"

    [sdof]
    mass = 70.0                 # kg

    [mount]
    law = "piecewise"           # thesis eq. 2.16-2.20, 3.30
    k1 = 45935.0                # N/m
    k2 = 256900.0               # N/m
    delta = 0.01225             # m
    c = 150.0                   # N s/m

    [mount.friction]            # friction element (default kind), thesis Sec. 2.2
    kf = 60000.0                # N/m
    mu = 1.0
    n0 = 10.0                   # N

    [excitation]
    kind = "unbalance"          # f = f0 omega^2 sin(omega t), thesis eq. 4.2
    amplitude = 0.0305          # f0, kg m

Every problem of a file is collected and raised together as one :class:`ConfigError`
whose ``problems`` name the field path (``mounts[2].axial.friction.kf``, indices from
0), the value and what is allowed. Unknown keys get the closest valid key as a hint.

Public functions: :func:`load_config`, :func:`config_from_dict`, :func:`load_preset`,
:func:`list_presets`, :func:`preset_text`, :func:`resolve_config`,
:func:`mount_from_table`.

Modules: ``schema`` (allowed keys, result objects, ConfigError), ``checks`` (the field
checker), ``mounts`` (mount tables -> mount parameters), ``systems`` (model tables,
excitation, settings, building the System), ``loading`` (dict, file, text, presets).
"""

from drymount.config.loading import (
    config_from_dict,
    list_presets,
    load_config,
    load_preset,
    preset_text,
    resolve_config,
)
from drymount.config.mounts import mount_from_table, readable_unit
from drymount.config.checks import INERTIA_RANGE_KGM2, MASS_RANGE_KG
from drymount.hbm.options import MAX_HARMONICS, MAX_N_SAMPLES  # the one bound of each
from drymount.config.schema import (
    ALLOWED_KEYS,
    MAX_POINTS,
    MODELS,
    Config,
    ConfigError,
    CosimSettings,
    HBMSettings,
    SweepSettings,
)

__all__ = [
    "MAX_HARMONICS",
    "MAX_N_SAMPLES",
    "MAX_POINTS",
    "MASS_RANGE_KG",
    "INERTIA_RANGE_KGM2",
    "MODELS",
    "Config",
    "ConfigError",
    "SweepSettings",
    "HBMSettings",
    "CosimSettings",
    "load_config",
    "config_from_dict",
    "load_preset",
    "list_presets",
    "preset_text",
    "resolve_config",
    "readable_unit",
    "ALLOWED_KEYS",
    "mount_from_table",
]
