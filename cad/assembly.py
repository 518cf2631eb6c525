"""The assembly: every part placed in the body frame, the kinematic chain, and the assembly checks.

Kinematics (layout/geometry.py): joint j (1..N) turns about a vertical axis through (x = -s_j, y = 0); a positive
angle turns the child's tail toward +y, i.e. a rotation by -theta about +z. A part on link k moves by
``T_1(theta_1) T_2(theta_2) ... T_k(theta_k)`` applied to its rest coordinates (the deepest joint first,
about its rest axis; the parents then carry that axis along).

Checks (all on triangle meshes, with manifold3d: ``min_gap`` for clearances, boolean intersection volume for
contacts; both are exact on the meshes, far faster than OCC booleans):

1. **Clearance over the range of motion.** For two parts on links a <= b only the joints a+1..b move one
   relative to the other. The joint box [-stop_j, +stop_j] is searched by branch and bound: at the box centre
   the gap g is measured; every point of the moving part lies within ``delta = sum_j D_j h_j`` of where it is
   at the centre (h_j: half-width of the box in joint j; D_j: bound on the distance of the moving part from
   joint j's axis: a rotation by h about an axis at distance D moves a point by 2 D sin(h/2) <= D h, and the
   distance from axis j is at most D_{j+1} + |s_{j+1} - s_j| whatever the joints behind do). So the gap over
   the whole box is >= g - delta: if that meets the clearance the box is done; if g itself misses it, that
   configuration is a failure; otherwise the box is halved across its widest D_j h_j. A box whose delta is
   below ``RESOLUTION_MM`` is accepted when its centre passes: the clearance is verified to within that
   resolution everywhere in the range of motion, not only at samples. While delta exceeds
   ``EXACT_BELOW_MM`` only the bounding boxes are compared (cheap; an exact gap with a wide search radius
   makes every triangle pair a candidate and costs seconds on the hull shells). The first configuration tried is the
   rest pose (the centre of the box), then the half-stops, then ever closer to the stops.
2. **Meant to touch.** The pairs in :data:`CONTACTS` (a link in its clevis, a mount against the hull wall, the
   fin tang in its slot, ...) may touch but not interpenetrate: their intersection volume may not exceed
   what the tessellation can create between two touching exact surfaces, ``2 x mesh tolerance x the
   smaller part's area``. Across joints they are sampled with a joint step that moves no point of the moving
   part by more than ``print.clearance_sliding_mm`` between samples.
3. **Inside the hull.** Every internal part (all but the hull and the fin) lies inside the hull's inner
   surface (the elliptic NACA envelope shrunk by the wall) at rest: checked on the mesh vertices, which is
   exact up to the tolerance because the envelope is convex (NACA 00xx half-thickness is concave in x and the
   sections are ellipses scaled by it) so a mesh whose vertices are inside lies inside.

**Cables and tubes** (:mod:`swiftfin.cad.cables`) take part like any other part: each cable piece and tube is a
mesh rigid with its link (family "cable" / "tube"). A cable keeps :func:`cable_clearance_mm` (half the sliding
clearance) from every part it is not declared to touch; its declared contacts (:data:`CONTACTS`) are its own
spool, tube, tendon groove and anchor, and its own pieces where they meet; a tube touches its guide channel or
bulkhead hole. ``check_assembly(..., focus=labels)`` checks only the pairs with one of ``labels`` (the cables
against parts already checked among themselves).

A failed check raises :class:`swiftfin.core.errors.BuildError` naming both parts, the joint angles and the
measured gap or overlap.
"""
from __future__ import annotations

import functools
import hashlib
import json
import math
import re
from pathlib import Path
from dataclasses import dataclass, field
from typing import Iterable

import numpy as np

from swiftfin.layout.geometry import (inner_envelope_excess_mm, joint_stations_mm,  # noqa: F401 (re-exported)
                                      joint_stop_angles_rad)
from swiftfin.core.errors import BuildError
from swiftfin.core.schema import Params

