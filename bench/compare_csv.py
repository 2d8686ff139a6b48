"""Compare two drymount CSV outputs number by number (issue 27: results unchanged).

``python bench/compare_csv.py A.csv B.csv [--tol 1e-9]`` prints the rows of each, the
largest relative difference of any numeric field (``|a - b| / max(|a|, |b|)``, 0
where both are 0; the same-NaN fields equal) with its row and column, and exits 1 if
the shapes, the headers or any non-numeric field differ, or a difference exceeds
``--tol``. Comment lines (``#``) are compared as text but do not fail the check
(they carry the run's wording), unless ``--comments``.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path


def _rows(path: Path) -> tuple[list[str], list[list[str]]]:
    comments, rows = [], []
    for line in path.read_text().splitlines():
        if not line:
            continue
        (comments if line.startswith("#") else rows).append(line)
    return comments, [r.split(",") for r in rows]


def _num(s: str) -> float | None:
    try:
        return float(s)
    except ValueError:
        return None


def compare(a: Path, b: Path) -> dict:
    """``{"rows": (na, nb), "max_rel": float, "where": (row, col), "problems": [...],
    "comments_equal": bool}``."""
    ca, ra = _rows(a)
    cb, rb = _rows(b)
    out = {"rows": (len(ra) - 1, len(rb) - 1), "max_rel": 0.0, "where": None,
           "problems": [], "comments_equal": ca == cb}
    if not ra or not rb:
        out["problems"].append("a file has no header")
        return out
    if ra[0] != rb[0]:
        out["problems"].append(f"headers differ: {ra[0]} / {rb[0]}")
        return out
    header = ra[0]
    if len(ra) != len(rb):
        out["problems"].append(f"rows differ: {len(ra) - 1} / {len(rb) - 1}")
    for i, (x, y) in enumerate(zip(ra[1:], rb[1:], strict=False), start=1):
        if len(x) != len(y):
            out["problems"].append(f"row {i}: {len(x)} / {len(y)} fields")
            continue
        for j, (s, t) in enumerate(zip(x, y, strict=True)):
            u, v = _num(s), _num(t)
            if u is None or v is None:
                if s != t:
                    out["problems"].append(f"row {i} {header[j]}: {s!r} / {t!r}")
                continue
            if math.isnan(u) and math.isnan(v):
                continue
            if math.isnan(u) or math.isnan(v):
                rel = math.inf
            else:
                top = max(abs(u), abs(v))
                rel = abs(u - v) / top if top > 0 else 0.0
            if rel > out["max_rel"]:
                out["max_rel"], out["where"] = rel, (i, header[j])
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("a", type=Path)
    ap.add_argument("b", type=Path)
    ap.add_argument("--tol", type=float, default=1e-9)
    ap.add_argument("--comments", action="store_true",
                    help="fail if the comment lines differ too")
    args = ap.parse_args(argv)
    res = compare(args.a, args.b)
    where = "" if res["where"] is None else f" (row {res['where'][0]}, " \
        f"{res['where'][1]})"
    print(f"{args.a.name} / {args.b.name}: rows {res['rows'][0]} / {res['rows'][1]}, "
          f"max relative difference {res['max_rel']:.3g}{where}, comments "
          f"{'equal' if res['comments_equal'] else 'differ'}")
    for p in res["problems"][:20]:
        print("  " + p)
    bad = bool(res["problems"]) or res["max_rel"] > args.tol or (
        args.comments and not res["comments_equal"])
    return 1 if bad else 0


if __name__ == "__main__":
    raise SystemExit(main())
