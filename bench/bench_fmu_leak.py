"""Memory per instantiate/free cycle of the FMUs (issue 25 item 6).

Run: ``python bench/bench_fmu_leak.py [--cycles N] [--build python|native|both]``

Each build runs in its own child process (fmpy as the importer): ``N`` cycles of
instantiate, setup, initialise, 10 steps, terminate, ``fmi2FreeInstance`` with the
library loaded once; with ``--reload`` each cycle also loads and unloads the library
(a new ``FMU2Slave``; fmpy's ``freeInstance`` unloads it). After a warm-up of N/5
cycles it reads the resident set size (``/proc/self/statm``), the Python heap
(``tracemalloc``) and the count of live Python objects (``gc``), and again after the
N cycles; it prints the growth per cycle of each, and the five source lines whose
Python allocations grew most (a Python object kept alive per instance shows up
there; memory held by C code shows only in the RSS). Linux only (``/proc``). Not a
test: the figures depend on the allocator, the machine and the load.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CHILD = r"""
import gc, json, os, sys, tracemalloc
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from drymount.vehicle import fmi_logging

path, cycles, reload = sys.argv[1], int(sys.argv[2]), sys.argv[3] == "reload"
md = read_model_description(path)
unzipped = extract(path)
page = os.sysconf("SC_PAGE_SIZE")
fmu = None

def rss():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * page

def cycle():  # as the harness does (vehicle.backends): drymount's logger callbacks
    global fmu
    if reload or fmu is None:  # a new FMU2Slave loads the library (again)
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipped,
                        modelIdentifier=md.coSimulation.modelIdentifier,
                        instanceName="m")
    cb = fmi_logging.callbacks(lambda *message: None)
    fmu.instantiate(callbacks=cb)
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    for k in range(10):
        fmu.doStep(currentCommunicationPoint=k * 1e-3, communicationStepSize=1e-3)
    fmu.terminate()
    if reload:
        fmu.freeInstance()  # fmpy's: fmi2FreeInstance, then it unloads the library
    else:
        fmu.fmi2FreeInstance(fmu.component)
        fmu.component = None
    fmi_logging.release(cb)

warm = max(cycles // 5, 20)
for _ in range(warm):
    cycle()
gc.collect()
tracemalloc.start(10)
snap0 = tracemalloc.take_snapshot()
r0, n0, (h0, _) = rss(), len(gc.get_objects()), tracemalloc.get_traced_memory()
for _ in range(cycles):
    cycle()
gc.collect()
r1, n1, (h1, _) = rss(), len(gc.get_objects()), tracemalloc.get_traced_memory()
top = tracemalloc.take_snapshot().compare_to(snap0, "lineno")[:5]
print(json.dumps({"cycles": cycles, "rss_per_cycle": (r1 - r0) / cycles,
                  "python_heap_per_cycle": (h1 - h0) / cycles,
                  "objects_per_cycle": (n1 - n0) / cycles,
                  "top": [str(s) for s in top]}))
"""


def measure(fmu: Path, cycles: int, reload: bool) -> dict:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    p = subprocess.run([sys.executable, "-c", CHILD, str(fmu), str(cycles),
                        "reload" if reload else "instance"],
                       capture_output=True, text=True, env=env, timeout=3600)
    if p.returncode != 0:
        raise SystemExit(f"the child failed ({p.returncode}):\n{p.stderr[-3000:]}")
    return json.loads(p.stdout.strip().splitlines()[-1])


def fmus(which: str) -> dict:
    out = {}
    if which in ("python", "both"):
        from drymount.fmu_build.builder import ensure_fmu

        out["PythonFMU"] = ensure_fmu()
    if which in ("native", "both"):
        from drymount.fmu_build.native import build_native_fmu

        out["native FMI 2.0"] = Path(build_native_fmu(fmi=2).path)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cycles", type=int, default=2000)
    ap.add_argument("--build", choices=("python", "native", "both"), default="both")
    ap.add_argument("--reload", action="store_true",
                    help="load and unload the library every cycle (fmpy's "
                         "freeInstance); default: loaded once, fmi2FreeInstance")
    args = ap.parse_args(argv)
    for name, path in fmus(args.build).items():
        m = measure(path, args.cycles, args.reload)
        print(f"{name}: {m['cycles']} cycles: RSS {m['rss_per_cycle']:+.0f} B/cycle, "
              f"Python heap {m['python_heap_per_cycle']:+.0f} B/cycle, live objects "
              f"{m['objects_per_cycle']:+.2f}/cycle")
        for line in m["top"]:
            print(f"    {line}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
