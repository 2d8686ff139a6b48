"""drymount.threads: the CLI runs BLAS/OpenMP with one thread unless DRYMOUNT_THREADS
says otherwise; worker processes inherit the limit through the environment."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from drymount.threads import ENV, LIBRARY_VARIABLES, limit_threads, thread_limit

ROOT = Path(__file__).resolve().parents[1]


def test_thread_limit_parses_the_override():
    assert thread_limit({}) == 1
    assert thread_limit({ENV: "3"}) == 3
    assert thread_limit({ENV: "default"}) is None
    for bad in ("0", "-2", "two", "1.5"):
        with pytest.raises(ValueError, match=f"`{ENV}` must be a positive integer"):
            thread_limit({ENV: bad})


def test_limit_threads_sets_the_library_variables():
    env = {ENV: "2", "OMP_NUM_THREADS": "8"}
    assert limit_threads(env) == 2
    assert all(env[v] == "2" for v in LIBRARY_VARIABLES)
    env = {ENV: "default", "OMP_NUM_THREADS": "8"}
    assert limit_threads(env) is None
    assert env == {ENV: "default", "OMP_NUM_THREADS": "8"}


def _blas_threads_after_cli(value, tmp_path):
    """OpenBLAS threads seen by a fresh CLI process and by a process it spawns."""
    code = (
        "import sys, multiprocessing as mp\n"
        "from drymount import cli\n"
        "from threadpoolctl import threadpool_info\n"
        "def child(q):\n"
        "    import numpy\n"
        "    from threadpoolctl import threadpool_info\n"
        "    q.put(sorted({i['num_threads'] for i in threadpool_info()"
        " if i['internal_api'] == 'openblas'}))\n"
        "if __name__ == '__main__':\n"
        "    cli.main(['presets', 'list'])\n"
        "    import numpy\n"
        "    own = sorted({i['num_threads'] for i in threadpool_info()"
        " if i['internal_api'] == 'openblas'})\n"
        "    q = mp.get_context('spawn').Queue()\n"
        "    p = mp.get_context('spawn').Process(target=child, args=(q,))\n"
        "    p.start(); kid = q.get(timeout=60); p.join()\n"
        "    print(own, kid)\n")
    env = {k: v for k, v in os.environ.items()
           if k not in LIBRARY_VARIABLES and k != ENV}
    if value is not None:
        env[ENV] = value
    script = tmp_path / "probe.py"
    script.write_text(code)
    env["PYTHONPATH"] = str(ROOT)
    out = subprocess.run([sys.executable, str(script)], cwd=ROOT, env=env,
                         capture_output=True, text=True, timeout=120, check=True)
    return out.stdout.strip().splitlines()[-1]


def test_cli_and_its_workers_run_one_blas_thread_by_default(tmp_path):
    import numpy  # noqa: F401 - loads OpenBLAS
    from threadpoolctl import threadpool_info
    if not any(i["internal_api"] == "openblas" for i in threadpool_info()):
        pytest.skip("NumPy is not linked to OpenBLAS here")
    assert _blas_threads_after_cli(None, tmp_path) == "[1] [1]"
    assert _blas_threads_after_cli("2", tmp_path) == "[2] [2]"
