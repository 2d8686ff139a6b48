"""`drymount study incline` in quick mode (about 4 s)."""

import csv
import math

import pytest

from drymount.studies.incline import K1, MASS, G, run_incline, static_point
from fmu_src.inclined import InclinedParameters, inclined_update

#: static balance k1 x + F(x) = weight at the bisected point, N (measured ~1e-9)
STATIC_TOL = 1e-6


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    out = tmp_path_factory.mktemp("incline")
    return out, run_incline(out, quick=True, progress=False)


def test_files_and_statuses(study):
    out, res = study
    assert all(f.exists() and f.stat().st_size > 0 for f in res["files"])
    assert not res["failures"]
    st = res["statuses"]
    assert st["30/20000/200"] == "self-locks"   # both slipping: determinant < 0
    assert st["60/20000/200"] == "ok" and st["90/20000/200"] == "ok"
    with open(out / "incline.csv", newline="") as fh:
        rows = {r["theta_deg"]: r for r in csv.DictReader(fh)}
    r60, r90 = rows["60.0"], rows["90.0"]
    # 90 degrees: constant normal force = preload (the thesis's design)
    assert float(r90["N_min_N"]) == pytest.approx(200.0, rel=1e-12)
    assert float(r90["N_max_N"]) == pytest.approx(200.0, rel=1e-12)
    # 60 degrees: the normal force varies with the motion (what the thesis could not do)
    assert float(r60["N_max_N"]) - float(r60["N_min_N"]) > 100.0


def test_static_point_balances_the_weight():
    p = InclinedParameters(theta_deg=60.0, k=2e4, preload=200.0)
    x, st = static_point(p, MASS * G)
    again = inclined_update(x, 0.0, 0.0, 0.0, p)
    assert abs(K1 * x + again.force - MASS * G) <= STATIC_TOL
    assert math.isclose(again.n1, st.n1)
