"""Co-simulation of the inclined two-surface friction mount (thesis Ch. 5) through
its FMU (``InclinedMount.fmu``, built by :mod:`fmu_build`) and fmpy.

:class:`InclinedFMU` is one FMU instance driven with the harness's convention (set
``u``, ``v`` at t_n, read the outputs, ``doStep(t_n, h)`` commits);
:func:`inclined_cosim_steady` integrates :class:`hbm.inclined.InclinedSDOF` (mass on
an elastomer and the element, weight + harmonic force) with the FMU giving the
element's force every step, by the same velocity-Verlet stepping as
:func:`hbm.inclined.inclined_time_reference`, until the period repeats.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fmu_build import ensure_fmu
from fmu_src.inclined import InclinedParameters
from fmu_src.inclined_mount import INCLINED_MODEL_NAME
from hbm.inclined import InclinedSDOF, inclined_time_reference

__all__ = ["InclinedFMU", "InclinedOutputs", "inclined_cosim_steady", "OUTPUT_NAMES"]

#: Real outputs of the FMU read by :meth:`InclinedFMU.outputs`, in that order.
OUTPUT_NAMES = ("F", "N", "N2", "f1", "f2", "kt", "E_fr")
_PARAM_NAMES = ("theta_deg", "k", "kf", "kf2", "mu1", "mu2", "preload")


@dataclass(frozen=True)
class InclinedOutputs:
    """The FMU's outputs at the current inputs: forces in N, ``kt`` in N/m, ``E_fr``
    (cumulative dissipated energy) in J, the two slip flags."""

    F: float
    N: float
    N2: float
    f1: float
    f2: float
    kt: float
    E_fr: float
    slip1: bool
    slip2: bool


class InclinedFMU:
    """One InclinedMount FMU instance through fmpy's ``FMU2Slave`` (a context manager).

    ``InclinedFMU(p, dt)`` builds the default FMU if missing or stale
    (:func:`ensure_fmu`; a given ``fmu_path`` is used as is),
    instantiates it, sets the parameters of ``p`` and initializes it (ValueError
    with the FMU's message if it rejects them). Calling it, ``fmu(x, v, t) -> F``,
    sets the inputs at ``t``, reads the force and commits with ``doStep(t, dt)``
    (RuntimeError with the FMU's message if it refuses the step, e.g. lost
    contact). ``messages`` holds what the FMU logged.
    """

    def __init__(self, p: InclinedParameters, dt: float, fmu_path=None):
        from fmpy import extract, read_model_description
        from fmpy.fmi2 import FMU2Slave

        self.dt = float(dt)
        self.messages: list[str] = []
        self._live = False
        self._failed = False   # after fmi2Fatal only fmi2FreeInstance is called
        # a user's FMU is used as is; only drymount's default one is (re)built
        self.path = (ensure_fmu(model=INCLINED_MODEL_NAME) if fmu_path is None
                     else Path(fmu_path))
        md = read_model_description(str(self.path))
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self._unzipdir = extract(str(self.path))
        self._fmu = FMU2Slave(guid=md.guid, unzipDirectory=self._unzipdir,
                              modelIdentifier=md.coSimulation.modelIdentifier,
                              instanceName="inclined")
        self._fmu.instantiate(callbacks=self._callbacks(), loggingOn=True)
        self._live = True
        try:
            self._fmu.setupExperiment(startTime=0.0)
            self._fmu.enterInitializationMode()
            self._fmu.setReal([self.vr[n] for n in _PARAM_NAMES],
                              [float(getattr(p, n)) for n in _PARAM_NAMES])
            self._fmu.exitInitializationMode()
        except Exception as exc:
            self._failed = True
            self.close()
            raise ValueError(f"InclinedMount FMU rejected its parameters: "
                             f"{' | '.join(self.messages) or exc}") from exc
        self._uv = [self.vr["u"], self.vr["v"]]
        self._out = [self.vr[n] for n in OUTPUT_NAMES]
        self._flags = [self.vr["slip1"], self.vr["slip2"]]

    def _callbacks(self):
        from vehicle import fmi_logging

        def logger(env, instance, status, category, message):
            self.messages.append(message.decode("utf-8", "replace") if message else "")

        cb = fmi_logging.callbacks(logger)  # one process-wide logger (see module)
        self._cb = cb   # the FMU keeps pointers into it: keep it alive
        return cb

    def get_state(self):
        """The FMU's state (``fmi2GetFMUstate``), for :meth:`set_state`."""
        return self._fmu.getFMUState()

    def set_state(self, state) -> None:
        """Restore a state of :meth:`get_state` (``fmi2SetFMUstate``)."""
        self._fmu.setFMUState(state)

    def set_inputs(self, u: float, v: float = 0.0) -> None:
        """Deflection ``u`` (m) and its rate ``v`` (m/s) at the current time."""
        self._fmu.setReal(self._uv, [u, v])

    def outputs(self) -> InclinedOutputs:
        """The trial outputs at the current inputs (commits nothing)."""
        vals = self._fmu.getReal(self._out)
        slip = self._fmu.getBoolean(self._flags)
        return InclinedOutputs(*vals, bool(slip[0]), bool(slip[1]))

    def commit(self, t: float) -> None:
        """``doStep(t, dt)``: the state follows the inputs set at ``t``."""
        try:
            self._fmu.doStep(currentCommunicationPoint=t, communicationStepSize=self.dt)
        except Exception as exc:   # fmpy raises on fmi2Discard/fmi2Error
            self._failed = True
            raise RuntimeError(f"InclinedMount FMU refused the step at t = {t!r} s: "
                               f"{' | '.join(self.messages[-3:]) or exc}") from exc

    def __call__(self, x: float, v: float, t: float) -> float:
        self._fmu.setReal(self._uv, [x, v])
        try:
            force = self._fmu.getReal(self._out[:1])[0]
        except Exception as exc:   # fmpy raises on fmi2Error (e.g. lost contact)
            self._failed = True
            raise RuntimeError(f"InclinedMount FMU failed at t = {t!r} s, u = {x!r} m: "
                               f"{' | '.join(self.messages[-3:]) or exc}") from exc
        self.commit(t)
        return force

    def close(self) -> None:
        """Terminate (unless a call failed) and free the instance, remove the
        extracted FMU (idempotent)."""
        import shutil

        if self._live:
            self._live = False
            try:
                if not self._failed:
                    self._fmu.terminate()
            finally:
                self._fmu.freeInstance()
                shutil.rmtree(self._unzipdir, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def inclined_cosim_steady(sys: InclinedSDOF, freq_hz: float, *, steps: int = 1000,
                          periods: int = 400, rtol: float = 1e-7,
                          fmu_path: str | os.PathLike | None = None) -> np.ndarray:
    """Displacement samples (m) of the last period of the co-simulation of ``sys`` at
    ``freq_hz`` with the element's force from the InclinedMount FMU (``steps`` per
    period, until two periods differ by ``rtol`` of the peak-to-peak, at most
    ``periods``)."""
    with InclinedFMU(sys.p, 1.0 / (freq_hz * steps), fmu_path) as fmu:
        return inclined_time_reference(sys, freq_hz, periods=periods, steps=steps,
                                        rtol=rtol, element=fmu)

