"""Every output of every build stays finite with parameters at their allowed extremes
(issue 25, item 5): an output that would overflow (or be NaN) is refused with
fmi2Error naming it, never returned with status OK.

For each Real parameter of the interface table at its extremes (1e308, the smallest
subnormal, 0, +inf where allowed), on a Jenkins, a micro-slip (64 sliders) and an
inclined axis, the instance is initialized, driven with moderate and huge inputs
(|u| up to 1e201, n up to 1e300) and every Real output read, stepping in between:
through tests/importers/fmu_fuzz_drive.py, one process per build, which checks that
no Real read is NaN or infinite and that every refusal logged a message. The three
cases of the issue are in the list by name.
"""

from __future__ import annotations

import pytest

pytest.importorskip("fmpy", reason="pip install fmpy (the test extra)")

from test_fmu_fuzz import BUILDS, _check, _drive, unzipped  # noqa: E402,F401

from drymount.fmu_src.interface import VARIABLES  # noqa: E402

REAL_PARAMETERS = [v.name for v in VARIABLES
                   if v.causality == "parameter" and v.type == "Real"
                   and v.name.startswith("axial_")]
EXTREMES = (1e308, 5e-324, 0.0, float("inf"))
KINDS = ([], [["setInteger", "axial_sliders", 64], ["setReal", "axial_spread", 0.9]],
         [["setInteger", "axial_friction_kind", 1]])
#: the issue's three cases: (parameters, inputs)
ISSUE_CASES = [([["setReal", "axial_mu", 1e200]], [["setReal", "u_axial", 1e201]]),
               ([["setReal", "axial_fs_ratio", 1e308]],
                [["setReal", "u_axial", -0.02]]),
               ([["setReal", "axial_mu", 1e300]], [["setReal", "n_axial", 1e300]])]
INPUTS = ([["setReal", "u_axial", 0.02]], [["setReal", "u_axial", -0.02]],
          [["setReal", "u_axial", 1e201], ["setReal", "v_axial", 1e300]],
          [["setReal", "n_axial", 1e300]])


def _case(params: list, inputs_list) -> list:
    calls = [["reset"], ["setBoolean", "axial_friction", True],
             ["setReal", "axial_n0", 100.0], *params, ["setup", 0.0], ["enter"],
             ["getReal"], ["exit"], ["getReal"]]
    t = 0.0
    for inputs in inputs_list:
        calls += [*inputs, ["getReal"], ["doStep", t, 1e-4], ["getReal"]]
        t += 1e-4
    return calls


def extreme_calls(issue_reads: list | None = None) -> list:
    """Every case's calls; ``issue_reads`` receives the index of the first read after
    the inputs of each of the issue's cases."""
    calls = []
    for params, inputs in ISSUE_CASES:
        case = _case(params, [inputs, *INPUTS])
        if issue_reads is not None:
            issue_reads.append(len(calls) + 9 + len(params) + len(inputs) - 1)
        calls += case
    for kind in KINDS:
        for name in REAL_PARAMETERS:
            for value in EXTREMES:
                calls += _case([*kind, ["setReal", name, value]], INPUTS)
    return calls


@pytest.mark.parametrize("build", BUILDS)
def test_every_output_finite_at_parameter_extremes(unzipped, build):  # noqa: F811
    issue_reads = []
    calls = extreme_calls(issue_reads)
    for k in issue_reads:
        assert calls[k] == ["getReal"], calls[k - 3:k + 1]
    res = _drive(unzipped[build], calls)
    _check(res, calls)
    answers = res["answers"]
    # the issue's cases reach their non-finite outputs and are refused there
    assert [answers[k][0] for k in issue_reads] == [3, 3, 3], \
        [answers[k] for k in issue_reads]
    refused = [c for c, a in zip(calls, answers) if a[0] == 3 and c[0] == "getReal"]
    assert refused, "no output was refused: the extremes were not reached"
    read = sum(len(a[1]) for a in answers if a[1] is not None)
    assert read > 1000
