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
    "bought": "swiftfin.cad.bought:make_bought_parts",
}


def family_function(name: str):
    module, func = FAMILIES[name].split(":")
    return getattr(importlib.import_module(module), func)
