"""exports/parallel.map_parts: results in order on forked workers, and a worker that dies is an error, not a hang."""
from __future__ import annotations

import os
from concurrent.futures.process import BrokenProcessPool

import pytest

from swiftfin.exports.parallel import map_parts


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
