"""The column layout of one row of the co-simulation master's buffer
(:class:`Layout`): where the mounts' deflections and rates, the integrator state, the
mount outputs and the right-hand side of the next step sit, shared by the backends
(:mod:`vehicle.backends`), the master loop and its compiled twin.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Layout"]


@dataclass(frozen=True)
class Layout:
    """Column layout of one row of the master's buffer (all offsets in doubles).

    Row k = ``[UV | x | OUT | R]``:

    - ``UV`` (2m): per mount e, ``u`` of its ``m_e`` active axes then their ``v``;
    - ``x`` (3n): ``q_k``, ``vh_k = q'(t_k - h/2)``, ``a_{k-1}`` (integrator state);
    - ``OUT`` (2m + n_mounts): per mount, ``F`` (m_e), ``Ffr`` (m_e), ``E`` (1);
    - ``R`` (n + 2m): ``M^-1 (f_k + K_b y_k + C_b y'_k)`` and the base part of UV at
      step k+1 (``[G y; G y']`` per mount).

    m is the number of active mount axes, n the number of DOFs.
    """

    n: int
    m: int
    n_mounts: int
    names: tuple[str, ...]
    active: tuple[tuple[int, ...], ...]

    @classmethod
    def of(cls, system) -> Layout:
        active = tuple(e.active_axes for e in system.elements)
        return cls(system.n_dof, sum(len(a) for a in active), len(active),
                   tuple(e.name for e in system.elements), active)

    @property
    def o_x(self) -> int:
        return 2 * self.m

    @property
    def o_out(self) -> int:
        return 2 * self.m + 3 * self.n

    @property
    def n_out(self) -> int:
        return 2 * self.m + self.n_mounts

    @property
    def o_r(self) -> int:
        return self.o_out + self.n_out

    @property
    def n_next(self) -> int:
        """Columns written by the linear update: ``UV`` and ``x`` of the next row."""
        return 2 * self.m + 3 * self.n

    @property
    def width(self) -> int:
        return self.o_r + self.n + 2 * self.m

    def m_of(self, e: int) -> int:
        return len(self.active[e])

    def uv_off(self, e: int) -> int:
        return 2 * sum(len(a) for a in self.active[:e])

    def out_off(self, e: int) -> int:
        return self.o_out + sum(2 * len(a) + 1 for a in self.active[:e])

    def axes(self) -> list[tuple[int, int, int]]:
        """``(global index i, mount e, local axis j)`` of every active axis."""
        out, i = [], 0
        for e, act in enumerate(self.active):
            for j in act:
                out.append((i, e, j))
                i += 1
        return out

    def columns(self) -> dict[str, np.ndarray]:
        """Column indices per active axis (``u``, ``v``, ``F``, ``Ffr``) and per mount
        (``E``)."""
        cols = {k: [] for k in ("u", "v", "F", "Ffr")}
        for e, act in enumerate(self.active):
            me = len(act)
            for a in range(me):
                cols["u"].append(self.uv_off(e) + a)
                cols["v"].append(self.uv_off(e) + me + a)
                cols["F"].append(self.out_off(e) + a)
                cols["Ffr"].append(self.out_off(e) + me + a)
        out = {k: np.array(v, dtype=int) for k, v in cols.items()}
        out["E"] = np.array([self.out_off(e) + 2 * self.m_of(e)
                             for e in range(self.n_mounts)], dtype=int)
        return out