RESOLUTION_MM = 0.02        # clearance verified to within this everywhere in the range of motion
MAX_BOXES_PER_PAIR = 20000
EXACT_BELOW_MM = 4.0        # boxes whose motion bound exceeds this are split on the cheap bounding-box test alone  # branch-and-bound budget per pair (a guard against a pathological pair)

CABLE_CLEARANCE_FRACTION = 0.5
"""Gap a cable keeps from a part it is not meant to touch, as a fraction of ``print.clearance_sliding_mm``. A
tensioned cable runs on the straight line between its guides, so its place has no print error of its own; the
part's printed surface may stand out by half the sliding clearance (the sliding clearance is what two printed
surfaces need), so the cable keeps that half. Engineering default (issue 12)."""


def cable_clearance_mm(p: Params) -> float:
    """Least gap between a cable and a part it is not meant to touch [mm] (see :data:`CABLE_CLEARANCE_FRACTION`)."""
    return CABLE_CLEARANCE_FRACTION * p.print.clearance_sliding_mm


def pair_clearance_mm(p: Params, a: "Placed", b: "Placed") -> tuple[float, str]:
    """The gap a pair must keep and the name of its source: :func:`cable_clearance_mm` when either is a cable
    (family "cable"), else ``print.clearance_assembly_mm``."""
    if "cable" in (a.family, b.family):
        return cable_clearance_mm(p), "the cable clearance"
    return p.print.clearance_assembly_mm, "print.clearance_assembly_mm"


@dataclass(frozen=True)
class Contact:
    """Two parts that are meant to touch, with the reason.

    ``a``, ``b``: regular expressions matched against the whole labels; a named group present in both
    (``(?P<j>\\d+)``) must capture the same text in both labels (``spool_2`` with ``motor_2``, not ``motor_3``).
    ``link_delta``: if given, link(b) - link(a) must equal it (0: same link; -1: b on the link ahead of a).
    ``near_joint_mm``: if given (parts on neighbouring links), the bounding boxes of both parts at rest must
    come within this distance of the axis of the joint between them (the clevis at the rear of the segment
    ahead, not every piece of that link).
    ``one_body``: the two are pieces of one body (a cable cut at its links' boundaries): where they meet they
    overlap by the body's own shape, so no overlap volume is asked of them. A straight run ending tangent to its
    groove's arc overlaps it along sqrt(4 m r) of arc (moment arm m, cable radius r) whatever the tessellation:
    5 mm^3 on a seeded design whose 35 mm^2 groove piece the tessellation allowance (2 x tolerance x area) held
    to 4.4 mm^3 (2026-11-29). The cable's own shape is checked by its bend radii (cad/cables.py).
    """
    a: str
    b: str
    reason: str
    link_delta: int | None = None
    near_joint_mm: float | None = None   # both parts within this of the axis of the joint between them
    one_body: bool = False

    def matches(self, la: str, lb: str, link_a: int = 0, link_b: int = 0) -> bool:
        for (x, lx), (y, ly) in (((la, link_a), (lb, link_b)), ((lb, link_b), (la, link_a))):
            mx, my = re.fullmatch(self.a, x), re.fullmatch(self.b, y)
            if not (mx and my):
                continue
            shared = set(mx.groupdict()) & set(my.groupdict())
            if any(mx.group(k) != my.group(k) for k in shared):
                continue
            if self.link_delta is not None and ly - lx != self.link_delta:
                continue
            return True
        return False


