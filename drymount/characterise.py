"""``drymount characterise CONFIG``: dynamic-stiffness maps of a configuration's mounts.

For every mount and every axis the model moves, the dynamic stiffness |K*| and the
loss angle versus frequency at several displacement amplitudes and static preloads
(:func:`hbm.characterise.dynamic_stiffness`: harmonic balance with an imposed
harmonic deflection, fundamental force over displacement), the datasheet of a mount
test rig. A few points are cross-checked in the time domain: through the FrictionMount
FMU (fmpy, deflection imposed sample by sample, the force read before each step) or,
with ``--check law``, by marching the law in Python.

Writes into ``--out``: ``<mount>_<axis>.csv`` and ``.png`` (|K*| and loss angle vs
frequency, one curve per amplitude, a line style per preload) and ``crosscheck.csv``.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from drymount.io import save_figure, write_csv
from drymount.fmu_src.mount_law import AXES, AxisParameters, MountParameters
from drymount.hbm.characterise import (
    DEFAULT_SAMPLES,
    DynamicStiffnessMap,
    dynamic_stiffness,
    time_domain_stiffness,
)
from drymount.hbm.generic_march import MAX_PASSES

__all__ = ["AxisMap", "CrossCheck", "CROSSCHECK_RTOL", "mount_axes", "characterise",
           "cross_check", "fmu_stiffness", "main"]

#: Harmonic balance vs the time-domain check (FMU or law, 2048 steps per period, the
#: last of 4 periods): both sample the same law, so they agree to the quadrature error
#: of the slope jumps, measured <= 1e-7 (tests/test_characterise_cli.py). An element
#: without a fast form (the smooth elements) is marched by the maps until its state
#: repeats (up to MAX_PASSES periods) and settles slowly at small amplitudes, so its
#: check runs MAX_PASSES periods (4 left the rate-dependent element of
#: docs/physics.md on sdof_halved 3.6e-5 off at 0.1 mm, 30 Hz; 16 periods: 7e-15);
#: a rate-dependent element's step depends on the sampling, so it is checked at the
#: maps' own (DEFAULT_SAMPLES steps per period).
CROSSCHECK_RTOL = 1e-5
DEFAULT_AMPLITUDES_MM = (0.1, 0.5, 1.0, 2.0)
CHECK_STEPS = 2048
CHECK_PERIODS = 4


@dataclass(frozen=True)
class AxisMap:
    """The dynamic-stiffness map of one axis of one mount."""

    mount: str
    axis: str
    params: AxisParameters
    map: DynamicStiffnessMap

    @property
    def label(self) -> str:
        return f"{self.mount}_{self.axis}"


@dataclass(frozen=True)
class CrossCheck:
    """One point of a map recomputed in the time domain."""

    label: str
    method: str
    freq_hz: float
    amplitude: float
    preload: float
    mean_deflection: float
    K_hbm: complex
    K_time: complex

    @property
    def rel_error(self) -> float:
        return abs(self.K_hbm - self.K_time) / abs(self.K_time)


def mount_axes(system) -> list[tuple[str, str, AxisParameters]]:
    """``(mount name, axis name, law)`` of every axis the model deflects."""
    return [(e.name, AXES[j], e.params.axes[j]) for e in system.elements
            for j in e.active_axes]


def characterise(system, freqs_hz, amplitudes, preloads, progress: bool = False
                 ) -> list[AxisMap]:
    """Dynamic-stiffness maps of every deflected mount axis of ``system``."""
    axes = mount_axes(system)
    from tqdm import tqdm

    with tqdm(total=len(axes) * len(amplitudes) * len(preloads), unit="loop",
              desc="dynamic stiffness", disable=not progress, leave=False) as bar:
        return [AxisMap(m, a, p, dynamic_stiffness(p, freqs_hz, amplitudes, preloads,
                                                   progress=bar.update))
                for m, a, p in axes]


def _fmu_names(md_vars, axis: str, field: str) -> str:
    """The FMU's name of an axis parameter (``axial_k1`` or ``k1_axial``)."""
    for name in (f"{axis}_{field}", f"{field}_{axis}"):
        if name in md_vars:
            return name
    raise ValueError(f"the FMU has no parameter for {field!r} of axis {axis!r}")


def _axial_parameters(md_vars, axis: AxisParameters) -> dict[str, dict]:
    """``{FMI type: {FMU name: value}}`` of ``axis`` as the FMU's axial axis; a field
    the FMU lacks is skipped only while it has its interface default."""
    from drymount.fmu_src.interface import variable
    from drymount.vehicle.backends import fmu_parameter_values

    out = {}
    for typ, values in fmu_parameter_values(MountParameters(axis, axis, axis)).items():
        for name, value in values.items():
            axis_name, _, field = name.partition("_")
            if axis_name != "axial":
                continue
            try:
                out.setdefault(typ, {})[_fmu_names(md_vars, "axial", field)] = value
            except ValueError:
                if value != variable(name).start:
                    raise
    return out


