"""The part families, in build order: name -> 'module:function', each ``function(params) -> list[PartSpec]``."""
from __future__ import annotations

import importlib

FAMILIES: dict[str, str] = {
    "hull": "cad.hull:make_hull_segments",
    "link": "cad.link:make_joint_links",
    "fin": "cad.fin:make_caudal_fin",
    "spool": "cad.spool:make_spools",
    "mount": "cad.mount:make_motor_mounts",
    "guide": "cad.guide:make_guides",
    "bought": "cad.bought:make_bought_parts",
}


def family_function(name: str):
    module, func = FAMILIES[name].split(":")
    return getattr(importlib.import_module(module), func)