# Pairs meant to touch (one table, with the reason). Every other pair keeps print.clearance_assembly_mm
# everywhere in the range of motion; these may touch but not interpenetrate (check 2 of the module docstring).
CONTACTS: tuple[Contact, ...] = (
    Contact(r"hull_.+", r"hull_.+", "pieces of one hull segment (upper/lower halves, front/rear lengths) are "
            "screwed together face to face", link_delta=0),
    Contact(r"seam_gasket(_\d+)?", r"hull_.+", "the seam gasket lies compressed between the sealed pieces' upper and "
            "lower halves, on the limiters round the seam screws (cad/seal.py)", link_delta=0),
    Contact(r"joint_link_\d+", r"hull_.+", "a joint link is bolted to the front bulkhead of its own (child) "
            "segment (cad/link.py)", link_delta=0),
    Contact(r"joint_link_\d+", r"hull_.+", "a joint link turns in the clevis of the segment ahead: lugs and "
            "pins with print.clearance_sliding_mm, checked over the joint's range", link_delta=-1,
            near_joint_mm=25.0),
    Contact(r"caudal_fin", r"hull_peduncle(_.+)?", "the fin's root tang slides into the peduncle's slot "
            "(sliding fit, cross screws) (cad/fin.py)", link_delta=0),
    Contact(r"spool_(?P<j>\d+)", r"motor_(?P<j>\d+)", "a spool sits on its motor's shaft (bore = shaft + sliding "
            "clearance, set screw on the flat)"),
    Contact(r"motor_mount_(?P<j>\d+)", r"motor_(?P<j>\d+)", "a motor's face is screwed to its mount plate, the "
            "pilot boss in the plate's hole (cad/mount.py)"),
    Contact(r"motor_mount_\d+", r"hull_.+", "mount tabs are screwed to the hull wall at "
            "swiftfin.layout.mount_plan.mount_fixings_mm", link_delta=0),
    Contact(r"guide_exit_(?P<j>\d+)", r"motor_mount_(?P<j>\d+)", "an exit guide is screwed onto posts of its "
            "motor's mount (cad/guide.py)"),
    Contact(r"guide_bay", r"motor_mount_1", "the bay guide is screwed onto posts at the aft edge of motor_mount_1 "
            "(cad/guide.py)"),
    Contact(r"flotation_\d+", r"hull_.+", "a flotation foam block is glued into the lower "
            "half of its flooded segment where its sides meet the shell (layout/flotation_plan.py)", link_delta=0),
    Contact(r"trim_ballast|ballast_dam(_fore|_aft)?", r"hull_.+", "the trim ballast (lead shot set in epoxy) is "
            "poured into the hull's hollow against the shell and its printed dams, which the epoxy bonds there "
            "(cad/ballast.py)", link_delta=0),
    Contact(r"trim_ballast", r"ballast_dam(_fore|_aft)?", "the trim ballast is poured against its dams "
            "(cad/ballast.py)", link_delta=0),
    Contact(r"cradle_.+", r"hull_.+", "a component's cradle is bonded with epoxy into the hull's lower half along "
            "its underside (cad/cradle.py)", link_delta=0),
    Contact(r"cradle_(?P<c>.+)", r"(?P<c>.+)", "a component sits in its cradle's pocket on a hook-and-loop pad, "
            "its walls print.clearance_sliding_mm from its sides (cad/cradle.py)", link_delta=0),
    Contact(r"spool_(?P<j>\d+)_upper", r"spool_(?P<j>\d+)", "the split spool's upper half sits on the lower half "
            "at the cable plane, locked by the index screw (cad/spool.py)"),
    Contact(r"spool_(?P<j>\d+)_upper", r"motor_(?P<j>\d+)", "the spool's upper half turns on its motor's shaft "
            "(round bore, sliding clearance) (cad/spool.py)"),
    # cables and tubes (cad/cables.py); every other pair with a cable keeps cable_clearance_mm
    Contact(r"cable_(?P<j>\d+)_(?P<s>left|right)_.+", r"cable_(?P<j>\d+)_(?P<s>left|right)_.+", "pieces of one "
            "cable meet end to end (on a hinge line, at the sector's tangent point, at the anchor)", link_delta=0,
            one_body=True),
    Contact(r"cable_(?P<j>\d+)_(?P<s>left|right)_.+", r"cable_(?P<j>\d+)_(?P<s>left|right)_.+", "pieces of one "
            "cable meet on the hinge line of the joint between their links", link_delta=1, one_body=True),
    Contact(r"cable_(?P<j>\d+)_(left|right)_0", r"spool_(?P<j>\d+)(_upper)?", "a cable leaves its own spool's "
            "groove tangent to the drum", link_delta=0),
    Contact(r"cable_(?P<j>\d+)_(left|right)_\d+_(groove|anchor)", r"joint_link_(?P<j>\d+)", "a cable lies in its "
            "own tendon sector's groove and anchor hole", link_delta=0),
    Contact(r"cable_(?P<j>\d+)_(left|right)_\d+", r"joint_link_(?P<j>\d+)", "a cable leaves its own tendon "
            "sector's groove tangent to it (the straight run on the link ahead)", link_delta=1),
    Contact(r"cable_(?P<j>\d+)_(?P<s>left|right)_\d+(_\w+)?", r"tube_.+_(?P<j>\d+)_(?P<s>left|right)(_[a-z])?",
            "a cable runs in its own PTFE tube (at a bend it rides on the bore's inner side)", link_delta=0),
    Contact(r"tube_(?P<h>guide_(exit_\d+|bay))_\d+_(left|right)(_[a-z])?", r"(?P<h>guide_(exit_\d+|bay))",
            "a PTFE tube sits in its guide channel (channel = tube OD + sliding clearance)", link_delta=0),
    Contact(r"tube_(?P<h>hull_[a-z0-9_]+?)_\d+_(left|right)(_[a-z])?", r"(?P<h>hull_[a-z0-9_]+?)(_upper|_lower)?",
            "a PTFE tube sits in its bulkhead hole (hole = tube OD + 2 sliding clearance)", link_delta=0),
    Contact(r"tube_hull_[a-z0-9_]+?_\d+_(left|right)(_[a-z])?", r"joint_link_\d+", "a tube's end meets the flange of "
            "the link bolted on its bulkhead, whose pass-through hole continues the bulkhead's", link_delta=0),
)


