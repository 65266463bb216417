"""The Dask path of compare.run.runs.run_many against the local one, on a real local
cluster: a scheduler and two worker processes (``LocalCluster(processes=True)``:
each worker is a separate Python process started by its nanny)."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from trilith_xval.compare.run import runs
from trilith_xval.compare.campaign.validation import CampaignConfig, _run_one
from trilith_xval.compare.campaign.validation_jobs import history_job
from trilith_xval.compare.run.store import RunStore
from tests.support.trajectories import assert_same_trajectory

distributed = pytest.importorskip("distributed")
from tests.support.paths import ROOT


@pytest.fixture(scope="module")
def cluster():
    # The workers import compare/ from this checkout; put PYTHONPATH back after,
    # or every later subprocess of the run sees the checkout (the packaging test).
    before = os.environ.get("PYTHONPATH")
    os.environ["PYTHONPATH"] = os.pathsep.join([str(ROOT), *filter(None, [before])])
    try:
        with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                      dashboard_address=None, silence_logs=40) as c:
            yield c
    finally:
        if before is None:
            os.environ.pop("PYTHONPATH", None)
        else:
            os.environ["PYTHONPATH"] = before


def _jobs(fig5):
    """Campaign history jobs: pymunk at the paper's A and D, coarse steps (fast)."""
    config = CampaignConfig(engines=("pymunk",), engine_dt=5e-4)
    return [history_job("pymunk", scene, point, config)
            for scene in (fig5, fig5.without_pendulum()) for point in ("A", "D")]


def test_dask_results_equal_local_results(cluster, fig5):
    jobs = _jobs(fig5)
    local = [out for out, *_ in runs.run_many(_run_one, jobs, workers=2)]
    remote = [out for out, *_ in runs.run_many(_run_one, jobs,
                                               scheduler=cluster.scheduler_address)]
    assert len(remote) == len(jobs)
    for a, b in zip(local, remote):
        assert_same_trajectory(a, b, timings=False)


def test_dask_workers_fill_the_callers_store(cluster, fig5, tmp_path):
    jobs = _jobs(fig5)
    store = RunStore(tmp_path)
    with runs.using(store):
        remote = [out for out, *_ in runs.run_many(_run_one, jobs,
                                                   scheduler=cluster.scheduler_address)]
        assert store.count("run") == len(jobs)  # stored by the workers
        runs.STATS.clear()
        again = [out for out, *_ in runs.run_many(_run_one, jobs, workers=1)]
        assert runs.STATS["hits"] == len(jobs) and runs.STATS["computed"] == 0
    for a, b in zip(remote, again):
        assert_same_trajectory(a, b)  # what the cluster computed, bit for bit


def test_spectrum_cli_on_the_cluster(cluster, tmp_path):
    def spectrum(*extra):
        proc = subprocess.run([sys.executable, "-m", "trilith_xval.compare.cli.main", "spectrum", "--omega",
                               "8:14:2", "--json", "--no-cache", *extra], cwd=ROOT,
                              env=os.environ, capture_output=True, text=True, timeout=600)
        assert proc.returncode == 0, proc.stderr
        doc = json.loads(proc.stdout)
        doc.pop("timings")  # wall times live apart from the results
        return doc
    assert spectrum("--scheduler", cluster.scheduler_address) == spectrum("--workers", "2")


def test_the_atlas_on_the_cluster_equals_the_local_one(cluster):
    from trilith_xval.compare.campaign.atlas import AtlasConfig, run_atlas
    config = AtlasConfig(engines=("pymunk",), scenes=(("fig8_lam5_gamma0.1", "sine"),),
                         omegas=(12.0, 18.0), factors=(1.0, 2.0), cases=("no_pendulum",))

    def rows(doc):  # the measurement, without what differs by where it ran
        drop = ("cpu_s", "from_store")
        return [(pt["omega"], pt["a_reference"], pt["valid"],
                 [{k: v for k, v in r.items() if k not in drop} for r in pt["engines"]["pymunk"]])
                for pt in doc["points"]]
    with runs.using(None):
        local = run_atlas(config, workers=1)
        runs.set_scheduler(cluster.scheduler_address)
        try:
            remote = run_atlas(config)
        finally:
            runs.set_scheduler(None)
    assert any(pt["engines"]["pymunk"] for pt in local["points"])  # something was measured
    assert rows(remote) == rows(local)
    # The cluster's workers are not this process's children: their CPU is not
    # claimed as the run's whole cost (the engine jobs' own CPU is in the table).
    assert remote["local_cpu_s"] is None and local["local_cpu_s"] > 0


def test_unreachable_scheduler_is_a_usage_error():
    proc = subprocess.run([sys.executable, "-m", "trilith_xval.compare.cli.main", "spectrum", "--omega", "10",
                           "--no-cache", "--scheduler", "tcp://127.0.0.1:9"], cwd=ROOT,
                          env={**os.environ, "PYTHONPATH": str(ROOT)}, capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines()[-1].startswith("error: --scheduler")


def test_parallel_slots_counts_the_clusters_threads_not_local_workers(cluster):
    # Two single-threaded workers: batches sized for the cluster, not for --workers.
    runs.set_scheduler(cluster.scheduler_address)
    try:
        assert runs.parallel_slots(1) == 2
    finally:
        runs.set_scheduler(None)
    assert runs.parallel_slots(3) == 3
