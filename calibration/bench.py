"""The bench a joint log was measured on (issue 14, item 1: "a bench that holds a different link is described by
an optional small bench file, never by editing code"). ``swiftfin synth joint --bench FILE`` simulates it,
``swiftfin fit joint --bench FILE`` models it, and the replay (:mod:`swiftfin.calibration.replay`) puts its link
on the simulated hinge.

Without a bench file the hinge holds the design's own link: the links behind the joint with the fin, held
straight, in air (:func:`swiftfin.layout.loads.hinge_inertia`). A bench file says what differs::

    # bench.toml: what the joint bench holds
    medium = "water"                   # the design's link in water: with its added mass and the water it carries
    link_inertia_kg_m2 = 6e-6          # or another link: its inertia about the hinge (weigh it, or take it from CAD;
                                       # in water, include the water's share)
    bearing_damping_nm_s_rad = 2e-4    # the bare hinge's viscous damping (a ring-down of the free link gives it)

Every key is optional: ``link_inertia_kg_m2`` replaces the design's link (``medium`` then only says where the
bench stands), ``bearing_damping_nm_s_rad`` defaults to
:data:`~swiftfin.calibration.joint.BENCH_BEARING_DAMPING_NM_S_RAD` (a greased steel pin in a printed bore).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

from swiftfin.calibration.joint import (BENCH_BEARING_DAMPING_NM_S_RAD, BENCH_LINK_INERTIA_KG_M2, JointDesign,
                                        joint_design)
from swiftfin.core.schema import Params
from swiftfin.core.params import ParamError, Problem, parse_toml_bytes, read_file_bytes, suggest

WHAT = ("bench file", "the bench file")
#: numeric key -> (lowest, highest, what it is)
KEYS = {
    "link_inertia_kg_m2": (1e-9, 1.0, "inertia of the link about the hinge [kg m^2]"),
    "bearing_damping_nm_s_rad": (0.0, 10.0, "viscous damping of the bare hinge [N m s/rad]"),
}
MEDIA = ("air", "water")


@dataclass(frozen=True)
class Bench:
    """What a joint bench holds. ``link_inertia_kg_m2`` None: the design's own link (in ``medium``)."""
    link_inertia_kg_m2: float | None = None
    bearing_damping_nm_s_rad: float = BENCH_BEARING_DAMPING_NM_S_RAD
    medium: str = "air"
    source: str = "no bench file: the design's link in air"

    def design(self, p: Params, joint: int | None = None) -> JointDesign:
        """The joint's design constants on this bench: the design's link in the bench's medium, or the bench's own
        link, and the bench's bearing."""
        d = joint_design(p, joint, self.medium)
        if self.link_inertia_kg_m2 is not None:
            d = dataclasses.replace(d, link_inertia_kg_m2=self.link_inertia_kg_m2,
                                    link_inertia_source=f"{self.link_inertia_kg_m2:.3g} kg m^2: the bench's link "
                                                        f"({self.source})")
        return dataclasses.replace(d, bearing_damping_nm_s_rad=self.bearing_damping_nm_s_rad)


#: The bare printed arm (:data:`~swiftfin.calibration.joint.BENCH_LINK_INERTIA_KG_M2`): the bench of the project's
#: own synthetic suite and tests, and of the independent MuJoCo bench.
BARE_ARM = Bench(link_inertia_kg_m2=BENCH_LINK_INERTIA_KG_M2, source="the bare printed arm of calibration/joint.py")


def load_bench(path: str | Path) -> Bench:
    """Read and check a bench file; every problem at once, naming the file and the key."""
    name = str(path)
    raw = parse_toml_bytes(read_file_bytes(path, *WHAT), name, *WHAT)
    out, vals = [], {}
    for k, v in raw.items():
        if k == "medium":
            if v not in MEDIA:
                out.append(Problem(k, v, "expected \"air\" or \"water\": where the bench holds the design's link"))
            else:
                vals[k] = v
            continue
        if k not in KEYS:
            names = ("medium", *KEYS)
            out.append(Problem(k, v, "unknown key (expected " + ", ".join(names) + ")" + suggest(k, names)))
            continue
        lo, hi, what = KEYS[k]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or not lo <= v <= hi:
            out.append(Problem(k, v, f"expected a number in [{lo:g}, {hi:g}]: the {what}"))
            continue
        vals[k] = float(v)
    if out:
        raise ParamError(name, out, WHAT[1])
    return Bench(**vals, source=name)