@dataclass
class Placed:
    """A part of the assembly: its rest mesh in the body frame (mm) and the link that carries it."""
    label: str
    link: int
    family: str
    vertices: np.ndarray
    faces: np.ndarray
    _manifold: object = field(default=None, repr=False)
    _digest: str | None = field(default=None, repr=False)
    _bounds: tuple | None = field(default=None, repr=False)

    @property
    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """(min corner, max corner) of the mesh's bounding box, computed once."""
        if self._bounds is None:
            self._bounds = (self.vertices.min(axis=0), self.vertices.max(axis=0))
        return self._bounds

    @property
    def manifold(self):
        if self._manifold is None:
            import manifold3d as m3d
            mesh = m3d.Mesh(vert_properties=np.asarray(self.vertices, dtype=np.float32),
                            tri_verts=np.asarray(self.faces, dtype=np.uint32))
            man = m3d.Manifold(mesh)
            if man.status() != m3d.Error.NoError:
                raise BuildError(f"{self.label}: its mesh is not a closed manifold ({man.status()}); "
                                 f"cannot check the assembly")
            self._manifold = man
        return self._manifold

    @property
    def digest(self) -> str:
        """SHA-256 of the mesh and the link: two parts with the same digests get the same check result."""
        if self._digest is None:
            h = hashlib.sha256(f"{self.link}:{self.family}:".encode())
            h.update(np.ascontiguousarray(self.vertices, dtype=np.float64).tobytes())
            h.update(np.ascontiguousarray(self.faces, dtype=np.int64).tobytes())
            self._digest = h.hexdigest()
        return self._digest


