"""Mount-force backends of the co-simulation master: in-process law or an FMU per mount.

Both backends run the same fixed-step loop of :mod:`vehicle.master` over a row buffer
``rec`` (one row per step, layout in :class:`Layout`): at step k they read the local
deflections ``u``, rates ``v`` of every active mount axis from row k, write the mount
outputs (force ``F``, friction force ``Ffr`` per active axis, cumulative friction energy
``E`` per mount) into row k, and advance the linear part with one matrix-vector product
``rec[k+1, :n_next] = W @ rec[k, o_x:]`` (see :mod:`vehicle.master`).

``inproc`` (``native`` before, a deprecated alias now)
    calls :func:`fmu_src.mount_law.axis_force` (the FMU's own law) in-process, one call
    per active axis and step, and commits the slider positions at once.
``fmu``
    drives one instance of ``FrictionMount.fmu`` per mount, set up through fmpy's
    ``FMU2Slave``; the stepping loop calls the FMU's own ``fmi2SetReal`` /
    ``fmi2GetReal`` / ``fmi2DoStep`` directly through ctypes (:func:`raw_fmi_calls`:
    every argument prebuilt, preallocated value-reference arrays, the real buffers
    pointers into the row buffer), so no value is copied and no object is made in
    Python per step. Per mount and step exactly one
    ``fmi2SetReal`` (``u_<axis>``, ``v_<axis>`` of the active axes), one ``fmi2GetReal``
    (``F_<axis>``, ``Ffr_<axis>`` of the active axes and ``E_fr``) and one
    ``fmi2DoStep(t_k, h)`` (commits the sliders) are made. Logging is on; the FMU's
    messages are kept (last 50 per instance) and quoted in errors. Any failure is
    re-raised as :class:`FMUError` naming the mount and the simulation time, and
    :meth:`FMUBackend.close` always terminates and frees every instance. An FMI 3.0
    build (``FrictionMountNative3.fmu``) runs through :mod:`vehicle.fmi3_adapter`.

Both follow the FMU protocol (docs/fmu.md): the force at t_k is the trial
return map ``law(u_k, v_k, w_{k-1})``; the step commits ``w_k = w_new(u_k)``; the energy
output includes the dissipation of the current trial (``E_fr`` = committed + trial).
"""

from __future__ import annotations

import collections
import ctypes
import logging
import shutil
import warnings

import numpy as np

from drymount.fmu_src.friction import flat_state
from drymount.fmu_src.interface import SLIDER_SLOTS, by_causality
from drymount.vehicle.c_loop import for_backend as c_loop_for
from drymount.vehicle.layout import Layout
from drymount.vehicle.raw_calls import raw_fmi_calls
from drymount.fmu_src.mount_law import (AXES, axis_force, conform_state,
                                        friction_kind_code, initial_sliders, law_code,
                                        slider_position)

__all__ = ["Layout", "InProcessBackend", "FMUBackend", "FMUError", "BACKENDS",
           "make_backend"]

_log = logging.getLogger(__name__)

#: FMU variables the harness reads or writes, per axis and global (names as in
#: ``fmu_src.interface``); plus every parameter of the interface table.
FMU_AXIS_VARIABLES = ("u", "v", "F", "Ffr", "w", "E_fr")


def fmu_parameter_values(params) -> dict[str, dict]:
    """FMU start values of a mount's ``MountParameters`` by FMI type:
    ``{"Real": {name: float}, "Integer": {...}, "Boolean": {...}}`` for every
    parameter of the interface table (``law`` as its integer code)."""
    out = {"Real": {}, "Integer": {}, "Boolean": {}}
    for var in by_causality("parameter"):
        axis, _, field = var.name.partition("_")
        value = getattr(params.axes[AXES.index(axis)], field)
        if field == "law":
            value = law_code(value)
        elif field == "friction_kind":
            value = friction_kind_code(value)
        cast = {"Real": float, "Integer": int, "Boolean": bool}[var.type]
        out[var.type][var.name] = cast(value)
    return out


