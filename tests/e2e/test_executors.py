"""Campaigns through standard executors: the same trials give the same results on every one."""

from __future__ import annotations

import dataclasses
import json
import os
import sys
from concurrent.futures import Executor
from pathlib import Path

import pytest

from palpate.campaigns.campaign import campaign_trials, run_campaign, summarize_campaign
from palpate.campaigns.executors import (
    EXECUTORS,
    ExecutorUnavailableError,
    SerialExecutor,
    blas_share,
    open_executor,
    process_pool,
)
from palpate.cli import main
from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.simulation.trial import TrialOutcome, TrialSpec

STACK = load_stack()
BENCH = load(SceneConfig, resolve("scenes/bench.yaml"))
# three trials on different samples and lengths (every 7th of the 55 of the bench campaign)
SPECS: list[TrialSpec] = campaign_trials(BENCH, STACK, seed=4)[::7][:3]


def _fingerprint(outcomes: list[TrialOutcome]) -> list[tuple[object, ...]]:
    """What must not depend on the executor: trial, state, both estimates (the joint fit with
    its interval), control ticks, simulated time; then the campaign's table, row by row."""
    rows: list[tuple[object, ...]] = []
    for o in outcomes:
        est = o.estimate
        jf = o.joint
        rows.append(
            (
                o.spec.trial_id,
                o.state,
                None if est is None else est.modulus,
                None if est is None else est.delta,
                None if est is None else est.force,
                None if jf is None else (jf.modulus, jf.ci_low, jf.ci_high, jf.contact),
                o.ticks,
                o.sim_time,
            )
        )
    outlier = BENCH.campaign.outlier_above_kpa * 1e3
    for method in ("joint", "paper"):
        for row in summarize_campaign(outcomes, outlier, method):
            rows.append((method, row.sample, row.trials, dataclasses.astuple(row.summary)))
    return rows


@pytest.fixture(scope="module")
def serial() -> list[tuple[object, ...]]:
    return _fingerprint(run_campaign(SPECS, BENCH, STACK))


def test_the_reference_run_estimates_every_trial(serial: list[tuple[object, ...]]) -> None:
    trials, table = serial[: len(SPECS)], serial[len(SPECS) :]
    assert [r[0] for r in trials] == [s.trial_id for s in SPECS]
    assert len({s.sample for s in SPECS}) == 3
    assert all(r[1] == "done" and r[2] is not None and r[5] is not None for r in trials)
    assert [r[:3] for r in table] == [(m, s.sample, 1) for m in ("joint", "paper") for s in SPECS]


@pytest.mark.parametrize("kind", ["serial", "thread", "process"])
def test_results_do_not_depend_on_the_executor(kind: str, serial: list[tuple[object, ...]]) -> None:
    seen: list[str] = []
    with open_executor(kind, workers=2) as executor:
        outcomes = run_campaign(
            SPECS, BENCH, STACK, executor=executor, progress=lambda o: seen.append(o.spec.trial_id)
        )
    assert _fingerprint(outcomes) == serial  # in the order of the specs, bit for bit
    assert sorted(seen) == sorted(s.trial_id for s in SPECS)  # progress once per trial


@pytest.fixture(scope="module")
def pooled() -> list[tuple[object, ...]]:
    """The campaign through a local process pool of two workers."""
    with open_executor("process", workers=2) as executor:
        return _fingerprint(run_campaign(SPECS, BENCH, STACK, executor=executor))


@pytest.mark.slow
def test_a_local_dask_cluster_gives_the_process_pools_table(
    pooled: list[tuple[object, ...]], serial: list[tuple[object, ...]]
) -> None:
    # Dask distributed is in the dev extras: this runs in CI. An in-process cluster (worker
    # threads, no spawned processes) keeps it quick; the timeouts are generous for a loaded
    # machine, and nothing here measures time.
    distributed = pytest.importorskip("distributed")
    seen: list[str] = []
    with (
        distributed.LocalCluster(
            n_workers=1,
            threads_per_worker=2,
            processes=False,
            dashboard_address=None,
            scheduler_port=0,
        ) as cluster,
        distributed.Client(cluster, timeout="120s") as client,
    ):
        executor: Executor = client.get_executor()
        outcomes = run_campaign(
            SPECS, BENCH, STACK, executor=executor, progress=lambda o: seen.append(o.spec.trial_id)
        )
    assert _fingerprint(outcomes) == pooled == serial  # estimates, ticks, sim time, the table
    assert sorted(seen) == sorted(s.trial_id for s in SPECS)


def test_serial_executor_reports_errors_through_the_future() -> None:
    future = SerialExecutor().submit(int, "not a number")
    assert future.done()
    with pytest.raises(ValueError, match="invalid literal"):
        future.result()
    assert SerialExecutor().submit(pow, 2, 10).result() == 1024


def test_bad_executor_requests_are_refused_clearly(monkeypatch: pytest.MonkeyPatch) -> None:
    assert set(EXECUTORS) == {"process", "thread", "serial", "dask"}
    with pytest.raises(ExecutorUnavailableError, match="unknown executor 'ray'"):
        open_executor("ray")
    with pytest.raises(ExecutorUnavailableError, match="--scheduler is for --executor dask"):
        open_executor("process", 2, "tcp://127.0.0.1:8786")
    with pytest.raises(ExecutorUnavailableError, match="--workers must be >= 1"):
        open_executor("thread", 0)
    monkeypatch.setitem(sys.modules, "distributed", None)  # as if it were not installed
    with pytest.raises(ExecutorUnavailableError, match=r"palpate\[dask\]"), open_executor("dask"):
        pass


def test_palpate_sim_takes_the_executor_flag(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["sim", "--campaign", "bench", "--limit", "2", "--seed", "4", "--no-plots", "--json"]
    code = main([*argv, "--out", str(tmp_path), "--executor", "thread", "--workers", "2"])
    out = json.loads(capsys.readouterr().out)
    assert code == 0
    trials = campaign_trials(BENCH, STACK, seed=4)[:2]
    assert [t["trial"] for t in out["trials"]] == [s.trial_id for s in trials]
    assert all(t["state"] == "done" for t in out["trials"])
    assert main([*argv, "--out", str(tmp_path), "--scheduler", "tcp://127.0.0.1:1"]) == 2
    assert "--scheduler is for --executor dask" in capsys.readouterr().err


def _blas_threads() -> list[int]:
    import scipy.linalg  # noqa: F401  (scipy's own OpenBLAS too, as the map's GP loads it)
    from threadpoolctl import threadpool_info

    return [int(lib["num_threads"]) for lib in threadpool_info() if lib["user_api"] == "blas"]


def test_a_pool_worker_runs_blas_on_its_share_of_the_cores() -> None:
    """Two workers on two cores, each spreading its products over both, wait on each other
    (docs/speed.md, "One BLAS thread a worker"): a pool's worker keeps BLAS to its share."""
    cores = os.cpu_count() or 1
    with process_pool(cores) as pool:
        threads = pool.submit(_blas_threads).result()
    assert threads
    assert set(threads) == {1}
    assert blas_share(2) == max(1, cores // 2)
    assert blas_share(1) == cores
