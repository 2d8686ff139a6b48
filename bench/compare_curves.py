"""How far one drymount HBM curve lies from another traced with other points.

``python bench/compare_curves.py OLD.csv NEW.csv`` (issue 27: a change that places
the points differently along the same curve must say by how much it moved them). Each
curve is a polyline in scaled coordinates: the frequency over the band, every
amplitude column (``*_amp``, ``*_peak``) and the transmissibility over that column's
largest value on OLD. It prints the rows of each, the distance of every NEW point to
OLD's polyline (largest, median, and the row and frequency of the largest), and the
same the other way round; the largest error-estimate columns of each; the stable
rows of each; and, if both have their events file (``*_events.csv``), each event of
OLD with the nearest of the same kind and DOF in NEW (frequency moved, largest
change of its amplitudes relative to OLD's peak of that column). Exit 0: it reports,
it does not judge.
"""

from __future__ import annotations

import argparse
import csv
import math
from pathlib import Path

import numpy as np


def read(path: Path) -> tuple[list[str], np.ndarray]:
    """Header and numeric rows of a drymount CSV (comment lines skipped; empty
    fields NaN)."""
    lines = [ln for ln in path.read_text().splitlines()
             if ln and not ln.startswith("#")]
    rows = list(csv.reader(lines))
    head, body = rows[0], rows[1:]

    def num(s):
        try:
            return float(s)
        except ValueError:
            return math.nan
    return head, np.array([[num(s) for s in r] for r in body])


def _columns(head: list[str], fundamentals: bool = False) -> list[int]:
    """The amplitude columns (``fundamentals``: ``*_amp`` only, what the step control
    bounds; else also ``*_peak`` and the transmissibility)."""
    if fundamentals:
        return [i for i, h in enumerate(head) if h.endswith("_amp")]
    return [i for i, h in enumerate(head)
            if h.endswith(("_amp", "_peak")) or h == "transmissibility"]


def _distances(p: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """Distance of each row of ``p`` to the polyline through the rows of ``poly``."""
    a, d = poly[:-1], poly[1:] - poly[:-1]
    dd = np.einsum("ij,ij->i", d, d)
    out = np.empty(len(p))
    for k, x in enumerate(p):
        pa = x - a
        with np.errstate(divide="ignore", invalid="ignore"):
            s = np.where(dd > 0, np.clip(np.einsum("ij,ij->i", pa, d) / dd, 0, 1), 0)
        r = pa - s[:, None] * d
        out[k] = math.sqrt(float(np.min(np.einsum("ij,ij->i", r, r))))
    return out


def compare_curves(old: Path, new: Path, fundamentals: bool = False) -> dict:
    """The figures printed by :func:`main`, as a dict."""
    h0, a0 = read(old)
    h1, a1 = read(new)
    if h0 != h1:
        raise SystemExit(f"the headers differ: {h0} / {h1}")
    f = h0.index("freq_hz")
    cols = _columns(h0, fundamentals)
    span = float(np.nanmax(a0[:, f]) - np.nanmin(a0[:, f]))
    scale = np.nanmax(np.abs(a0[:, cols]), axis=0)
    scale = np.where(scale > 0, scale, 1.0)

    def scaled(a):
        return np.column_stack([a[:, f] / span, a[:, cols] / scale])
    s0, s1 = scaled(a0), scaled(a1)
    d10, d01 = _distances(s1, s0), _distances(s0, s1)
    out = {"rows": (len(a0), len(a1)), "new_to_old": d10, "old_to_new": d01,
           "freq_new": a1[:, f], "freq_old": a0[:, f]}
    for name in ("err_truncation", "err_sampling"):
        if name in h0:
            j = h0.index(name)
            out[name] = (float(np.nanmax(a0[:, j])), float(np.nanmax(a1[:, j])))
    if "stable" in h0:
        j = h0.index("stable")
        out["stable"] = (int(np.nansum(a0[:, j])), int(np.nansum(a1[:, j])))
    out["peak_scale"] = dict(zip([h0[i] for i in cols], scale, strict=True))
    return out


def compare_events(old: Path, new: Path, peak_scale: dict) -> list[str]:
    """One line per event of OLD: the nearest event of the same kind and DOF in NEW."""
    def rows(path):
        lines = [ln for ln in path.read_text().splitlines()
                 if ln and not ln.startswith("#")]
        return list(csv.DictReader(lines))
    e0, e1 = rows(old), rows(new)
    lines = []
    for ev in e0:
        same = [e for e in e1 if e["kind"] == ev["kind"] and e["dof"] == ev["dof"]]
        label = f"{ev['kind']} {ev['dof']}".strip()
        if not same:
            lines.append(f"  {label} at {float(ev['freq_hz']):.7f} Hz: none in NEW")
            continue
        near = min(same, key=lambda e: abs(float(e["freq_hz"]) - float(ev["freq_hz"])))
        df = float(near["freq_hz"]) - float(ev["freq_hz"])
        da = max(abs(float(near[k]) - float(ev[k])) / peak_scale[k] for k in peak_scale
                 if ev.get(k) not in (None, "") and near.get(k) not in (None, ""))
        lines.append(f"  {label} at {float(ev['freq_hz']):.7f} Hz: moved {df:+.2e} Hz "
                     f"({df / float(ev['freq_hz']):+.1e} relative), amplitudes by "
                     f"{da:.1e} of their peak")
    if len(e1) != len(e0):
        lines.append(f"  events: {len(e0)} in OLD, {len(e1)} in NEW")
    return lines


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("old", type=Path)
    ap.add_argument("new", type=Path)
    args = ap.parse_args(argv)
    r = compare_curves(args.old, args.new)
    print(f"{args.old} / {args.new}: rows {r['rows'][0]} / {r['rows'][1]} (distances "
          "scaled: the frequency over the band, each amplitude over its peak)")
    for cols, rr in (("every amplitude column", r),
                     ("the fundamentals (*_amp)", compare_curves(args.old, args.new,
                                                                True))):
        for key, freq, what in (
                ("new_to_old", rr["freq_new"], "NEW's points to OLD's"),
                ("old_to_new", rr["freq_old"], "OLD's points to NEW's")):
            d = rr[key]
            k = int(np.argmax(d))
            print(f"  {what} curve, {cols}: largest {d[k]:.1e} (row {k + 1}, "
                  f"{freq[k]:.6g} Hz), median {np.median(d):.1e}, "
                  f"{int(np.sum(d > 1e-3))} beyond 1e-3")
    for name in ("err_truncation", "err_sampling"):
        if name in r:
            print(f"  largest {name}: {r[name][0]:.3g} / {r[name][1]:.3g}")
    if "stable" in r:
        print(f"  stable rows: {r['stable'][0]} / {r['stable'][1]}")
    ev0 = args.old.with_name(args.old.stem + "_events.csv")
    ev1 = args.new.with_name(args.new.stem + "_events.csv")
    if ev0.exists() and ev1.exists():
        print("  events (OLD -> nearest of the same kind in NEW):")
        for line in compare_events(ev0, ev1, r["peak_scale"]):
            print(line)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
