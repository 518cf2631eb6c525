"""Per-part work started while the later part families are still being modelled.

The part families run one after the other in the build's process, and OpenCascade keeps about one and a half of
the machine's cores busy (a cold build of the default design: 59 s of modelling for 86 s of CPU on two cores).
What a finished part alone decides need not wait for the others: its mass model's layer slicing
(:func:`swiftfin.exports.print_model.layer_core`, seconds for a hull piece) reads only its mesh and its print
orientation. :class:`Prefetch` hands that work, part by part as its family finishes, to one worker process that
files each result in the build's stage cache (:class:`swiftfin.cache.StageCache`, stage ``part_core``) under the
very key the mass model looks up later, so the mass model finds it there instead of computing it.

The worker is forked when the build starts, before the first family runs OpenCascade, and it never calls the
CAD kernel (a child forked from a process whose OpenCascade thread pool runs would wait for ever on it: see
:mod:`swiftfin.exports.parallel`, whose workers keep to the same rule). It is not spawned: a spawned child imports
the caller's main module again, and a user's script that calls the build without a ``__main__`` guard would
build again in it. A job that fails stores nothing: the mass model then computes the part itself, with its
fallbacks, and says why. Without a cache, with ``$SWIFTFIN_JOBS`` = 1, or where fork is not available, nothing is
prefetched.
"""
from __future__ import annotations

from concurrent.futures import Future

CORE_STAGE = "part_core"


def _core_job(root: str, modules: tuple[str, ...], key: list, vertices, faces, print_rotation, pm,
              layer_height_mm: float) -> bool:
    """In the worker: the part's layer core into the stage cache. True when it is stored."""
    import numpy as np
    import trimesh

    from swiftfin.cache import StageCache
    from swiftfin.exports.print_model import layer_core, rotation_matrix

    mesh = trimesh.Trimesh(np.asarray(vertices, dtype=float), np.asarray(faces, dtype=np.int64), process=False)
    try:
        StageCache(root, {CORE_STAGE: modules}).get(
            CORE_STAGE, key, lambda: layer_core(mesh, rotation_matrix(print_rotation), pm, layer_height_mm))
    except ValueError:          # the layers model cannot take this mesh: the mass model falls back itself
        return False
    return True


PLOTS_STAGE = ("report-plots", ("swiftfin.report.plots",))
"""The family-cache entry of the report's plots (name, modules): :func:`swiftfin.report.html.standard_plots`, a
function of the parameters alone, stored under the parameter keys they read."""


def report_plots(cache, params):
    """The report's three plots of ``params`` from ``cache`` (swiftfin.cache.FamilyCache), made and stored if it
    does not hold them."""
    from swiftfin.report.html import standard_plots

    name, modules = PLOTS_STAGE
    return cache.memoize(name, modules, params, standard_plots.__wrapped__)


def _plots_job(root: str, params) -> bool:
    """In the worker: the report's plots into the family cache."""
    from swiftfin.cache import FamilyCache

    report_plots(FamilyCache(root), params)
    return True


class Prefetch:
    """One worker process doing per-part work into the stage cache while the build goes on (see the module)."""

    def __init__(self, cache_root, modules: tuple[str, ...], jobs: int):
        self.root = str(cache_root)
        self.modules = tuple(modules)
        self.pool = None
        self.futures: list[Future] = []
        import multiprocessing as mp
        if jobs > 1 and "fork" in mp.get_all_start_methods() and not mp.current_process().daemon:
            from concurrent.futures import ProcessPoolExecutor
            self.pool = ProcessPoolExecutor(1, mp_context=mp.get_context("fork"))
            self.pool.submit(int).result()      # fork it now, before the families start the kernel's threads

    def parts(self, built, params) -> None:
        """Queue the layer cores of the printed parts in ``built`` (pipeline.BuiltPart, just made, not cached)."""
        if self.pool is None:
            return
        from swiftfin.exports.print_model import PrintModel, core_key

        pm = PrintModel.from_params(params)
        h = params.print.layer_height_mm
        for b in built:
            if b.cached or not b.spec.printed:
                continue
            key = [[b.content_sha256], core_key(pm, h, b.spec.print_rotation)]
            self.futures.append(self.pool.submit(
                _core_job, self.root, self.modules, key, b.export.mesh.vertices, b.export.mesh.faces,
                tuple(b.spec.print_rotation), pm, h))

    def plots(self, params) -> None:
        """Queue the report's plots (matplotlib, about 2 s, the parameters alone), which a rebuild after a change
        they read would otherwise draw at the end, on the report's critical path."""
        if self.pool is not None:
            self.futures.append(self.pool.submit(_plots_job, self.root, params))

    def close(self, cancel: bool = False) -> int:
        """Wait for the queued work (``cancel``: only for the job running, dropping the others) and stop the
        worker. Returns how many results were stored."""
        if self.pool is None:
            return 0
        stored = 0
        try:
            for f in [] if cancel else self.futures:
                try:
                    stored += bool(f.result())
                except Exception:   # a lost worker or a failed job: the mass model computes the part itself
                    pass
        finally:
            self.pool.shutdown(wait=True, cancel_futures=True)
            self.pool = None
        return stored
