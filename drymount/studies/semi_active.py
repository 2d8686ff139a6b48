"""Study ``semi-active``: passive vs controlled normal force in co-simulation (issue 14
item 4).

On the quarter car (``quarter_car_halved``) and the 6-DOF engine (``six_dof_halved``),
time-domain scenarios:

* **run-up**: the crank excitation of an inline four (thesis eq. 1.3,
  :class:`vehicle.inputs.CrankRunUp`) from 600 to 6000 rpm, chassis at rest;
* **road**: an ISO 8608 class C random road at 20 m/s under the tyre of the quarter
  car, engine not running;
  for the 6-DOF engine the chassis points move as the body of that quarter car on
  the road (:class:`vehicle.inputs.SuspendedRoad`: one-way, all corners in phase);
* **road rig** (6-DOF): the same profile straight into the chassis attachment points
  (vertical), i.e. a shaker rig without a suspension: the mounts deflect far past
  their knee (issue 26 item 3). A labelled rig case, not a road.

And on the single-DOF engine (``sdof_halved``), the unbalance at 3 Hz (stuck band),
4.2 Hz (resonance) and 8 Hz, measured over the last periods of a run from rest.

Designs, each simulated with the in-process law (``backend="inproc"``, the FMU's law):

* ``passive original``: the preset's normal force n0;
* ``passive best n0``: the constant n0 among ``N0_FACTORS`` x n0 with the smallest RMS
  transmitted force in that scenario;
* ``scheduled``: n(t) from a table of the HBM's best n0 per excitation frequency
  (``hbm.solve_frequencies`` with the crank load at each frequency, same n0 grid),
  looked up at the run-up's second-order frequency (run-up only);
* ``balance``, ``skyhook``, ``growth`` (:mod:`vehicle.control`): ``n_on`` =
  ``ONOFF_FACTOR`` x n0 while on, 0 while off; balance: on while the friction force
  opposes the elastic force (``u v < 0``); skyhook: while it opposes the engine's
  absolute velocity; growth: while the deflection grows (the former ``on/off``, which
  adds to the transmitted force); rate limited to ``RATE_MAX_PER_N0`` n0 per second.

Transmitted force: the sum of the mounts' axial forces (the force the engine puts
into the chassis along the vertical for these layouts); engine displacement: DOF
``engine`` (quarter car) or ``z`` (6-DOF). Outputs: ``semi_active.csv``,
``semi_active.md`` (Markdown table) and one plot per model.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

import drymount.hbm as hbm
from drymount.io import atomic_write_text, write_csv
from drymount.studies.common import engine_excited, load_system
from drymount.studies.output import md_table, new_figure, progress_bar, save_fig
from drymount.fmu_src.mount_law import AXES, MountParameters
from drymount.hbm.system import Excitation, System, Transmissibility
from drymount.vehicle import CrankRunUp, Master, RandomRoad
from drymount.vehicle.inputs import HarmonicInput, SuspendedRoad
from drymount.vehicle import control as vc
from drymount.vehicle.control import Limits, ScheduledControl

#: Models of the study: (label, preset, engine DOF, scenarios).
MODELS = (("single-DOF", "sdof_halved", "x", ("unbalance 3 Hz", "unbalance 4.2 Hz",
                                              "unbalance 8 Hz")),
          ("quarter car", "quarter_car_halved", "engine", ("run-up", "road")),
          ("6-DOF engine", "six_dof_halved", "z", ("run-up", "road", "road rig")))
#: Unbalance runs: periods from rest, of which the last ones are measured (steady).
UNBALANCE_PERIODS, UNBALANCE_MEASURED = 34, 4
#: Constant normal forces tried for "passive best n0", times the preset's n0.
N0_FACTORS = (0.1, 0.3, 1.0, 3.0)
#: Frequencies of the HBM schedule table, Hz (second order at 600-6000 rpm: 20-200).
SCHEDULE_HZ = (20.0, 40.0, 80.0, 140.0, 200.0)
#: on/off law: n_on = ONOFF_FACTOR * n0, n_off = 0.
ONOFF_FACTOR = 2.0
#: Rate limit of the controllers, n0 per second (a 10 ms full swing).
RATE_MAX_PER_N0 = 100.0
#: Run-up and road durations, s: (full, quick); the steps, s.
RUNUP_S = (8.0, 1.0)
ROAD_S = (8.0, 1.5)
DT_RUNUP, DT_ROAD = 1.0 / (200.0 * 32), 5e-4
ROAD_CLASS, ROAD_SPEED = "C", 20.0


@dataclass(frozen=True)
class Run:
    """One simulated design: metrics in N and m, and the series for plots."""

    model: str
    scenario: str
    design: str
    n0: float
    rms_force: float
    peak_force: float
    rms_disp: float
    peak_disp: float
    t: np.ndarray
    force: np.ndarray


def _n0(system: System) -> float:
    return max(p.n0 for e in system.elements for p in e.params.axes if p.friction)


def _scaled_n0(system: System, n0: float) -> System:
    """Every friction axis at normal force ``n0`` (N, > 0)."""
    params = [MountParameters(**{a: replace(p, n0=n0) if p.friction else p
                                 for a, p in zip(AXES, e.params.axes)})
              for e in system.elements]
    return system.with_mount_params(params)


def _crank_system(system: System) -> System:
    """``system`` loaded by the engine's second order (HBM), chassis fixed."""
    if system.n_dof == 6:
        return engine_excited(system)
    from drymount.studies.common import ENGINE_EXCITATION as eng

    u = np.zeros(system.n_dof)
    u[list(system.dof_names).index("engine")] = eng.unbalance_z
    return replace(system, excitation=Excitation("unbalance", u),
                   transmissibility=Transmissibility("force", forces=((0, 0),)))


