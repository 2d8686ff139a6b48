"""Corrupted serialized FMU states and random FMI call sequences through all three
builds (PythonFMU, native FMI 2.0, native FMI 3.0), each sequence in its own process
(tests/importers/fmu_fuzz_drive.py): issue 25, items 2-4.

Checked for every sequence: the process does not die, no call is fatal, no Real read
is NaN or infinite, every refused call has status error and logged a message, after
every refused call the outputs answer, after the sequence a reset instance runs.
The word sweep overwrites every aligned word of a valid state with 0x7fffffff, NaN,
+inf (with and without a recomputed checksum, so that the range checks are reached):
a refused state leaves the instance exactly as it was (outputs bit-equal).

Default: a fixed seed, 3 x 2 random sequences and 3 word sweeps (~40 s with the
builds); ``-m slow``: 3 x 60 random sequences.
"""

from __future__ import annotations

import json
import math
import os
import random
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("fmpy", reason="pip install fmpy (the test extra)")

from native_helpers import need_gcc  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
DRIVER = REPO / "tests" / "importers" / "fmu_fuzz_drive.py"
BUILDS = ("pythonfmu", "native2", "native3")
OUTPUTS = ("F_axial", "Ffr_axial", "kt_axial", "E_fr_axial", "E_fr", "N_axial",
           "F_radial1")
#: a valid state to corrupt: micro-slip friction on the axial axis, two steps
PREFIX = [["setBoolean", "axial_friction", True], ["setReal", "axial_n0", 50.0],
          ["setInteger", "axial_sliders", 4], ["setReal", "axial_spread", 0.5],
          ["setup", 0.0], ["enter"], ["exit"], ["setReal", "u_axial", 0.003],
          ["doStep", 0.0, 1e-4], ["setReal", "u_axial", 0.001],
          ["doStep", 1e-4, 1e-4], ["getState"], ["serialize", 0]]
T_PREFIX = 2e-4


@pytest.fixture(scope="module")
def unzipped(tmp_path_factory):
    from fmpy import extract

    from drymount.fmu_build import build_fmu
    from drymount.fmu_build.native import build_native_fmu

    need_gcc()
    folder = tmp_path_factory.mktemp("fuzz")
    paths = {"pythonfmu": build_fmu(folder / "FrictionMount.fmu"),
             "native2": build_native_fmu(folder / "N2.fmu").path,
             "native3": build_native_fmu(folder / "N3.fmu", fmi=3).path}
    return {k: extract(str(p), unzipdir=str(folder / k)) for k, p in paths.items()}


def _drive(unzipdir, calls) -> dict:
    out = subprocess.run([sys.executable, str(DRIVER), str(unzipdir)],
                         input=json.dumps(calls) + "\n", capture_output=True,
                         text=True, timeout=300,
                         env={**os.environ, "PYTHONPATH": str(REPO)})
    assert out.returncode == 0, (out.returncode, out.stderr[-3000:], calls[-20:])
    return json.loads(out.stdout.splitlines()[-1])


def _check(res: dict, calls: list) -> None:
    assert len(res["answers"]) == len(calls), "a call was fatal"
    for call, (status, values, messages) in zip(calls, res["answers"]):
        assert status in (0, 3), (call, status)  # never fatal, never a warning
        if status == 3:
            assert messages >= 1, ("refused without a message", call)
        if values is not None:
            assert all(math.isfinite(x) for x in values), (call, values)
    for status, values in res["probes"]:
        assert status in (0, 3), status
        if status == 0:
            assert all(math.isfinite(x) for x in values), values
    assert res["usable"], "a reset instance does not run"


def _random_load(rng: random.Random, size: int) -> list:
    kind = rng.choice(["random", "truncate", "word", "wordfix", "empty", "asis"])
    if kind == "random":
        return ["load", 0, "random", rng.randrange(10**6), rng.choice([0, 7, size,
                                                                        size * 2])]
    if kind == "truncate":
        return ["load", 0, "truncate", rng.randrange(size)]
    if kind in ("word", "wordfix"):
        what = rng.choice(["int", "nan", "inf", "-inf"])
        step = 4 if what == "int" else 8
        args = ["load", 0, "word", step * rng.randrange(size // step), what]
        return args + (["fix"] if kind == "wordfix" else [])
    return ["load", 0, kind]


def random_sequence(rng: random.Random, size: int, n_calls: int = 40) -> list:
    """PREFIX, then random calls: corrupted loads, restores, steps that continue
    from the last one (or not), inputs, reads, resets."""
    calls, t = list(PREFIX), T_PREFIX
    for _ in range(n_calls):
        r = rng.random()
        if r < 0.35:
            calls.append(_random_load(rng, size))
        elif r < 0.45:
            calls.append(["setState", 0])
        elif r < 0.6:
            calls.append(["setReal", rng.choice(["u_axial", "v_axial", "n_axial",
                                                 "u_radial1"]),
                          rng.choice([rng.uniform(-0.03, 0.03), 1e300, -1e300, 0.0])])
        elif r < 0.8:
            calls.append(["getReal", *OUTPUTS])
        elif r < 0.95:
            h = rng.choice([1e-4, 1e-3])
            calls.append(["doStep", t, h])
            t += h  # refused steps (wrong state) make later ones refused too: fine
        else:
            calls.append(["getState"])
    return calls


def _blob_size(unzipdir) -> int:
    return _drive(unzipdir, PREFIX)["blob_sizes"][0]


def _run_random(unzipped, build, seed, count):
    size = _blob_size(unzipped[build])
    rng = random.Random(seed)
    for _ in range(count):
        calls = random_sequence(rng, size)
        _check(_drive(unzipped[build], calls), calls)


@pytest.mark.parametrize("build", BUILDS)
def test_random_sequences_with_corrupted_states(unzipped, build):
    _run_random(unzipped, build, seed=25, count=2)


@pytest.mark.slow
@pytest.mark.parametrize("build", BUILDS)
def test_random_sequences_with_corrupted_states_long(unzipped, build):
    _run_random(unzipped, build, seed=2025, count=60)


@pytest.mark.parametrize("build", BUILDS)
def test_every_word_of_a_state_overwritten(unzipped, build):
    size = _blob_size(unzipped[build])
    # an empty state, refused: its probe (every Real output) is the reference
    calls = list(PREFIX) + [["setState", 0], ["load", 0, "empty"], ["setState", 0]]
    loads = []
    for what, step in (("int", 4), ("nan", 8), ("inf", 8)):
        for offset in range(0, size - step + 1, step):
            for fix in ([], ["fix"]):
                loads.append(["load", 0, "word", offset, what, *fix])
    for load in loads:
        calls += [load, ["setState", 0]]
    res = _drive(unzipped[build], calls)
    _check(res, calls)
    answers = res["answers"]
    reference = res["probes"][0][1]
    probes = iter(res["probes"])
    refused = 0
    for call, (status, _, _) in zip(calls, answers):
        if status == 3:
            assert call[0] == "load", call  # only corrupted states are refused
            probe_status, values = next(probes)
            # the instance kept the valid state: the same outputs, bit for bit
            assert probe_status == 0 and values == reference, (call, values)
            refused += 1
    # without the recomputed checksum every corrupted state is refused
    plain = [c for c in loads if c[-1] != "fix"]
    assert refused >= len(plain), (refused, len(plain))