class FMUError(RuntimeError):
    """An FMU call failed. Attributes: ``mount`` (name), ``time`` (s), ``function``
    (FMI function name or None), ``status`` (FMI status or None), ``log`` (the
    instance's last log messages)."""

    def __init__(self, mount: str, time: float, message: str, *, function=None,
                 status=None, log=()):
        self.mount = mount
        self.time = time
        self.function = function
        self.status = status
        self.log = list(log)
        text = f"FMU of mount {mount!r} failed at t = {time:.9g} s: {message}"
        if self.log:
            text += "\nFMU log (last messages):\n  " + "\n  ".join(self.log)
        super().__init__(text)


class _Backend:
    """Shared bookkeeping. Subclasses implement ``bind``, ``run``, ``sliders``,
    ``energy``, ``set_sliders``, ``close``."""

    name = ""

    def __init__(self, system, layout: Layout):
        self.system = system
        self.layout = layout
        self.steps = 0  # mount-force evaluations (steps) done
        self._rec = None
        self._ctl = []      # controlled axes: [global index, u col, v col, controller]
        self._n_ctl = []    # their last applied normal forces, N
        self.control_log = None

    def set_element_states(self, states: dict) -> None:
        """Set whole friction-element states ``{(mount index, axis index): state}``
        (the element's own state, e.g. an ``fmu_src.inclined.InclinedState``), not
        only the one-number position of :meth:`set_sliders`. The in-process backend
        sets the state; the FMU backend its position ``w_<axis>`` and then its
        sliders ``w1_<axis>``, ``w2_<axis>`` (``FrictionElement.slider_slots``); a
        backend without either refuses."""
        raise ValueError(f"the {self.name!r} backend cannot set a whole friction-"
                         f"element state (its w_<axis> relaxes the element); use "
                         f"backend 'inproc' (the same law in-process)")

    def set_control(self, controls: dict) -> None:
        """Drive normal forces from ``controls`` = ``{(mount name, axis name):
        controller}`` (:mod:`vehicle.control`) at every step; ``{}`` switches off.

        The first command is rate-limited from the axis's ``n0``; the applied forces
        are kept in :attr:`control_log` (:class:`vehicle.control.ControlLog`).
        """
        from drymount.vehicle.control import ControlLog

        L, names = self.layout, [e.name for e in self.system.elements]
        cols = L.columns()
        by_key = {(names[e], AXES[j]): (i, e, j) for (i, e, j) in L.axes()}
        ctl, n0, labels = [], [], []
        for key, c in controls.items():
            if key not in by_key:
                raise ValueError(f"control of {key!r}: no active mount axis of that "
                                 f"(mount, axis); active: {sorted(by_key)}")
            i, e, j = by_key[key]
            p = self.system.elements[e].params.axes[j]
            if not p.friction:
                raise ValueError(f"control of {key!r}: the axis has no friction "
                                 f"element, so its normal force does nothing")
            if not p.element.uses_normal_input:
                raise ValueError(f"control of {key!r}: the axis's friction element "
                                 f"{p.friction_kind!r} does not read the normal-force "
                                 f"input n_<axis> (its normal forces follow from its "
                                 f"own state)")
            ctl.append([i, int(cols["u"][i]), int(cols["v"][i]), c, p])
            n0.append(float(p.n0))
            labels.append(f"{key[0]}_{key[1]}")
        self._ctl, self._n_ctl = ctl, n0
        self._ctl_targets = None
        self.control_log = ControlLog(tuple(labels)) if ctl else None

    def _commands(self, t: float, uv, h: float, row=None) -> list[float]:
        """Apply every controller at time ``t`` to the row values ``uv`` (and the
        whole row ``row`` of the step, for laws that sense the DOFs); returns the
        limited normal forces (and logs them)."""
        n_ctl = self._n_ctl
        for idx, (_i, iu, iv, c, _p) in enumerate(self._ctl):
            n_ctl[idx] = c.limits.apply(c.command(t, uv[iu], uv[iv], row, h),
                                        n_ctl[idx], h)
        self.control_log.add(t, n_ctl)
        return n_ctl

    def _bind_common(self, rec: np.ndarray, W: np.ndarray) -> None:
        L = self.layout
        if rec.ndim != 2 or rec.shape[1] != L.width or not rec.flags.c_contiguous:
            raise ValueError("row buffer must be C-contiguous with the layout width")
        self._rec = rec
        self._W = W
        self._ins = [rec[k, L.o_x:] for k in range(rec.shape[0] - 1)]
        self._nexts = [rec[k + 1, :L.n_next] for k in range(rec.shape[0] - 1)]

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class InProcessBackend(_Backend):
    """The mount law of :mod:`fmu_src.mount_law` called in-process (no FMI): the
    backend ``"inproc"`` (called ``"native"`` before: that word now means only the
    C FMU, ``fmu_build.native``)."""

    name = "inproc"

    def __init__(self, system, layout: Layout):
        super().__init__(system, layout)
        cols = layout.columns()
        o = layout.o_out
        self._axes = []
        for (i, e, j) in layout.axes():
            p = system.elements[e].params.axes[j]
            # UV starts at column 0, OUT positions are relative to o_out
            self._axes.append((
                int(cols["u"][i]), int(cols["v"][i]), int(cols["F"][i]) - o,
                int(cols["Ffr"][i]) - o, e, p))
        self._e_pos = [(e, layout.out_off(e) - layout.o_out + 2 * layout.m_of(e))
                       for e in range(layout.n_mounts)]
        # friction state of the active axes: each element's own (a float or a
        # tuple of floats, fmu_src.mount_law.initial_sliders)
        self._w = [initial_sliders(a[5]) for a in self._axes]
        self._E = [0.0] * layout.n_mounts    # committed friction energy per mount, J
        self._E_axis = [0.0] * layout.m

    def bind(self, rec, W, h):
        self._bind_common(rec, W)
        L = self.layout
        self._h_step = float(h)
        self._uvs = [rec[k, :2 * L.m] for k in range(rec.shape[0] - 1)]
        self._outs = [rec[k, L.o_out:L.o_out + L.n_out]
                      for k in range(rec.shape[0] - 1)]

    def run(self, k0: int, k1: int, times) -> None:
        Wdot, ins, nexts = self._W.dot, self._ins, self._nexts
        uvs, outs, axes, w = self._uvs, self._outs, self._axes, self._w
        E, E_axis, e_pos = self._E, self._E_axis, self._e_pos
        template = [0.0] * self.layout.n_out
        n_in = [None] * len(axes)  # normal forces of the controlled axes
        h = self._h_step
        for k in range(k0, k1):
            # the increment the outputs of row k span: 0 at the very first row, as
            # in the FMU (read by rate-dependent friction elements only)
            dt = h if k or self.steps else 0.0
            uv = uvs[k].tolist()
            if self._ctl:
                n = self._commands(times[k - k0], uv, h, self._rec[k])
                for (i, _iu, _iv, _c, _p), ni in zip(self._ctl, n):
                    n_in[i] = ni
            out = template[:]
            i = 0
            for (iu, iv, iF, iFr, e, p) in axes:
                f, ffr, wn, _kt, _slip, diss = axis_force(uv[iu], uv[iv], w[i], p,
                                                          n_in[i], dt)
                w[i] = wn
                out[iF] = f
                out[iFr] = ffr
                if diss:
                    E[e] += diss
                    E_axis[i] += diss
                i += 1
            for e, pos in e_pos:
                out[pos] = E[e]
            outs[k][:] = out
            Wdot(ins[k], nexts[k])  # np.dot(W, x, out=y) without keyword parsing
        self.steps += k1 - k0

    def sliders(self) -> np.ndarray:
        """Friction-element positions, shape (n_mounts, 3), m (0 on inactive axes;
        each element's ``position``, as the FMU's ``w_<axis>``)."""
        out = np.zeros((self.layout.n_mounts, 3))
        for (i, e, j) in self.layout.axes():
            out[e, j] = slider_position(self._axes[i][5], self._w[i])
        return out

    def set_sliders(self, w) -> None:
        """Relax the friction elements at ``w`` (n_mounts, 3), m (each element's
        ``start``, as setting the FMU's ``w_<axis>``)."""
        w = np.asarray(w, dtype=float)
        for (i, e, j) in self.layout.axes():
            self._w[i] = initial_sliders(self._axes[i][5], float(w[e, j]))

    def set_element_states(self, states: dict) -> None:
        index = {(e, j): i for (i, e, j) in self.layout.axes()}
        for (e, j), state in states.items():
            i = index.get((e, j))
            if i is None:
                raise ValueError(f"element state for mount {e} axis {j}: not an "
                                 f"active axis of the system")
            self._w[i] = conform_state(self._axes[i][5], state)

    def energy(self) -> np.ndarray:
        """Committed friction energy per mount, shape (n_mounts,), J."""
        return np.array(self._E, dtype=float)

    def close(self) -> None:
        pass


