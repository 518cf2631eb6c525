"""build123d, imported on first use.

The design loader and the design rules read the numbers of the part families (the links' room for their
hardware, the hull's split plan) on every command; importing the CAD kernel costs seconds, and only the
solids need it. Part modules write ``from cad.kernel import bd`` and use ``bd.Solid`` etc. as usual.
"""
from __future__ import annotations


class _LazyKernel:
    def __getattr__(self, name):
        import build123d
        return getattr(build123d, name)


bd = _LazyKernel()
