"""The bench a joint log was measured on (issue 14, item 1: "a bench that holds a different link is described by
an optional small bench file, never by editing code"). ``swiftfin synth joint --bench FILE`` simulates it,
``swiftfin fit joint --bench FILE`` models it, and the replay (:mod:`swiftfin.calibration.replay`) puts its link
on the simulated hinge::

    # bench.toml: what the joint bench holds
    link_inertia_kg_m2 = 6e-6          # the link on the hinge, about the hinge axis (weigh it, or take it from CAD)
    bearing_damping_nm_s_rad = 2e-4    # the bare hinge's viscous damping (a ring-down of the free link gives it)

A key left out keeps its default (:data:`~swiftfin.calibration.joint.BENCH_LINK_INERTIA_KG_M2` and
:data:`~swiftfin.calibration.joint.BENCH_BEARING_DAMPING_NM_S_RAD`: a 10 g printed arm in air). The link is in
air: a bench in water would add the water's added mass to the link, which this file does not model (give the
sum as ``link_inertia_kg_m2``).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

from swiftfin.calibration.joint import BENCH_BEARING_DAMPING_NM_S_RAD, BENCH_LINK_INERTIA_KG_M2, JointDesign
from swiftfin.core.params import ParamError, Problem, parse_toml_bytes, read_file_bytes, suggest

WHAT = ("bench file", "the bench file")
#: key -> (default, lowest, highest, what it is)
KEYS = {
    "link_inertia_kg_m2": (BENCH_LINK_INERTIA_KG_M2, 1e-9, 1.0, "inertia of the link about the hinge [kg m^2]"),
    "bearing_damping_nm_s_rad": (BENCH_BEARING_DAMPING_NM_S_RAD, 0.0, 10.0,
                                 "viscous damping of the bare hinge [N m s/rad]"),
}


@dataclass(frozen=True)
class Bench:
    link_inertia_kg_m2: float = BENCH_LINK_INERTIA_KG_M2
    bearing_damping_nm_s_rad: float = BENCH_BEARING_DAMPING_NM_S_RAD
    source: str = "the defaults of calibration/joint.py (a 10 g printed arm in air)"

    def on(self, d: JointDesign) -> JointDesign:
        """The joint's design constants with this bench's link and bearing."""
        return dataclasses.replace(d, link_inertia_kg_m2=self.link_inertia_kg_m2,
                                   bearing_damping_nm_s_rad=self.bearing_damping_nm_s_rad)


def load_bench(path: str | Path) -> Bench:
    """Read and check a bench file; every problem at once, naming the file and the key."""
    name = str(path)
    raw = parse_toml_bytes(read_file_bytes(path, *WHAT), name, *WHAT)
    out, vals = [], {}
    for k, v in raw.items():
        if k not in KEYS:
            out.append(Problem(k, v, "unknown key (expected " + ", ".join(KEYS) + ")" + suggest(k, KEYS)))
            continue
        _, lo, hi, what = KEYS[k]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or not lo <= v <= hi:
            out.append(Problem(k, v, f"expected a number in [{lo:g}, {hi:g}]: the {what}"))
            continue
        vals[k] = float(v)
    if out:
        raise ParamError(name, out, WHAT[1])
    return Bench(**vals, source=name)