# --------------------------------------------------------------------------------------------- kinematics
def joint_transform(p: Params, joint: int, angle_rad: float) -> np.ndarray:
    """4x4 motion of joint ``joint`` (1-based) by ``angle_rad`` about its rest axis."""
    s = joint_stations_mm(p)[joint - 1]
    c, si = math.cos(-angle_rad), math.sin(-angle_rad)
    r = np.array([[c, -si, 0, 0], [si, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], dtype=float)
    t, ti = np.eye(4), np.eye(4)
    t[0, 3], ti[0, 3] = -s, s
    return t @ r @ ti


def chain_transform(p: Params, first_joint: int, last_joint: int, angles_rad: dict[int, float]) -> np.ndarray:
    """T_first(theta) ... T_last(theta): the motion of a part behind ``last_joint`` relative to the link
    ahead of ``first_joint``. Joints missing from ``angles_rad`` stay at 0."""
    m = np.eye(4)
    for j in range(first_joint, last_joint + 1):
        m = m @ joint_transform(p, j, angles_rad.get(j, 0.0))
    return m


def link_transform(p: Params, link: int, angles_rad: Iterable[float]) -> np.ndarray:
    """Body-frame pose of link ``link`` for the joint angles (one per joint, radians)."""
    return chain_transform(p, 1, link, dict(enumerate(angles_rad, start=1)))


def _transform_manifold(man, m: np.ndarray):
    return man.transform(np.asarray(m[:3, :4], dtype=np.float64))


# --------------------------------------------------------------------------------------------- helpers
def _axis_distance_mm(p: Params, part: Placed, joint: int) -> float:
    """Horizontal distance from joint ``joint``'s axis to the part's bounding box at rest."""
    x_axis = -joint_stations_mm(p)[joint - 1]
    lo, hi = part.bounds
    dx = max(0.0, lo[0] - x_axis, x_axis - hi[0])
    dy = max(0.0, lo[1], -hi[1])
    return math.hypot(dx, dy)


@functools.lru_cache(maxsize=1 << 15)
def _matching_contacts(contacts: tuple[Contact, ...], la: str, lb: str, link_a: int, link_b: int
                       ) -> tuple[Contact, ...]:
    """The contacts whose labels and links match the pair, in order: remembered per pair (a whole build asks for
    ~6 000 pairs of parts, cable and tube pieces, 0.7 s of regular expressions each time before)."""
    return tuple(c for c in contacts if c.matches(la, lb, link_a, link_b))


def contact_reason(a: Placed, b: Placed, contacts: Iterable[Contact] = CONTACTS, p: Params | None = None
                   ) -> str | None:
    for c in _matching_contacts(tuple(contacts), a.label, b.label, int(a.link), int(b.link)):
        if c.near_joint_mm is not None:
            joint = max(a.link, b.link)
            if p is None or abs(a.link - b.link) != 1 or any(
                    _axis_distance_mm(p, q, joint) > c.near_joint_mm for q in (a, b)):
                continue
        return c.reason
    return None


def _aabb_gap(lo1, hi1, lo2, hi2) -> float:
    d = np.maximum(0.0, np.maximum(lo1 - hi2, lo2 - hi1))
    return float(np.linalg.norm(d))


def _axis_distance_bounds(p: Params, part: Placed, first: int, last: int) -> dict[int, float]:
    """D_j for j = first..last: bound on the horizontal distance of the part's points from joint j's axis,
    whatever the joints behind j (up to ``last``) do."""
    st = joint_stations_mm(p)
    v = part.vertices
    out: dict[int, float] = {}
    d_next = None
    for j in range(last, first - 1, -1):
        xa = -st[j - 1]
        rest = float(np.max(np.hypot(v[:, 0] - xa, v[:, 1])))
        d = rest if d_next is None else max(rest, d_next + abs(st[j] - st[j - 1]))
        out[j] = d
        d_next = d
    return out


def _fmt_angles(angles: dict[int, float]) -> str:
    if not angles:
        return "at rest"
    return "at " + ", ".join(f"joint {j} = {math.degrees(a):+.1f} deg" for j, a in sorted(angles.items()))


@dataclass(frozen=True)
class Clash:
    a: str
    b: str
    angles_rad: dict
    kind: str            # "clearance", "interference", "outside hull"
    value_mm: float      # gap (clearance), overlap volume mm^3 (interference), distance outside (hull)
    limit: float
    where_mm: tuple | None = None   # (x, y, z) or, for an overlap, (x, y, z, dx, dy, dz, volume_mm3)
    limit_name: str = "print.clearance_assembly_mm"

    def __str__(self) -> str:
        at = _fmt_angles(self.angles_rad)
        loc = ""
        if self.where_mm is not None:
            loc = " near (" + ", ".join(f"{c:.1f}" for c in self.where_mm[:3]) + ") mm"
            if len(self.where_mm) >= 6:
                loc += " over " + " x ".join(f"{c:.1f}" for c in self.where_mm[3:6]) + " mm"
        if self.kind == "clearance" and self.where_mm is not None and len(self.where_mm) == 7 \
                and self.where_mm[6] > 1e-3:
            return (f"{self.a} and {self.b} interfere {at}: overlap {self.where_mm[6]:.1f} mm^3{loc}")
        if self.kind == "clearance" and self.value_mm == 0.0:
            return (f"{self.a} and {self.b} touch {at} (gap 0, no measurable overlap; they need "
                    f"{self.limit_name} {self.limit:g} mm or a declared contact){loc}")
        if self.kind == "clearance":
            return (f"{self.a} and {self.b}: gap {self.value_mm:.3f} mm < {self.limit_name} "
                    f"{self.limit:g} mm {at}{loc}")
        if self.kind == "interference":
            return (f"{self.a} and {self.b} interfere {at}: overlap {self.value_mm:.3f} mm^3 (allowed "
                    f"{self.limit:.3f} mm^3 of tessellation){loc}")
        return f"{self.a} lies outside the hull's inner surface by {self.value_mm:.3f} mm{loc}"


# --------------------------------------------------------------------------------------------- checks
def _pair_clearance(p: Params, A: Placed, B: Placed, need: float, boxes_budget: int = MAX_BOXES_PER_PAIR,
                    limit_name: str = "print.clearance_assembly_mm") -> Clash | None:
    """Branch and bound over the joints between A and B (A on the link ahead). None if clear."""
    if A.link > B.link:
        A, B = B, A
    joints = list(range(A.link + 1, B.link + 1))
    stops = joint_stop_angles_rad(p)
    a_lo, a_hi = A.bounds
    if not joints:
        b_lo, b_hi = B.bounds
        if _aabb_gap(a_lo, a_hi, b_lo, b_hi) >= need:
            return None
        g = A.manifold.min_gap(B.manifold, need)
        return None if g >= need else Clash(A.label, B.label, {}, "clearance", g, need, _near(A, B, {}, p),
                                            limit_name)
    D = _axis_distance_bounds(p, B, joints[0], joints[-1])
    b_lo, b_hi = B.bounds
    corners = np.array([[x, y, z] for x in (b_lo[0], b_hi[0]) for y in (b_lo[1], b_hi[1]) for z in (b_lo[2], b_hi[2])])
    stack = [tuple((-stops[j - 1], stops[j - 1]) for j in joints)]
    n_boxes = 0
    while stack:
        box = stack.pop()
        n_boxes += 1
        if n_boxes > boxes_budget:
            raise BuildError(f"assembly check of {A.label} and {B.label} did not converge in {boxes_budget} "
                             f"boxes of joint angles (parts nearly touching over a wide range?)")
        centre = {j: (lo + hi) / 2 for j, (lo, hi) in zip(joints, box)}
        half = {j: (hi - lo) / 2 for j, (lo, hi) in zip(joints, box)}
        delta = sum(D[j] * half[j] for j in joints)
        m = chain_transform(p, joints[0], joints[-1], centre)
        cb = corners @ m[:3, :3].T + m[:3, 3]   # B's box moved: holds B, so a gap from it is a lower bound
        if _aabb_gap(a_lo, a_hi, cb.min(axis=0), cb.max(axis=0)) >= need + delta:
            continue
        vb = B.vertices @ m[:3, :3].T + m[:3, 3]
        if _aabb_gap(a_lo, a_hi, vb.min(axis=0), vb.max(axis=0)) >= need + delta:
            continue
        if delta > EXACT_BELOW_MM:
            g = None   # an exact gap over a wide search is slow (every triangle pair is a candidate): split
        else:
            g = A.manifold.min_gap(_transform_manifold(B.manifold, m), need + delta)
            if g >= need + delta:
                continue
        if g is not None and g < need:
            return Clash(A.label, B.label, centre, "clearance", g, need, _near(A, B, centre, p), limit_name)
        if g is not None and delta <= RESOLUTION_MM:
            continue  # gap >= need at the centre and nothing moves more than the resolution in the box
        k = max(joints, key=lambda j: D[j] * half[j])
        i = joints.index(k)
        lo, hi = box[i]
        mid = (lo + hi) / 2
        left = box[:i] + ((lo, mid),) + box[i + 1:]
        right = box[:i] + ((mid, hi),) + box[i + 1:]
        stack += [left, right]
    return None


def _near(A: Placed, B: Placed, angles: dict, p: Params) -> tuple | None:
    """A point of the overlap (or of the closest approach) for the message: the centre of A ∩ B, or of the
    vertices of B nearest to A's bounding box."""
    try:
        if angles:
            joints = sorted(angles)
            m = chain_transform(p, joints[0], joints[-1], angles)
        else:
            m = np.eye(4)
        inter = A.manifold ^ _transform_manifold(B.manifold, m)
        if inter.volume() > 0:
            bb = inter.bounding_box()
            lo, hi = bb[:3], bb[3:]
            return (tuple(float((a + b) / 2) for a, b in zip(lo, hi))
                    + tuple(float(b - a) for a, b in zip(lo, hi)) + (float(inter.volume()),))
        vb = B.vertices @ m[:3, :3].T + m[:3, 3]
        lo, hi = A.vertices.min(axis=0), A.vertices.max(axis=0)
        d = np.linalg.norm(np.maximum(0, np.maximum(lo - vb, vb - hi)), axis=1)
        return tuple(float(c) for c in vb[int(np.argmin(d))])
    except Exception:  # the location is decoration of the message; never hide the clash itself
        return None


def _pair_contact(p: Params, A: Placed, B: Placed, tol_mm: float, step_mm: float) -> Clash | None:
    """Touching allowed, interpenetration not: overlap volume <= 2 tol x smaller area at every sample."""
    if A.link > B.link:
        A, B = B, A
    joints = list(range(A.link + 1, B.link + 1))
    area = min(A.manifold.surface_area(), B.manifold.surface_area())
    allowed = 2.0 * tol_mm * area
    stops = joint_stop_angles_rad(p)
    if joints:
        D = _axis_distance_bounds(p, B, joints[0], joints[-1])
        grids = []
        for j in joints:
            n = max(2, math.ceil(2 * stops[j - 1] * D[j] / step_mm))
            grids.append(np.linspace(-stops[j - 1], stops[j - 1], n + 1))
        configs = [dict(zip(joints, c)) for c in _product(grids)]
    else:
        configs = [{}]
    for angles in configs:
        m = chain_transform(p, joints[0], joints[-1], angles) if joints else np.eye(4)
        vol = (A.manifold ^ _transform_manifold(B.manifold, m)).volume()
        if vol > allowed:
            return Clash(A.label, B.label, angles, "interference", vol, allowed, _near(A, B, angles, p))
    return None


def _product(grids):
    import itertools
    return list(itertools.product(*grids))


INTERNAL_EXCLUDED_FAMILIES = ("hull", "fin", "seal")
"""Families that are the hull's skin or stand out of it (the seam gasket lies in the wall, between the halves)."""


_SOURCE_DIGEST = hashlib.sha256(Path(__file__).read_bytes()).digest()


def _pair_key(p: Params, A: Placed, B: Placed, reason: str | None) -> str:
    """Everything a pair's result depends on: both meshes and links, the joint axes and stops, the limits,
    whether the pair is a declared contact, and this module's source."""
    h = hashlib.sha256(_SOURCE_DIGEST)
    h.update(json.dumps([sorted([A.digest, B.digest]), A.link, B.link, reason is not None,
                         list(joint_stations_mm(p)), list(joint_stop_angles_rad(p)),
                         p.print.clearance_assembly_mm, p.print.clearance_sliding_mm,
                         p.export.mesh_tolerance_mm, RESOLUTION_MM, EXACT_BELOW_MM]).encode())
    return h.hexdigest()


class PassedPairs:
    """Memo of pairs that passed (a folder of empty files named by :func:`_pair_key`), so that a rebuild
    re-checks only the pairs in which a part changed. Failures are never stored: they are re-checked."""

    def __init__(self, folder: str | Path):
        self.folder = Path(folder)

    def __contains__(self, key: str) -> bool:
        return (self.folder / key[:2] / key).exists()

    def add(self, key: str) -> None:
        d = self.folder / key[:2]
        d.mkdir(parents=True, exist_ok=True)
        (d / key).touch()


def check_assembly(p: Params, parts: list[Placed], contacts: Iterable[Contact] = CONTACTS,
                   progress=None, inside_hull: bool = True, passed: PassedPairs | None = None,
                   focus: Iterable[str] | None = None) -> dict:
    """Run every check; raise BuildError listing every failure. Returns counts for the build summary.

    ``inside_hull=False`` skips check 3 (for parts checked against one another only); ``passed`` is a memo
    of pairs already known to pass (swiftfin/cache.py keeps one per cache folder); ``focus`` (labels), if given,
    limits the checks to the pairs with at least one of these parts, and check 3 to them (e.g. the cables and
    tubes of :func:`swiftfin.cad.cables.cable_parts` against parts already checked among themselves)."""
    contacts = tuple(contacts)
    tol = p.export.mesh_tolerance_mm
    failures: list[Clash] = []
    stats = {"pairs": 0, "contact_pairs": 0, "inside_checked": 0, "pairs_remembered": 0}
    focus = None if focus is None else set(focus)
    for part in parts:
        if not inside_hull or part.family in INTERNAL_EXCLUDED_FAMILIES:
            continue
        if focus is not None and part.label not in focus:
            continue
        stats["inside_checked"] += 1
        ex = inner_envelope_excess_mm(p, part.vertices)
        i = int(np.argmax(ex))
        if ex[i] > 2 * tol:
            failures.append(Clash(part.label, "hull", {}, "outside hull", float(ex[i]), 2 * tol,
                                  tuple(float(c) for c in part.vertices[i])))
    for i, A in enumerate(parts):
        for B in parts[i + 1:]:
            if focus is not None and A.label not in focus and B.label not in focus:
                continue
            reason = contact_reason(A, B, contacts, p)
            stats["pairs" if reason is None else "contact_pairs"] += 1
            key = _pair_key(p, A, B, reason) if passed is not None else None
            if key is not None and key in passed:
                stats["pairs_remembered"] += 1
                continue
            if reason is None:
                need, name = pair_clearance_mm(p, A, B)
                clash = _pair_clearance(p, A, B, need, limit_name=name)
            elif any(c.one_body for c in _matching_contacts(contacts, A.label, B.label, int(A.link), int(B.link))):
                clash = None      # pieces of one cable: their overlap where they meet is the cable itself
            else:
                clash = _pair_contact(p, A, B, tol, p.print.clearance_sliding_mm)
            if clash is None and key is not None:
                passed.add(key)
            if clash is not None:
                failures.append(clash)
                if progress:
                    progress(f"assembly check: {clash}")
    if failures:
        raise BuildError(f"{len(failures)} assembly check(s) failed:\n" + "\n".join(f"  - {c}" for c in failures))
    return stats


# --------------------------------------------------------------------------------------------- the assembly
def make_assembly(specs, label: str = "swiftfin_assembly"):
    """One build123d Compound of every part at rest in the body frame; children carry the part labels."""
    from swiftfin.cad.kernel import bd

    children = []
    for s in specs:
        c = s.solid.moved(bd.Location())
        c.label = s.label
        children.append(c)
    return bd.Compound(children=children, label=label)
