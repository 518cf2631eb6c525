"""The part families, in build order: name -> 'module:function', each ``function(params) -> list[PartSpec]``."""
from __future__ import annotations

import importlib

FAMILIES: dict[str, str] = {
    "hull": "swiftfin.cad.hull:make_hull_segments",
    "link": "swiftfin.cad.link:make_joint_links",
    "fin": "swiftfin.cad.fin:make_caudal_fin",
    "spool": "swiftfin.cad.spool:make_spools",
    "mount": "swiftfin.cad.mount:make_motor_mounts",
    "guide": "swiftfin.cad.guide:make_guides",
    "cradle": "swiftfin.cad.cradle:make_cradles",
    "bought": "swiftfin.cad.bought:make_bought_parts",
}


def family_function(name: str):
    """``function(params) -> list[PartSpec]`` of the family, with every fastener's holes cut in its parts
    (:func:`swiftfin.cad.fastening.apply_fasteners`): the families make the material (bosses, tabs), the
    fastener records decide the holes, so the two parts a screw joins always agree."""
    module, func = FAMILIES[name].split(":")
    make = getattr(importlib.import_module(module), func)

    def build(p):
        from swiftfin.cad.fastening import apply_fasteners
        return apply_fasteners(p, make(p))

    build.__name__ = build.__qualname__ = func
    build.__doc__ = make.__doc__
    return build
