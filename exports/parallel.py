"""Per-part work, on every core and stored: the mass model's layer slicing, the link meshes and the report's
part pictures are independent from part to part and take seconds each. :func:`map_parts` runs them on forked
workers (the work and the parts, OpenCascade solids, need not be picklable; only the results are);
:func:`memoized` files each result in the application's store, so that the layers below it stay pure."""
from __future__ import annotations

import os

_MAP_STATE: tuple = ()      # (fn, items) of the running map_parts, inherited by its forked workers
_CALL_STATE: dict = {}      # id -> fn of a Forked being started, inherited by its forked process


def _map_one(i: int):
    fn, items = _MAP_STATE
    return fn(items[i])


def map_parts(fn, items: list, jobs: int | None = 1) -> list:
    """``[fn(x) for x in items]``, on ``jobs`` forked processes (None: one per core; 1 or one item: here).

    Each part's mass is independent of the others' (the layer slicing of a hull piece takes seconds), so on a
    two-core machine a cold build's mass model takes about half the time. The workers are forked, so ``fn``
    and the parts (OpenCascade solids) need not be picklable; only the results are. Where fork is not
    available, and inside a worker of another map (whose processes may not have children), the items are done
    here, one after the other.

    ``fn`` must not run OpenCascade booleans: build123d runs them on OCCT's thread pool
    (``SetRunParallel(True)``), and a child forked from a process whose pool has started waits for ever on the
    pool's threads, which fork does not copy (seen 2026-11-26: part families built on forked workers hung on the
    second build in one process). The per-part work mapped here reads meshes and B-rep volume integrals only.
    """
    global _MAP_STATE
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    n = len(items)
    jobs = (os.cpu_count() or 1) if jobs is None else jobs
    jobs = min(jobs, n)
    if jobs <= 1 or "fork" not in mp.get_all_start_methods() or mp.current_process().daemon:   # a worker: here
        return [fn(x) for x in items]
    _MAP_STATE = (fn, items)
    try:
        # concurrent.futures, not multiprocessing.Pool: a worker that dies (a crash in native code, the OOM
        # killer) raises BrokenProcessPool here, where Pool.map would wait for its lost result for ever
        with ProcessPoolExecutor(jobs, mp_context=mp.get_context("fork")) as pool:
            return list(pool.map(_map_one, range(n)))
    finally:
        _MAP_STATE = ()


def _call_one(key: int):
    return _CALL_STATE[key]()


def _can_fork() -> bool:
    import multiprocessing as mp
    return "fork" in mp.get_all_start_methods() and not mp.current_process().daemon


class Forked:
    """``fn()`` on one forked process while the caller goes on; :meth:`result` returns its value or raises its
    exception (a process that dies raises BrokenProcessPool). The rule of :func:`map_parts` holds: ``fn`` must
    not run OpenCascade (the process is forked after the kernel's thread pool has started); only its result
    crosses back (pickled), so whatever ``fn`` changes in its copy of the caller's objects stays there.
    With ``run_here`` or where fork is not available (or inside a worker), ``fn`` runs at :meth:`result`."""

    def __init__(self, fn, run_here: bool = False):
        self._fn, self._pool, self._future, self._done = fn, None, None, False
        if run_here or not _can_fork():
            return
        import multiprocessing as mp
        from concurrent.futures import ProcessPoolExecutor

        _CALL_STATE[id(self)] = fn
        try:
            self._pool = ProcessPoolExecutor(1, mp_context=mp.get_context("fork"))
            self._future = self._pool.submit(_call_one, id(self))   # fork context: forks here, at the submit
        finally:
            _CALL_STATE.pop(id(self), None)

    def result(self):
        if self._done:
            raise RuntimeError("Forked.result() called twice")
        self._done = True
        if self._future is None:
            return self._fn()
        try:
            return self._future.result()
        finally:
            self._pool.shutdown()

    def cancel(self) -> None:
        """Stop waiting for it (after the caller failed): the process is ended, its result dropped."""
        if self._pool is None or self._done:
            return
        self._done = True
        for proc in list((getattr(self._pool, "_processes", None) or {}).values()):
            proc.terminate()
        self._pool.shutdown(wait=True, cancel_futures=True)


def memoized(memo, stage: str, labels: tuple[str, ...], extra, compute):
    """``compute()``, or its stored result: ``memo(stage, labels, extra, compute)`` is the application's store
    (swiftfin.cache.StageCache), keyed by the content of the named parts, ``extra`` and the stage's code. The
    functions here stay pure: with ``memo`` None they compute."""
    return compute() if memo is None else memo(stage, tuple(labels), extra, compute)
