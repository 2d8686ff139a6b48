"""`drymount study incline` in quick mode (about 6 s)."""

import csv
import math

import pytest

from drymount.studies.incline import G, MASS, incline_system, run_incline
from drymount.fmu_src.mount_law import static_force

#: static balance k1 u + F(u) + weight = 0 at the working point, N (measured ~1e-13)
STATIC_TOL = 1e-6


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    out = tmp_path_factory.mktemp("incline")
    return out, run_incline(out, quick=True, progress=False)


def test_files_and_statuses(study):
    out, res = study
    assert all(f.exists() and f.stat().st_size > 0 for f in res["files"])
    assert not res["failures"] and res["missing"] == 0
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


def test_static_point_balances_the_weight(study):
    out, _ = study
    with open(out / "incline.csv", newline="") as fh:
        r60 = {r["theta_deg"]: r for r in csv.DictReader(fh)}["60.0"]
    x = float(r60["x_static_m"])   # compression, m
    p = incline_system(60.0, 2e4, 200.0).elements[0].params.axial
    force, _ = static_force(-x, p)
    assert abs(force + MASS * G) <= STATIC_TOL   # static_force includes k1 u
    s, c = math.sin(math.radians(60)), math.cos(math.radians(60))
    # relaxed element: N = (k a + P) / sin with a = x cos / sin
    assert float(r60["N_static_N"]) == pytest.approx((2e4 * x * c / s + 200.0) / s,
                                                     rel=1e-12)