class FMUBackend(_Backend):
    """One ``FrictionMount.fmu`` instance per mount through fmpy's ``FMU2Slave``.

    Parameters
    ----------
    system : hbm.system.System
    layout : Layout
    fmu_path : path-like or None
        The FMU; None: ``fmu_build.ensure_fmu()`` (builds
        ``dist/FrictionMount.fmu`` when missing or stale).
    logging_on : bool
        FMU debug logging (default on; messages are kept and quoted in errors).
    start_values : dict, optional
        Extra ``{variable name: value}`` set on every instance before initialisation
        (after the mount parameters, so it can override them); an entry
        ``{mount name: {variable name: value}}`` applies to that mount only.
    """

    name = "fmu"

    def __init__(self, system, layout: Layout, fmu_path=None, *, logging_on=True,
                 start_values=None):
        super().__init__(system, layout)
        from fmpy import extract, read_model_description

        import drymount.vehicle.fmi_logging as fmi_logging

        if fmu_path is None:
            from drymount.fmu_build import ensure_fmu
            fmu_path = ensure_fmu()
        self.fmu_path = str(fmu_path)
        self._fmus = []        # FMU2Slave objects (library loaded)
        self._state = []       # "loaded" | "instantiated" | "initialized" | "failed"
        self._unzipdir = None
        self._messages = {}
        self.time = 0.0
        md = read_model_description(self.fmu_path)
        self._vars = {v.name: v for v in md.modelVariables}
        needed = [f"{p}_{a}" for a in AXES for p in FMU_AXIS_VARIABLES]
        needed += ["E_fr"] + [v.name for v in by_causality("parameter")]
        missing = [n for n in needed if n not in self._vars]
        if missing:
            raise ValueError(f"FMU {self.fmu_path!r} lacks the variables {missing} "
                             "required by the harness (see the FMU interface)")
        if md.coSimulation is None:
            raise ValueError(f"FMU {self.fmu_path!r} does not support co-simulation")
        mounts = [e.name for e in system.elements]
        common = {}
        self._start_values = {name: {} for name in mounts}
        for key, value in dict(start_values or {}).items():
            if key in self._start_values and isinstance(value, dict):
                self._start_values[key].update(value)
            else:
                common[key] = value
        for name in mounts:
            self._start_values[name] = {**common, **self._start_values[name]}
        bad = sorted({n for d in self._start_values.values() for n in d
                      if n not in self._vars})
        if bad:
            raise ValueError(f"`fmu_start_values` names unknown FMU variables {bad}")

        def logger(env, instance, status, category, message):
            name = instance.decode("utf-8", "replace") if instance else "?"
            text = message.decode("utf-8", "replace") if message else ""
            label = ["OK", "WARNING", "DISCARD", "ERROR", "FATAL", "PENDING"][status] \
                if 0 <= status <= 5 else str(status)
            self._messages.setdefault(name, collections.deque(maxlen=50)).append(
                f"[{label}] {text}")
            if status >= 1:
                _log.warning("FMU %s [%s] %s", name, label, text)

        cb = fmi_logging.callbacks(logger)  # one process-wide logger (see module)
        self._callbacks = cb
        self._logger = logger
        try:
            self._unzipdir = extract(self.fmu_path)
            for e, el in enumerate(system.elements):
                self._setup_instance(e, el, md, logging_on)
        except BaseException:
            self.close()
            raise
        self._make_references()

    # ---------------------------------------------------------------- setup
    def _instance_name(self, e: int) -> str:
        return self.system.elements[e].name

    def _setup_instance(self, e, el, md, logging_on):
        from fmpy.fmi2 import FMU2Slave

        name = el.name
        if md.fmiVersion.startswith("3"):  # e.g. FrictionMountNative3.fmu
            from drymount.vehicle.fmi3_adapter import FMU3Adapter

            fmu = FMU3Adapter(md, self._unzipdir, name, self._logger)
        else:
            fmu = FMU2Slave(guid=md.guid, unzipDirectory=self._unzipdir,
                            modelIdentifier=md.coSimulation.modelIdentifier,
                            instanceName=name)
        self._fmus.append(fmu)
        self._state.append("loaded")
        try:
            fmu.instantiate(callbacks=self._callbacks, loggingOn=bool(logging_on))
            self._state[e] = "instantiated"
            values = fmu_parameter_values(el.params)
            reals, ints, bools = values["Real"], values["Integer"], values["Boolean"]
            for n, v in self._start_values[name].items():
                typ = self._vars[n].type
                store = {"Real": reals, "Integer": ints, "Boolean": bools,
                         "Float64": reals, "Int32": ints}  # FMI 2.0 and 3.0 names
                store.get(typ, reals)[n] = v
            vr = self._vars
            if reals:
                fmu.setReal([vr[n].valueReference for n in reals],
                            [float(v) for v in reals.values()])
            if ints:
                fmu.setInteger([vr[n].valueReference for n in ints],
                               [int(v) for v in ints.values()])
            if bools:
                fmu.setBoolean([vr[n].valueReference for n in bools],
                               [bool(v) for v in bools.values()])
            fmu.setupExperiment(startTime=0.0)
            fmu.enterInitializationMode()
            fmu.exitInitializationMode()
            self._state[e] = "initialized"
        except Exception as exc:
            self._state[e] = "failed" if self._state[e] != "loaded" else "loaded"
            raise self._error(e, 0.0, exc) from exc

    def _make_references(self):
        L = self.layout
        vr = {n: v.valueReference for n, v in self._vars.items()}
        self._vin, self._vout, self._nin, self._nout = [], [], [], []
        for e, act in enumerate(L.active):
            ins = [vr[f"u_{AXES[j]}"] for j in act] + [vr[f"v_{AXES[j]}"] for j in act]
            outs = ([vr[f"F_{AXES[j]}"] for j in act]
                    + [vr[f"Ffr_{AXES[j]}"] for j in act] + [vr["E_fr"]])
            self._vin.append((ctypes.c_uint * len(ins))(*ins))
            self._vout.append((ctypes.c_uint * len(outs))(*outs))
            self._nin.append(len(ins))
            self._nout.append(len(outs))
        self._vr_w = [[vr[f"w_{a}"] for a in AXES] for _ in L.active]
        self._vr_E = vr["E_fr"]

    def bind(self, rec, W, h):
        self._bind_common(rec, W)
        L = self.layout
        self._h = float(h)
        base = rec.ctypes.data
        width = L.width
        dbl = ctypes.POINTER(ctypes.c_double)
        cast = ctypes.cast
        # the FMU's own functions, called directly (raw_fmi_calls: no fmpy frame, no
        # argument conversion); the step's time goes through one c_double
        self._t_arg = ctypes.c_double(0.0)
        raw = [raw_fmi_calls(fmu, self._h, self._t_arg) for fmu in self._fmus]
        self._calls = []
        for k in range(rec.shape[0] - 1):
            row = base + 8 * k * width
            self._calls.append([
                (e, r.set_real, r.set_args(self._vin[e], self._nin[e],
                                           cast(row + 8 * L.uv_off(e), dbl)),
                 r.get_real, r.get_args(self._vout[e], self._nout[e],
                                        cast(row + 8 * L.out_off(e), dbl)),
                 r.do_step, r.step_args)
                for e, r in enumerate(raw)])
        self._raw = raw
        # the same loop in C where it gives the same rows (vehicle.c_loop), else None
        self._c_loop = c_loop_for(self)

    # ---------------------------------------------------------------- stepping
    def run(self, k0: int, k1: int, times) -> None:
        if self._c_loop is not None and not self._ctl:
            return self._c_loop.run(k0, k1, times)
        # W.dot(x, y) is np.dot(W, x, out=y) (the same product, bit for bit) without
        # the keyword parsing: 0.4 against 0.6 us a step
        Wdot, ins, nexts, calls = self._W.dot, self._ins, self._nexts, self._calls
        h, t_arg, ctl = self._h, self._t_arg, self._ctl
        k = k0
        e = 0
        t = times[0] if len(times) else 0.0
        uvs = self._rec[:, :2 * self.layout.m] if ctl else None
        try:
            for k, t in zip(range(k0, k1), times):
                t_arg.value = t
                if ctl:
                    self._set_normal_forces(t, uvs[k].tolist(), h, self._rec[k])
                for e, S, sa, G, ga, D, da in calls[k]:
                    # status > fmi2Warning (1) fails, as fmpy's own wrappers
                    if (st := S(*sa)) > 1:
                        raise self._raw[e].failed("set", st)
                    if (st := G(*ga)) > 1:
                        raise self._raw[e].failed("get", st)
                    if (st := D(*da)) > 1:
                        raise self._raw[e].failed("step", st)
                Wdot(ins[k], nexts[k])
        except Exception as exc:
            self.steps += k - k0
            raise self._error(e, t, exc) from exc
        self.steps += k1 - k0
        self.time = t

    def _set_normal_forces(self, t: float, uv, h: float, row=None) -> None:
        """The controllers' normal forces into the inputs ``n_<axis>``."""
        n = self._commands(t, uv, h, row)
        if getattr(self, "_ctl_targets", None) is None:
            axes = self.layout.axes()
            self._ctl_targets = []
            for (i, *_rest) in self._ctl:
                _, e, j = axes[i]
                self._ctl_targets.append(
                    (self._fmus[e], [self._vars[f"n_{AXES[j]}"].valueReference]))
        for (fmu, vr), ni in zip(self._ctl_targets, n):
            fmu.setReal(vr, [ni])

    def _error(self, e: int, t: float, exc: Exception) -> FMUError:
        name = self._instance_name(e)
        function = getattr(exc, "function", None)
        status = getattr(exc, "status", None)
        if status is not None and status >= 4 and e < len(self._state):
            self._state[e] = "failed"  # fatal: only fmi2FreeInstance is allowed
        return FMUError(name, t, str(exc), function=function, status=status,
                        log=self._messages.get(name, ()))

    # ---------------------------------------------------------------- state access
    def sliders(self) -> np.ndarray:
        out = np.zeros((self.layout.n_mounts, 3))
        for e, fmu in enumerate(self._fmus):
            try:
                out[e] = fmu.getReal(self._vr_w[e])
            except Exception as exc:
                raise self._error(e, self.time, exc) from exc
        return out

    def set_sliders(self, w) -> None:
        w = np.asarray(w, dtype=float)
        for e, fmu in enumerate(self._fmus):
            try:
                fmu.setReal(self._vr_w[e], [float(x) for x in w[e]])
                back = fmu.getReal(self._vr_w[e])
            except Exception as exc:
                raise self._error(e, self.time, exc) from exc
            if not np.allclose(back, w[e], rtol=0, atol=0):
                raise FMUError(self._instance_name(e), self.time,
                               "the FMU did not accept slider positions w_<axis>; "
                               "continue a sweep on live instances instead")

    def set_element_states(self, states: dict) -> None:
        """Each state through the FMU: ``w_<axis>`` = its position (the element
        relaxed there), then ``w1_<axis>``, ``w2_<axis>`` = its sliders
        (``FrictionElement.with_sliders``), read back. ValueError if the FMU lacks
        the slider variables or the state is not its position plus its sliders
        (an element whose state holds more, e.g. a bristle deflection)."""
        index = {(e, j) for (_i, e, j) in self.layout.axes()}
        for (e, j), state in states.items():
            if (e, j) not in index:
                raise ValueError(f"element state for mount {e} axis {j}: not an "
                                 f"active axis of the system")
            p = self.system.elements[e].params.axes[j]
            where = f"mount {self.system.elements[e].name!r} axis {AXES[j]}"
            if not p.friction:
                raise ValueError(f"element state for {where}: the axis has no "
                                 f"friction element")
            el = p.element
            state = conform_state(p, state)
            pos, values = el.position(state), el.slider_values(p, state)
            rebuilt = el.with_sliders(p, el.start(p, pos), dict(enumerate(values)))
            if len(values) > SLIDER_SLOTS or flat_state(rebuilt) != flat_state(state):
                raise ValueError(
                    f"element state for {where}: the FMU sets a {el.name} element "
                    f"by its position w_{AXES[j]} and at most {SLIDER_SLOTS} sliders "
                    f"w1_..w{SLIDER_SLOTS}_{AXES[j]}; this state ({len(values)} "
                    f"sliders) is not of that form; use backend 'inproc'")
            names = [f"w_{AXES[j]}"] + [f"w{k + 1}_{AXES[j]}"
                                        for k in range(len(values))]
            missing = [n for n in names if n not in self._vars]
            if missing:
                raise ValueError(f"FMU {self.fmu_path!r} lacks {missing} (an FMU "
                                 f"built before the slider variables): rebuild it")
            fmu = self._fmus[e]
            want = [float(pos)] + [float(x) for x in values]
            try:
                fmu.setReal([self._vars[names[0]].valueReference], want[:1])
                if values:   # after w_: it relaxes the element
                    fmu.setReal([self._vars[n].valueReference for n in names[1:]],
                                want[1:])
                back = fmu.getReal([self._vars[n].valueReference for n in names])
            except Exception as exc:
                raise self._error(e, self.time, exc) from exc
            if list(back) != want:
                raise FMUError(self._instance_name(e), self.time,
                               f"the FMU did not accept the element state {want} "
                               f"(read back {list(back)})")

    def energy(self) -> np.ndarray:
        out = np.zeros(self.layout.n_mounts)
        for e, fmu in enumerate(self._fmus):
            try:
                out[e] = fmu.getReal([self._vr_E])[0]
            except Exception as exc:
                raise self._error(e, self.time, exc) from exc
        return out

    # ---------------------------------------------------------------- cleanup
    def close(self) -> None:
        """Terminate (when initialised and not failed) and free every instance, unload
        the libraries, remove the extracted FMU. Safe to call twice."""
        fmus, states = self._fmus, self._state
        self._fmus, self._state = [], []
        self._calls = []
        for fmu, state in zip(fmus, states, strict=True):
            try:
                if state == "initialized":
                    try:
                        fmu.terminate()
                    except Exception as exc:  # keep freeing the others
                        _log.warning("terminate of %s failed: %s", fmu.instanceName,
                                     exc)
            finally:
                try:
                    if state in ("instantiated", "initialized", "failed"):
                        fmu.freeInstance()   # fmi2FreeInstance + unload the library
                    else:
                        fmu.freeLibrary()
                except Exception as exc:
                    _log.warning("freeing %s failed: %s", fmu.instanceName, exc)
        if getattr(self, "_callbacks", None) is not None:
            import drymount.vehicle.fmi_logging as fmi_logging

            fmi_logging.release(self._callbacks)  # every instance is freed by now
        if self._unzipdir is not None:
            shutil.rmtree(self._unzipdir, ignore_errors=True)
            self._unzipdir = None

    @property
    def n_instances(self) -> int:
        """Instances currently alive (not yet freed)."""
        return len(self._fmus)

    def __del__(self):
        try:
            if self._fmus:
                self.close()
        except Exception:
            pass


