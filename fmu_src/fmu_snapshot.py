"""getFMUstate / setFMUstate of the FrictionMount slave (a mixin of
:class:`friction_mount.FrictionMount`).

A snapshot is everything settable (by the variables' own getters), the committed
energy, the committed friction state, the FMI state, the time and the records of the
last step; serialized with a checksum by :mod:`state_codec`. A state is checked whole
before any of it is set, and after initialization it must evaluate too, else the
instance is left as it was. Standard library only.
"""

from __future__ import annotations

from . import state_codec, step_record
from .fmi_guard import _guarded, _Rejected
from .fmi_state import Mode
from .interface import SLIDER_SLOT_NAMES
from .mount_law import AXES

__all__ = ["SnapshotMixin"]


class SnapshotMixin:
    """``_get_fmu_state``, ``_set_fmu_state`` and the byte codec pythonfmu calls; the
    class it is mixed into keeps the attributes it reads (``_e``, ``_w``, ``_mode``,
    ...) and provides ``vars``, ``_var`` and ``_axis``."""

    @_guarded
    def _get_fmu_state(self) -> dict:
        state = {var.name: var.getter() for var in self.vars.values()
                 if var.setter is not None}
        state["_E_committed"] = [float(x) for x in self._e]
        state["_n_set"] = list(self._n_set)
        # tuples (micro-slip sliders, an inclined element's (w1, w2, uc)) as lists;
        # _prepare reads them back as the axis's kind (mount_law.conform_state)
        state["_w"] = [list(w) if isinstance(w, tuple) else w for w in self._w]
        state["_mode"] = self._mode.value
        state["_t_next"] = self._t_next
        state["_dt"] = self._dt
        state["_step"] = [step_record.record_to_state(r) for r in self._rec]
        return state

    # Serialized states: bytes with a checksum, decoded without raising (pythonfmu
    # calls these on the class, outside any guard; fmu_src/state_codec.py).
    _fmu_state_to_bytes = staticmethod(state_codec.encode)
    _fmu_state_from_bytes = staticmethod(state_codec.decode)

    @_guarded
    def _set_fmu_state(self, state: dict) -> None:
        """Restore ``state`` after checking it whole (state_codec.state_problem);
        after initialization its parameters and outputs must evaluate too, else the
        instance is left as it was."""
        settable = {self._var[vr].name: self._var[vr]
                    for vr, var in self.vars.items() if var.setter is not None}
        why = state_codec.state_problem(state, settable)
        if why is not None:
            raise _Rejected(f"fmi2SetFMUstate: {why}")
        before = self._get_fmu_state.__wrapped__(self)
        self._apply_state(state)
        if self._mode in (Mode.STEP_COMPLETE, Mode.TERMINATED):
            try:
                for j in range(3):
                    self._axis(j)
            except Exception as exc:  # noqa: BLE001 - any failure: refuse the state
                self._apply_state(before)
                raise _Rejected(f"fmi2SetFMUstate: the state does not evaluate "
                                f"({exc})") from None

    def _apply_state(self, state: dict) -> None:
        by_name = {var.name: var for var in self.vars.values()}
        for name, value in state.items():
            # the sliders w1_/w2_ are part of the restored friction state `_w`
            if name in by_name and by_name[name].setter is not None \
                    and name.partition("_")[0] not in SLIDER_SLOT_NAMES:
                by_name[name].setter(value)
        self._e = [float(x) for x in state["_E_committed"]]
        self._n_set = [bool(x) for x in state["_n_set"]]
        self._w = [tuple(float(x) for x in w) if isinstance(w, list) else float(w)
                   for w in state["_w"]]
        self._mode, self._t_next = Mode(state["_mode"]), state["_t_next"]
        self._dt = float(state.get("_dt", 0.0))
        # in place: the getters hold the list
        self._rec[:] = [step_record.record_from_state(r) for r in state["_step"]] \
            if "_step" in state else [step_record.StepRecord() for _ in AXES]
        self._axes = None
        self._res = [None, None, None]
