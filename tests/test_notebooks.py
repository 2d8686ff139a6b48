"""The notebooks of examples/ run from top to bottom (nbclient, a python3 kernel that
imports this checkout), so that they never rot. Runtime about 20 s (two kernels)."""

import os
import shutil
from pathlib import Path

import pytest

nbformat = pytest.importorskip("nbformat", reason="the `test` extra installs nbformat")
nbclient = pytest.importorskip("nbclient", reason="the `test` extra installs nbclient")

REPO = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((REPO / "examples").glob("*.ipynb"))
#: Seconds a cell may take (they take under 5 s).
CELL_TIMEOUT_S = 300


def test_the_two_notebooks_are_there():
    assert {p.name for p in NOTEBOOKS} >= {"sdof_n0_study.ipynb",
                                           "six_dof_measured_road.ipynb"}


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_runs(path, tmp_path, monkeypatch):
    work = tmp_path / "examples"
    shutil.copytree(REPO / "examples", work)  # outputs go to the copy, not the repo
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(
        [str(REPO)] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep)
                       if p]))
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "1")
    nb = nbformat.read(work / path.name, as_version=4)
    nbclient.NotebookClient(nb, timeout=CELL_TIMEOUT_S, kernel_name="python3",
                            resources={"metadata": {"path": str(work)}}).execute()
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert images, "the notebook shows no figure"
    if path.stem == "six_dof_measured_road":
        head = (work / "six_dof_road_spectra.csv").read_text().splitlines()[0]
        assert "N^2/Hz" in head
