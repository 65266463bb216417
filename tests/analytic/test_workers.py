"""Worker pools that pay for themselves (``analytic/_workers.py``): how many
processes a piece of work is worth, and a map that measures its first item in
the calling process before it forks."""
from __future__ import annotations

import os

import pytest

from trilith_xval.analytic import _workers
from trilith_xval.analytic._workers import PAYOFF, POOL_START_CPU_S, map_measured, pool_size


def test_pool_size_counts_workers_the_work_pays_for():
    one_worker = PAYOFF * POOL_START_CPU_S  # the work that pays for one worker's start
    assert pool_size(10, 1.01 * one_worker / 10, 8) == 1
    assert pool_size(10, 2.01 * one_worker / 10, 8) == 2
    assert pool_size(10, 100 * one_worker, 8) == 8  # never more than asked
    assert pool_size(3, 100 * one_worker, 8) == 3  # nor more than the items
    assert pool_size(1, 100 * one_worker, 8) == 1
    assert pool_size(10, 100 * one_worker, 1) == 1
    assert pool_size(10, 0.0, 8) == 1


def _where(x: int) -> tuple[int, int]:
    return x * x, os.getpid()


def test_map_measured_runs_the_first_item_here_and_keeps_the_order(monkeypatch):
    items = list(range(7))
    monkeypatch.setattr(_workers, "POOL_START_CPU_S", 0.0)  # any work pays: a pool
    done = []
    out = map_measured(_where, items, 2, on_done=lambda i, r: done.append(i))
    assert [r[0] for r in out] == [x * x for x in items]
    assert out[0][1] == os.getpid()
    assert {r[1] for r in out[1:]} - {os.getpid()}, "the rest ran in workers"
    assert sorted(done) == items


def test_map_measured_without_a_pool_when_the_work_is_cheap(monkeypatch):
    monkeypatch.setattr(_workers, "POOL_START_CPU_S", 1e9)
    out = map_measured(_where, range(5), 2)
    assert [r[0] for r in out] == [0, 1, 4, 9, 16]
    assert {r[1] for r in out} == {os.getpid()}


def test_map_measured_of_nothing():
    assert map_measured(_where, [], 4) == []


@pytest.mark.parametrize("workers", [1, 3])
def test_map_measured_raises_an_item_error(workers, monkeypatch):
    monkeypatch.setattr(_workers, "POOL_START_CPU_S", 0.0)
    with pytest.raises(ZeroDivisionError):
        map_measured(_inverse, [1, 2, 0, 4], workers)


def _inverse(x: int) -> float:
    return 1 / x
