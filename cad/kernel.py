"""build123d, imported on first use.

The design loader and the design rules read the numbers of the part families (the links' room for their
hardware, the hull's split plan) on every command; importing the CAD kernel costs seconds, and only the
solids need it. Part modules write ``from swiftfin.cad.kernel import bd`` and use ``bd.Solid`` etc. as usual, or
``from swiftfin.cad.kernel import Solid, Plane`` (resolved from build123d when the part module is imported, which
happens only when its family is built). No other module of ``swiftfin.cad`` imports build123d itself.
"""
from __future__ import annotations


class _LazyKernel:
    def __getattr__(self, name):
        import build123d
        return getattr(build123d, name)


bd = _LazyKernel()


def __getattr__(name: str):
    """``from swiftfin.cad.kernel import Solid``: build123d's names, imported on first use (PEP 562)."""
    if name.startswith("__"):
        raise AttributeError(name)
    import build123d
    try:
        return getattr(build123d, name)
    except AttributeError:
        raise AttributeError(f"module 'swiftfin.cad.kernel' (build123d) has no attribute {name!r}") from None