BACKENDS = {"inproc": InProcessBackend, "fmu": FMUBackend}
#: Deprecated backend names -> their names now (accepted with a FutureWarning).
RENAMED_BACKENDS = {"native": "inproc"}


def renamed_backend_message(old: str) -> str:
    """The one-line notice for a deprecated backend name."""
    return (f"backend {old!r} is deprecated: it is called "
            f"{RENAMED_BACKENDS[old]!r} now (the law in-process); the native C FMU "
            f"is the fmu backend with dist/FrictionMountNative.fmu")


def backend_name(name, stacklevel: int = 3) -> str:
    """``name`` with a deprecated alias replaced by the backend's name now (a
    FutureWarning, one line, says so); other names are returned as given."""
    if isinstance(name, str) and name in RENAMED_BACKENDS:
        warnings.warn(renamed_backend_message(name), FutureWarning,
                      stacklevel=stacklevel)
        return RENAMED_BACKENDS[name]
    return name


def make_backend(name: str, system, layout: Layout, **options):
    """Create the backend ``name`` (``"inproc"`` or ``"fmu"``)."""
    name = backend_name(name)
    if name not in BACKENDS:
        raise ValueError(f"`backend` must be one of {sorted(BACKENDS)}, got {name!r}")
    if name == "inproc":  # FMU options are ignored
        return InProcessBackend(system, layout)
    return FMUBackend(system, layout, options.get("fmu_path"),
                      logging_on=options.get("logging_on", True),
                      start_values=options.get("start_values"))
