"""A sweep through a real local Dask scheduler and workers on loopback equals the serial sweep."""

import pytest

from mpm_fem.app.sweep import run_cases
from mpm_fem.problems.cases import sod_case

distributed = pytest.importorskip("dask.distributed", reason="the [dask] extra is not installed")

CASES = [{"h": h, "T": 0.02, "ppc": ppc} for h in (0.05, 0.025) for ppc in (2, 4)]


def test_dask_sweep_equals_serial_bit_for_bit(tmp_path):
    serial = run_cases(sod_case, CASES, jobs=1, progress=False)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None, silence_logs=40) as cluster:
        assert cluster.scheduler_address.startswith("tcp://127.0.0.1:")
        remote = run_cases(sod_case, CASES, scheduler=cluster.scheduler_address, cache_dir=tmp_path, progress=False)
    assert remote == serial
    assert len(list(tmp_path.glob("*.json"))) == len(CASES)
