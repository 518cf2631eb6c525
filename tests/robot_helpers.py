"""Shared by the robot-export tests: a small stand-in design of boxes, one or two per link, at the real
layout's stations (fast). The default design's real parts are the session fixture ``default_parts``.

``mini_parts`` is a STAND-IN, for the exporter's mechanics only (files, frames, digits, the gate). It is not
the fish: never swim it and never report a number from it. Swimming uses the real parts (the session fixture
``default_parts`` of tests/conftest.py)."""
from __future__ import annotations

from build123d import Axis, Box, Pos

from swiftfin.layout import geometry as layout
from swiftfin.cad.part import PartSpec


def mini_parts(p) -> list[PartSpec]:
    """Stand-in for the exporter's mechanics only (see the module docstring). A box per link inside the hull
    at its segment's middle (one turned 30 deg about z so the tensor has products of inertia), a bought
    'battery' in the head, and a thin 'fin' plate behind the hull end."""
    out = []
    for seg in layout.hull_segments(p):
        s = 0.5 * (seg.s_start_mm + seg.s_end_mm)
        length = min(40.0, 0.6 * (seg.s_end_mm - seg.s_start_mm))
        box = Pos(-s, 0, 2.0) * Box(length, 12, 10)
        if seg.link == 1:
            box = Pos(-s, 0, 2.0) * Box(length, 12, 10).rotate(Axis.Z, 30)
        out.append(PartSpec(f"block_{seg.name}", box, seg.link, "test"))
    out.append(PartSpec("battery", Pos(-0.09 * p.body.length_mm, 0, -12) * Box(48.5, 26.5, 17.5), 0, "bought",
                        printed=False, mass_kg=0.046))
    x_fin = -(layout.hull_end_mm(p) + 25.0)
    out.append(PartSpec("fin_plate", Pos(x_fin, 0, 0) * Box(30, 2.4, 120), p.joints.count, "fin"))
    return out


def mujoco_link_inertial(mujoco, model, name: str):
    """A link's mass, COM and inertia (link frame) as MuJoCo compiled them: its link body plus the welded
    buoyancy body ``<name>_buoyancy`` at its centre of buoyancy (exports/mjcf.py)."""
    import numpy as np

    from swiftfin.exports.inertia import combine, make_inertial

    items = []
    for body, offset in ((model.body(name), None), (model.body(f"{name}_buoyancy"), True)):
        R = np.zeros(9)
        mujoco.mju_quat2Mat(R, body.iquat)
        R = R.reshape(3, 3)
        com = np.asarray(body.ipos) + (np.asarray(body.pos) if offset else 0.0)
        items.append(make_inertial(body.mass[0], com, R @ np.diag(body.inertia) @ R.T))
    return combine(items)