def hbm_schedule(system: System, n0_grid, freqs=SCHEDULE_HZ, harmonics: int = 3
                 ) -> tuple[np.ndarray, np.ndarray]:
    """The n0 of ``n0_grid`` with the smallest HBM transmissibility at each of
    ``freqs`` (Hz) under the crank load: ``(freqs, n0 per freq)``."""
    best = np.full(len(freqs), np.inf)
    best_n = np.full(len(freqs), np.nan)
    for n0 in n0_grid:
        fr = hbm.solve_frequencies(_crank_system(_scaled_n0(system, n0)), freqs,
                                   harmonics=harmonics)
        tr = np.full(len(freqs), np.inf)
        tr[:fr.n_points] = fr.transmissibility
        better = tr < best
        best[better], best_n[better] = tr[better], n0
    if np.any(np.isnan(best_n)):
        missing = np.asarray(freqs)[np.isnan(best_n)]
        raise RuntimeError(f"HBM schedule: no solution at {missing} Hz")
    return np.asarray(freqs, dtype=float), best_n


def _inputs(system: System, scenario: str, quick: bool):
    if scenario.startswith("unbalance"):
        f = float(scenario.split()[1])
        return HarmonicInput(system, f), UNBALANCE_PERIODS / f, 1.0 / (256 * f)
    if scenario == "run-up":
        dur = RUNUP_S[1] if quick else RUNUP_S[0]
        return CrankRunUp(system, 600.0, 6000.0, dur), dur, DT_RUNUP
    dur = ROAD_S[1] if quick else ROAD_S[0]
    if scenario == "road" and "sprung" not in system.dof_names:
        # a body on the quarter car's suspension under every attachment point
        return SuspendedRoad(system, ROAD_CLASS, ROAD_SPEED, seed=1), dur, DT_ROAD
    return RandomRoad(system, ROAD_CLASS, ROAD_SPEED, seed=1), dur, DT_ROAD


def _simulate(system, inputs, dur, dt, control, engine_dof):
    with Master(system, "inproc", control=control) as m:
        th = m.simulate(dur, dt=dt, inputs=inputs)
    axial = [i for i, name in enumerate(th.force_names) if name.endswith("_axial")]
    f = th.forces[:, axial].sum(axis=1)
    x = th.q[:, list(th.dof_names).index(engine_dof)]
    return th.t, f, x


def _controllers(system: System, scenario: str, inputs, schedule, n0: float):
    keys = [(e.name, AXES[j]) for e in system.elements for j in e.active_axes
            if e.params.axes[j].friction]
    lim = Limits(0.0, math.inf, RATE_MAX_PER_N0 * n0)
    if scenario == "run-up":
        f, n = schedule
        ctl = ScheduledControl(tuple(f), tuple(n), signal=lambda t: float(
            inputs.second_order(t)), limits=lim)
        out = {"scheduled": {k: ctl for k in keys}}
    else:
        out = {}
    n_on = ONOFF_FACTOR * n0
    for name, law in (("balance", vc.BalanceControl), ("growth", vc.GrowthControl)):
        out[name] = {k: law(n_on, 0.0, lim, vc.macro_slip_contact(system, *k))
                     for k in keys}
    out["skyhook"] = {k: vc.SkyhookControl(
        n_on, 0.0, lim, vc.macro_slip_contact(system, *k),
        velocity=vc.engine_velocity(system, *k)) for k in keys}
    return out


