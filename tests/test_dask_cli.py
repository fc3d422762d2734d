"""The deep tier on a Dask cluster, run as a user runs it: ``dask scheduler`` and two ``dask worker``
processes started from the command line, a deep-tier study through ``--scheduler``, and its tables
equal to the serial run's bit for bit."""

from __future__ import annotations

import csv
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytest.importorskip("dask.distributed", reason="the [dask] extra is not installed")
pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parent.parent
STUDY = "projection"  # the cheapest deep-tier study: hundreds of small cases spread over the workers
TIMED = {"wall_s", "seconds", "cpu_s"}  # columns that measure time, not numbers of the method


def _dask(*args) -> list[str]:
    exe = shutil.which("dask") or str(Path(sys.executable).parent / "dask")
    return [exe, *args]


def _start(argv, log: Path) -> subprocess.Popen:
    return subprocess.Popen(argv, cwd=ROOT, stdout=log.open("w"), stderr=subprocess.STDOUT,
                            env={**os.environ, "PYTHONPATH": str(ROOT)}, start_new_session=True)


def _stop(proc: subprocess.Popen) -> None:
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGTERM)
        try:
            proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()


def _tables(folder: Path) -> dict:
    out = {}
    for path in sorted(folder.rglob("*.csv")):
        with path.open() as f:
            rows = [{k: v for k, v in r.items() if k not in TIMED} for r in csv.DictReader(f)]
        out[str(path.relative_to(folder))] = rows
    return out


def _study(out: Path, *options) -> None:
    proc = subprocess.run([sys.executable, "-m", "mpm_fem.app.cli", "study", STUDY, "--deep", "--out", str(out),
                           "--quiet", *options], cwd=ROOT, capture_output=True, text=True, timeout=900,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert proc.returncode == 0, proc.stderr


def test_a_deep_study_on_a_dask_cluster_started_from_the_command_line_equals_the_serial_run(tmp_path):
    address_file = tmp_path / "scheduler.json"
    procs = [_start(_dask("scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                          "--scheduler-file", str(address_file)), tmp_path / "scheduler.log")]
    try:
        for _ in range(600):
            if address_file.exists() and address_file.stat().st_size:
                break
            time.sleep(0.1)
        address = json.loads(address_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        for k in range(2):
            procs.append(_start(_dask("worker", "--scheduler-file", str(address_file), "--nthreads", "1",
                                      "--nworkers", "1", "--no-dashboard", "--name", f"w{k}"),
                                tmp_path / f"worker{k}.log"))
        _study(tmp_path / "cluster", "--scheduler", address)
        assert all(p.poll() is None for p in procs), "the scheduler and the workers stay up for the whole run"
    finally:
        for proc in reversed(procs):
            _stop(proc)
    _study(tmp_path / "serial", "--jobs", "1")
    cluster, serial = _tables(tmp_path / "cluster"), _tables(tmp_path / "serial")
    assert cluster and cluster.keys() == serial.keys()
    for name in serial:
        assert cluster[name] == serial[name], name
    workers = "".join((tmp_path / f"worker{k}.log").read_text() for k in range(2))
    assert workers.count("Registered to") >= 2, workers[-2000:]