def fmu_stiffness(fmu_path, axis: AxisParameters, freq_hz: float, X: float,
                  U0: float = 0.0, periods: int = CHECK_PERIODS,
                  steps_per_period: int = CHECK_STEPS) -> complex:
    """K* (N/m) of ``axis`` through the FMU: its axial axis driven by u = U0 + X sin.

    The slider starts relaxed at the working point (``w_axial = U0``), as in the
    harmonic balance; each step sets ``u``, ``v``, reads the force (direct
    feedthrough) and commits with ``doStep``. The fundamental of the last period.
    """
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(str(fmu_path))
    names = {v.name: v for v in md.modelVariables}
    unzip = extract(str(fmu_path))
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzip,
                    modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="characterise")
    vr = {n: v.valueReference for n, v in names.items()}
    try:
        fmu.instantiate()
        # every parameter of the axial axis in the interface table (the fields of
        # every registered friction element included)
        for typ, values in _axial_parameters(names, axis).items():
            setter = {"Real": fmu.setReal, "Integer": fmu.setInteger,
                      "Boolean": fmu.setBoolean}[typ]
            setter([vr[n] for n in values], list(values.values()))
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        fmu.setReal([vr["w_axial"]], [float(U0)])
        n, omega = int(steps_per_period), 2 * math.pi * freq_hz
        h = 1.0 / (freq_hz * n)
        io_in, io_out = [vr["u_axial"], vr["v_axial"]], [vr["F_axial"]]
        last = np.empty(n)
        for k in range(periods * n):
            th = 2 * math.pi * (k % n) / n
            fmu.setReal(io_in, [U0 + X * math.sin(th), X * omega * math.cos(th)])
            F = fmu.getReal(io_out)[0]
            fmu.doStep(k * h, h)
            if k >= (periods - 1) * n:
                last[k % n] = F
        fmu.terminate()
    finally:
        fmu.freeInstance()
    th = 2 * np.pi * np.arange(n) / n
    F_s, F_c = 2 / n * float(last @ np.sin(th)), 2 / n * float(last @ np.cos(th))
    return complex(F_s, F_c) / X


#: The fluid's start transient decays to this fraction of itself before the
#: time-domain cross-check of a hydraulic axis measures its last period.
FLUID_SETTLED = 1e-8


def fluid_settling_periods(hyd, freq_hz: float) -> int:
    """Periods at ``freq_hz`` after which the slowest decaying mode of the hydraulic
    fluid path ``hyd`` (``fmu_src.linear_branches.fluid_matrices``; the conserved
    volume's zero eigenvalues left out) has decayed to :data:`FLUID_SETTLED`; at
    least 20. A lightly damped decoupler needs hundreds at high frequency."""
    from drymount.fmu_src.linear_branches import fluid_matrices

    lam = np.linalg.eigvals(np.array(fluid_matrices(hyd)[0]))
    decay = -lam.real[np.abs(lam) > 1e-9 * np.abs(lam).max()]
    sigma = float(decay.min()) if decay.size else math.inf
    return max(20, math.ceil(freq_hz * math.log(1.0 / FLUID_SETTLED) / sigma))


