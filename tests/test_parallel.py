"""exports/parallel: map_parts (results in order on forked workers) and Forked (one job beside the caller); a
process that dies is an error, not a hang."""
from __future__ import annotations

import os
from concurrent.futures.process import BrokenProcessPool

import pytest

from swiftfin.core.errors import BuildError
from swiftfin.exports.parallel import Forked, map_parts


def test_results_come_back_in_order_from_the_workers():
    parent = os.getpid()
    out = map_parts(lambda x: (x * x, os.getpid()), list(range(7)), jobs=2)
    assert [v for v, _ in out] == [x * x for x in range(7)]
    assert any(pid != parent for _, pid in out)          # done on forked workers, not here


def test_a_worker_that_dies_raises_instead_of_waiting_for_ever():
    def die(x):
        if x == 3:
            os._exit(7)          # what a crash in native code or the OOM killer looks like from here
        return x

    with pytest.raises(BrokenProcessPool):
        map_parts(die, list(range(6)), jobs=2)


def test_an_exception_in_a_worker_reaches_the_caller():
    def fail(x):
        if x == 2:
            raise ValueError(f"part {x}: mass model failed")
        return x

    with pytest.raises(ValueError, match="part 2"):
        map_parts(fail, list(range(4)), jobs=2)


def test_forked_returns_its_value_from_another_process():
    parent = os.getpid()
    job = Forked(lambda: ("done", os.getpid()))
    value, pid = job.result()
    assert value == "done" and pid != parent
    with pytest.raises(RuntimeError, match="twice"):
        job.result()


def test_forked_raises_the_error_with_its_exit_code():
    def fail():
        raise BuildError("assembly: caudal_fin meets hull_peduncle_upper by 0.4 mm", exit_code=3)

    with pytest.raises(BuildError, match="caudal_fin meets") as err:
        Forked(fail).result()
    assert err.value.exit_code == 3


def test_forked_process_that_dies_raises_instead_of_waiting_for_ever():
    with pytest.raises(BrokenProcessPool):
        Forked(lambda: os._exit(7)).result()


def test_forked_run_here_runs_at_result_in_this_process():
    ran = []
    job = Forked(lambda: ran.append(os.getpid()) or len(ran), run_here=True)
    assert ran == []
    assert job.result() == 1 and ran == [os.getpid()]


def test_forked_cancel_ends_the_process():
    import time
    job = Forked(lambda: time.sleep(60))
    t0 = time.perf_counter()
    job.cancel()
    assert time.perf_counter() - t0 < 10
    job.cancel()                  # twice: nothing more