def _run_model(label, preset, dof, scenarios, quick, progress) -> list[Run]:
    system = load_system(preset)
    n0 = _n0(system)
    grid = [k * n0 for k in N0_FACTORS]
    schedule = hbm_schedule(system, grid) if "run-up" in scenarios else None
    runs = []
    for scenario in scenarios:
        inputs, dur, dt = _inputs(system, scenario, quick)

        def run(design, sys_, control, n_value):
            t, f, x = _simulate(sys_, inputs, dur, dt, control, dof)
            x = x - x[0]
            if scenario.startswith("unbalance"):  # the steady periods only
                keep = int(round(UNBALANCE_MEASURED / (dt * inputs.freq_hz)))
                t, f, x = t[-keep:], f[-keep:], x[-keep:]
            runs.append(Run(label, scenario, design, n_value,
                            float(np.sqrt(np.mean(f * f))), float(np.max(np.abs(f))),
                            float(np.sqrt(np.mean(x * x))), float(np.max(np.abs(x))),
                            t, f))
            return runs[-1]

        passive = [run("passive", _scaled_n0(system, n), None, n)
                   for n in progress_bar(grid, f"{label} {scenario}", progress)]
        best = min(passive, key=lambda r: r.rms_force)
        runs = [r for r in runs if all(r is not q for q in passive)]
        runs.append(replace(next(r for r in passive if r.n0 == n0),
                            design="passive original"))
        runs.append(replace(best, design="passive best n0"))
        for name, ctl in _controllers(system, scenario, inputs, schedule, n0).items():
            run(name, system, ctl, float("nan"))
    return runs, schedule


HEADER = ("model", "scenario", "design", "n0_N", "rms_force_N", "peak_force_N",
          "rms_engine_disp_mm", "peak_engine_disp_mm")


def _row(r: Run) -> list:
    return [r.model, r.scenario, r.design, r.n0, r.rms_force, r.peak_force,
            1e3 * r.rms_disp, 1e3 * r.peak_disp]


def _window_rms(t, f, width: float = 0.05):
    n = max(1, int(round(width / (t[1] - t[0]))))
    m = len(f) // n
    g = f[:m * n].reshape(m, n)
    return t[:m * n].reshape(m, n).mean(1), np.sqrt((g * g).mean(1))


PLOT_NAMES = {"x": "sdof", "engine": "quarter", "z": "six_dof"}


def _plot(model: str, runs: list[Run], path: Path, scenarios) -> None:
    fig = new_figure(figsize=(10, 3.5 * len(scenarios)), layout="constrained")
    axes = fig.subplots(len(scenarios), 1)
    for ax, scenario in zip(axes, scenarios):
        for r in runs:
            if r.scenario == scenario:
                tw, fw = _window_rms(r.t, r.force)
                ax.plot(tw, fw, label=f"{r.design} (RMS {r.rms_force:.3g} N)")
        what = ("crank run-up 600-6000 rpm" if scenario == "run-up"
                else f"ISO 8608 class {ROAD_CLASS} road at {ROAD_SPEED:g} m/s"
                + (" straight to the chassis points (rig)" if scenario == "road rig"
                   else "") if scenario.startswith("road") else scenario)
        ax.set_title(f"{model}: {what}")
        ax.set_xlabel("time [s]")
        ax.set_ylabel("transmitted force, 50 ms RMS [N]")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(f"Semi-active normal force, {model}: transmitted force")
    save_fig(fig, path)


def _markdown(runs: list[Run], schedules: dict, quick: bool) -> str:
    lines = [f"# Semi-active normal force ({'quick' if quick else 'full'} mode)", "",
             md_table(["model", "scenario", "design", "n0 [N]", "RMS force [N]",
                       "peak force [N]", "RMS engine disp. [mm]",
                       "peak engine disp. [mm]"], [_row(r) for r in runs]), "",
             "HBM schedule (best n0 per second-order frequency, crank load):", ""]
    for model, (f, n) in schedules.items():
        lines.append(f"- {model}: " + ", ".join(
            f"{fi:g} Hz -> {ni:.4g} N" for fi, ni in zip(f, n)))
    return "\n".join(lines) + "\n"


def run_semi_active(out_dir, quick: bool = False, progress: bool = True) -> dict:
    """Run the study into ``out_dir``.

    Returns ``{"files": [...], "failures": [], "rms_force": {"<model>/<scenario>/
    <design>": N}}``; ``summary.md`` holds the Markdown table.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    runs, schedules, files = [], {}, []
    for label, preset, dof, scenarios in MODELS:
        model_runs, sched = _run_model(label, preset, dof, scenarios, quick, progress)
        if sched is not None:
            schedules[label] = sched
        runs += model_runs
        png = out / f"semi_active_{PLOT_NAMES[dof]}.png"
        _plot(label, model_runs, png, scenarios)
        files.append(png)
    files.append(write_csv(
        out / "semi_active.csv", HEADER, [_row(r) for r in runs],
        comment="drymount study semi-active: passive vs controlled normal force"))
    files.append(atomic_write_text(out / "summary.md",
                                   _markdown(runs, schedules, quick)))
    return {"files": files, "failures": [],
            "rms_force": {f"{r.model}/{r.scenario}/{r.design}": r.rms_force
                          for r in runs}}