def cross_check(maps, method: str = "law", fmu_path=None) -> list[CrossCheck]:
    """Two points per distinct axis law, recomputed in the time domain.

    The points: (largest amplitude, lowest preload, median frequency) and (smallest
    amplitude, highest preload, highest frequency).
    """
    out, seen = [], set()
    for am in maps:
        key = repr(am.params)
        if key in seen:
            continue
        seen.add(key)
        m, p = am.map, am.params
        nf, na, npl = m.freq_hz.size, m.amplitude.size, m.preload.size
        steps = DEFAULT_SAMPLES if p.friction and p.element.rate_dependent \
            else CHECK_STEPS
        periods = MAX_PASSES if p.friction and p.fast_form is None else CHECK_PERIODS
        for i, j, k in ((0, na - 1, nf // 2), (npl - 1, 0, nf - 1)):
            f, X, U0 = m.freq_hz[k], m.amplitude[j], m.mean_deflection[i, j]
            if p.has_hydraulic:   # the fluid's start transient must die out
                periods = max(periods, fluid_settling_periods(p.hydraulic, f))
            how = method
            if how == "fmu":
                K_t = fmu_stiffness(fmu_path, p, f, X, U0, periods, steps)
            else:
                K_t = time_domain_stiffness(p, f, X, U0, periods, steps)
            out.append(CrossCheck(am.label, how, float(f), float(X),
                                  float(m.preload[i]), float(U0), complex(m.K[i, j, k]),
                                  K_t))
    return out


def _write_map(out: Path, am: AxisMap, source: str) -> None:
    m = am.map
    rows = [(P, X, m.mean_deflection[i, j], f, m.magnitude[i, j, k],
             m.loss_angle_deg[i, j, k], m.K[i, j, k].real, m.K[i, j, k].imag)
            for i, P in enumerate(m.preload) for j, X in enumerate(m.amplitude)
            for k, f in enumerate(m.freq_hz)]
    write_csv(out / f"{am.label}.csv",
              ["preload_N", "amplitude_m", "mean_deflection_m", "freq_hz",
               "stiffness_N_per_m", "loss_angle_deg", "K_real_N_per_m",
               "K_imag_N_per_m"], rows,
              comment=f"dynamic stiffness K* = fundamental force / displacement "
                      f"amplitude of {am.label} ({am.params.law}), imposed "
                      f"u = U0 + X sin(2 pi f t); {source}")
    from matplotlib.figure import Figure

    fig = Figure(figsize=(10.0, 4.2), layout="constrained")
    ax_k, ax_d = fig.subplots(1, 2)
    styles = ("-", "--", ":", "-.")
    for i, P in enumerate(m.preload):
        for j, X in enumerate(m.amplitude):
            lab = f"X = {X * 1e3:g} mm" + (f", P = {P:g} N" if m.preload.size > 1
                                           else "")
            line, = ax_k.plot(m.freq_hz, m.magnitude[i, j], styles[i % 4], label=lab,
                              color=f"C{j}")
            ax_d.plot(m.freq_hz, m.loss_angle_deg[i, j], styles[i % 4],
                      color=line.get_color())
    ax_k.set(xlabel="frequency [Hz]", ylabel="|K*| [N/m]", title="Dynamic stiffness")
    ax_d.set(xlabel="frequency [Hz]", ylabel="loss angle [deg]", title="Loss angle")
    for a in (ax_k, ax_d):
        a.grid(alpha=0.3)
    ax_k.legend(fontsize=7)
    fig.suptitle(f"{am.label}: {am.params.law} law"
                 + (f", friction kf = {am.params.kf:g} N/m, Fs = {am.params.fs:g} N"
                    if am.params.friction else ", no friction"))
    save_figure(fig, out / f"{am.label}.png")


def _check_method(args) -> tuple[str, Path | None]:
    if args.check == "law":
        return "law", None
    try:
        import fmpy  # noqa: F401
    except ImportError:
        if args.check == "fmu":
            raise
        return "law", None
    from drymount.fmu_build import ensure_fmu

    return "fmu", ensure_fmu(args.fmu)


def main(args) -> int:
    """Run ``drymount characterise`` (CLI arguments in ``args``); exit status."""
    from drymount.paths import load_with_overrides

    cfg = load_with_overrides(args.config, getattr(args, "overrides", None) or ())
    fmin = args.fmin if args.fmin is not None else cfg.sweep.fmin_hz
    fmax = args.fmax if args.fmax is not None else cfg.sweep.fmax_hz
    freqs = np.linspace(fmin, fmax, args.points)
    amps = np.array(args.amplitudes_mm) * 1e-3
    preloads = np.array(args.preloads)
    from drymount.cli_guard import check_out_dir

    out = check_out_dir(Path(args.out or f"{cfg.name}_characterise"), "--out")
    out.mkdir(parents=True, exist_ok=True)
    maps = characterise(cfg.system, freqs, amps, preloads, progress=not args.quiet)
    for am in maps:
        _write_map(out, am, f"configuration {cfg.source}")
        k = am.map.magnitude
        print(f"{am.label:<18} |K*| {k.min():.4g} to {k.max():.4g} N/m, loss angle "
              f"{am.map.loss_angle_deg.min():.3g} to {am.map.loss_angle_deg.max():.3g} "
              f"deg")
    method, fmu_path = _check_method(args)
    checks = cross_check(maps, method, fmu_path)
    write_csv(out / "crosscheck.csv",
              ["axis", "method", "freq_hz", "amplitude_m", "preload_N",
               "mean_deflection_m", "K_hbm_real", "K_hbm_imag", "K_time_real",
               "K_time_imag", "rel_error"],
              [(c.label, c.method, c.freq_hz, c.amplitude, c.preload,
                c.mean_deflection, c.K_hbm.real, c.K_hbm.imag, c.K_time.real,
                c.K_time.imag, c.rel_error) for c in checks],
              comment="harmonic balance vs time domain (FMU or law), K* in N/m")
    worst = max(c.rel_error for c in checks)
    print(f"cross-check against the {'FMU' if method == 'fmu' else 'law'} in the time "
          f"domain at {len(checks)} points: largest relative difference {worst:.2e} "
          f"(tolerance {CROSSCHECK_RTOL:g})")
    print(f"wrote {len(maps)} maps (CSV and PNG) and crosscheck.csv to {out}")
    if worst > CROSSCHECK_RTOL:
        print(f"drymount: error: the time-domain cross-check differs by {worst:.2e} "
              f"> {CROSSCHECK_RTOL:g}", file=sys.stderr)
        return 1
    return 0
