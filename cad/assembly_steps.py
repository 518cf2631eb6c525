"""Assembly steps: the order a builder puts the fish together, each step's parts, the direction each goes in along,
its fasteners, and the proof that every part reaches its place along that direction without passing through a
part already placed (issue 12, item 8).

**Planning, by taking the fish apart.** A part can be the last one put in when it can be taken out of the finished
assembly: :func:`plan_steps` removes parts one at a time from the whole fish and reverses the order. In each round
it tries the parts still in place in the order of :data:`REMOVAL` (the lid first, the tail last: the order the
fastener plans already assume, below), each along its family's preferred directions and then along the six axes
of the body frame, and removes the first that comes free. A part comes free along ``u`` when

* it has no fastener still holding it that must be driven before a part still in place goes on: a fastener's
  ``installed_after`` lists the parts put on after it is driven (its key passes where they go, see
  :mod:`swiftfin.cad.fastener_check`), so those parts come off first;
* its path, translated along ``u`` from where it sits until its bounding box clears every part still in place,
  passes through none of them (:func:`path_blocker`).

A part glued into another (a flotation block into its lower half, ``meta["glued_to"]``) moves with its host.
Fasteners are not solids here: a screw comes out along its axis through its own hole, and its driver's path is
proved free of every part but those put on after it (:mod:`swiftfin.cad.fastener_check`, on the whole assembly,
which is the strictest moment). The cables and PTFE tubes are threaded, not pushed in rigid: they get their own
steps (:func:`_with_threading`), from the tail forward, each before the hull piece that covers them closes.

**The path check** (exact on the meshes, manifold3d). For a pair that must keep a gap (not a declared contact of
:data:`swiftfin.cad.assembly.CONTACTS`) the moving part advances by the gap it has (conservative advancement: a
translation by ``g`` cannot close a gap of ``g``), so the path is proved clear, not sampled; the pair blocks when
the gap falls below :data:`MIN_PASSING_GAP_MM`. A declared contact (a spool on its shaft, a tang in its slot,
halves face to face) may touch while it slides; it is sampled every ``print.clearance_sliding_mm`` of travel and
blocks where the two overlap by more than the tessellation of two touching surfaces can make
(``2 x export.mesh_tolerance_mm x the smaller surface area``, as the assembly check's contacts); its booleans run on
the two parts cut down to where they can meet on the way (exact: nothing outside the cut enters the other's box).
A direction's pairs are proved cheapest first (the gap proofs, then the contacts by triangles times samples), so a
direction blocked by a part passed too close is given up before any long contact slide is sampled on it: the
default design's plan, 84 s -> 28 s from an empty memo, the same steps and notes.

Each step is then drawn exploded (:mod:`swiftfin.report`): what is already in place, and the step's parts set back
along their direction by :func:`explode_distance_mm`.
"""
from __future__ import annotations

import hashlib
import json
import math
import os
import re
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from swiftfin.cad import assembly as _assembly
from swiftfin.cad.assembly import CONTACTS, Contact, Placed, contact_reason
from swiftfin.core.errors import BuildError
from swiftfin.core.schema import Params

AXES: dict[str, tuple[float, float, float]] = {
    "+z": (0.0, 0.0, 1.0), "-z": (0.0, 0.0, -1.0), "+y": (0.0, 1.0, 0.0), "-y": (0.0, -1.0, 0.0),
    "+x": (1.0, 0.0, 0.0), "-x": (-1.0, 0.0, 0.0)}
"""Directions a part may be taken out along (body frame: +x forward, +y left, +z up)."""

MIN_PASSING_GAP_MM = 0.05
"""A part passing a part it is not meant to touch keeps at least this gap on its way in [mm] (a printed surface's
scatter is larger; below this the builder scrapes it past)."""

CLEAR_MARGIN_MM = 2.0
"""A part is out when its bounding box clears every part still in place by this much along its direction [mm]."""

# (label pattern, removal directions tried first, what the builder does when putting these parts in). Parts are
# taken out in this order (the first pattern first), so they go in in the reverse order. Matches the order the
# fastener plans assume: the tail from the peduncle forward, then the drive in the head's lower halves, the cables,
# and the head's upper halves (the lid) last (swiftfin.layout.hull_plan.head_lid_labels).
REMOVAL: tuple[tuple[str, tuple[str, ...], str], ...] = (
    (r"caudal_fin", ("-x",), "Slide the caudal fin's tang into the peduncle's slot and drive its root screws"),
    (r"hull_head_.+_upper", ("+z",), "Close the head with its upper halves; drive the wall screws into the "
     "motor mounts from outside"),
    (r"trim_ballast|ballast_dam(_fore|_aft)?", ("+z", "-z"), "On the bench, with the half that takes it on its "
     "back: bond the ballast dam in with epoxy, pour the weighed lead shot ahead of it and fill with epoxy to the "
     "level (bill of materials; cad/ballast.py); let it cure before the half goes on"),
    (r"seam_gasket(_\d+)?", ("+z",), "Lay the seam gasket on the head's lower halves, a compression limiter in each of "
     "its holes round the seam screws (cad/seal.py)"),
    (r"battery|electronics", ("+z", "+y", "-y"), "Seat the battery and the electronics"),
    (r"guide_.+", ("+z", "+y", "-y"), "Screw the PTFE guides onto their posts"),
    (r"spool_\d+_upper", ("+z",), "Set the split spools' upper halves and lock them with the index screws"),
    (r"spool_\d+", ("+z",), "Slide the spools onto the motor shafts and tighten the set screws on the flats"),
    (r"motor_mount_\d+", ("+z",), "Set the motor units (each motor screwed to its mount's plate on the bench) "
     "into the head's lower halves"),
    (r"cradle_.+", ("+z",), "Bond the components' cradles into the head's lower halves with epoxy (cad/cradle.py)"),
    (r"hull_head_.+", ("-z", "+z"), "Lay out the head's lower halves and join their splices"),
    (r"joint_link_\d+", ("+z", "+x", "-x"), "Round the edges of the joint link's pass-through holes on its hinge "
     "line with a deburring tool, as far as the link allows (the cables of the joints behind turn round them: "
     "rule physics.hinge_bend); fit it into the clevis ahead, press in the hinge pins and drive the plugs; bolt the "
     "link's flange to its segment's front bulkhead"),
    (r"hull_.+_upper", ("+z",), "Close the segment with its upper half"),
    (r"hull_.+", ("-z", "+z", "-x", "+x"), "Lay out the segment's lower half"),
    (r".+", (), "Fit"),
)

BENCH: tuple[tuple[str, str], ...] = (
    (r"motor_(?P<j>\d+)", r"motor_mount_(?P<j>\d+)"),
)
"""Bench sub-assemblies: (guest, host) label patterns; a named group must capture the same text in both. The guest
is fastened to its host on the bench and goes into the fish with it (a motor screwed to its mount: the mount's
plate is over the motor, so the motor alone could only go in first and hang there)."""

LEADS_TEXT = ("Lay the leads (cut lengths in the bill of materials; layout/harness_plan.py): each motor's up its flank "
              "from the strain relief and forward along it to the electronics' side, the battery snap's forward under "
              "the front motor and up beside the electronics' cradle; crimp their housings on, plug them in and lace "
              "each side's leads together. ")
WIND_TEXT = ("Seat the guides' PTFE tubes, lead every cable through them onto its split spool (lower half: the right "
             "cable, upper half: the left), crimp the ends in their seats and set the pretension with the vernier "
             "(steps in the tensioner table)")


@dataclass(frozen=True)
class Blocked:
    """Why a part cannot travel along a direction: the first part in its way, where, and by how much."""
    part: str
    direction: str
    blocker: str
    travel_mm: float          # how far it got
    measure_mm: float         # the gap left (a pair that keeps a gap) or the overlap volume (mm^3, a contact)
    contact: bool

    def __str__(self) -> str:
        what = (f"overlaps it by {self.measure_mm:.2f} mm^3" if self.contact else
                f"passes {self.measure_mm:.3f} mm from it (needs {MIN_PASSING_GAP_MM:g} mm)")
        return f"{self.part} along {self.direction}: after {self.travel_mm:.1f} mm {what} ({self.blocker})"


@dataclass(frozen=True)
class Step:
    """One assembly step: parts that go in together along one direction, and the fasteners driven then."""
    number: int
    text: str
    parts: tuple[str, ...]
    direction: str             # insertion direction, a key of AXES ("" for threading)
    travel_mm: tuple[float, ...]   # per part: the path proved clear, from outside everything placed to its seat
    fasteners: tuple[str, ...] = ()
    threads: tuple[str, ...] = ()  # cables and tubes threaded, leads laid, in this step
    explode_mm: float = 0.0        # how far the exploded view sets the parts back (explode_distance_mm)

    @property
    def vector(self) -> np.ndarray:
        """Unit vector the step's parts travel along into place (zero for threading)."""
        return np.asarray(AXES[self.direction], float) if self.direction else np.zeros(3)


@dataclass
class Plan:
    steps: list[Step]
    checked_paths: int = 0           # part paths proved clear
    pair_checks: int = 0             # part pairs whose path was proved (gap or contact)
    pairs_remembered: int = 0        # of them, found in the PathMemo: proved earlier in this plan (a part tried
                                     # again in a later round) or by an earlier build
    tried: int = 0                   # directions tried in all
    fastener_count: int = 0
    notes: list[str] = field(default_factory=list)

    def order(self) -> list[str]:
        return [q for s in self.steps for q in s.parts]


def _opposite(d: str) -> str:
    return ("-" if d[0] == "+" else "+") + d[1]


def _travel_out_mm(lo: np.ndarray, hi: np.ndarray, u: np.ndarray, lo_all: np.ndarray, hi_all: np.ndarray) -> float:
    """Translation along the axis ``u`` that takes the box [lo, hi] clear of [lo_all, hi_all] by CLEAR_MARGIN_MM."""
    k = int(np.argmax(np.abs(u)))
    if u[k] > 0:
        return max(0.0, hi_all[k] - lo[k]) + CLEAR_MARGIN_MM
    return max(0.0, hi[k] - lo_all[k]) + CLEAR_MARGIN_MM


def _window(lo, hi, u, qlo, qhi, margin: float) -> tuple[float, float] | None:
    """Travel interval [t0, t1] (t >= 0) in which the box [lo, hi] moved by t u comes within ``margin`` of
    [qlo, qhi]; None when it never does."""
    t0, t1 = 0.0, math.inf
    for k in range(3):
        a0, a1 = lo[k] - margin, hi[k] + margin
        if abs(u[k]) < 1e-12:
            if a1 < qlo[k] or a0 > qhi[k]:
                return None
            continue
        # a0 + t u <= qhi and a1 + t u >= qlo
        ta, tb = (qlo[k] - a1) / u[k], (qhi[k] - a0) / u[k]
        if ta > tb:
            ta, tb = tb, ta
        t0, t1 = max(t0, ta), min(t1, tb)
        if t0 > t1:
            return None
    return t0, t1


SEARCH_MM = (0.5, 8.0)
"""The gap query's search radius in the conservative advancement [mm]: twice the last gap, within these bounds.
A query costs by the triangle pairs closer than its radius (a guide 0.5 mm inside the head's skin: 0.25 s at 5 mm,
5 ms at 0.6 mm), and a step can never be longer than the gap, so a radius past twice the gap only costs."""


def _swept_box(lo: np.ndarray, hi: np.ndarray, u: np.ndarray, t0: float, t1: float, margin: float):
    """The box [lo, hi] swept along ``u`` from ``t0`` to ``t1``, grown by ``margin`` on every side: a manifold3d
    cube."""
    import manifold3d as m3d

    a = lo + np.minimum(t0 * u, t1 * u) - margin
    b = hi + np.maximum(t0 * u, t1 * u) + margin
    return m3d.Manifold.cube(tuple(float(c) for c in b - a)).translate(tuple(float(c) for c in a))


CLIP_MARGIN_MM = 1.0
"""How far outside the region two parts can meet in a sweep the clipping box of :func:`_pair_path` cuts [mm]: its
cut faces never touch the other part, so the overlap it measures is the whole parts' (the margin is 20 times the
default tessellation tolerance)."""


def _pair_path(p: Params, m: Placed, q: Placed, u: np.ndarray, t0: float, t1: float,
               contact: bool) -> tuple[float, float] | None:
    """Where ``m`` moved along ``u`` from ``t0`` to ``t1`` first blocks on ``q``: (travel, the gap left or the overlap
    volume), or None when the way is clear. See the module docstring.

    A declared contact is sampled with booleans on the two parts cut down to where they can meet: ``q`` to ``m``'s
    box swept over the travel, ``m`` to ``q``'s box swept back (grown by :data:`CLIP_MARGIN_MM`). A point of
    ``m`` outside its clip never enters ``q``'s box on the way, nor one of ``q`` outside its clip ``m``'s, so the
    overlap at every sample is the whole parts' (the seam gasket sliding along the head's lower halves: a 4 mm slab
    of the hull instead of the hull, 12 s -> under 1 s)."""
    tol = p.export.mesh_tolerance_mm
    step = p.print.clearance_sliding_mm
    if contact:
        allowed = 2.0 * tol * min(m.manifold.surface_area(), q.manifold.surface_area())
        n = max(1, math.ceil((t1 - t0) / step))
        samples = np.linspace(max(t0, step), max(t1, step), n + 1)
        mm = m.manifold ^ _swept_box(*q.bounds, -u, float(samples[0]), float(samples[-1]), CLIP_MARGIN_MM)
        qq = q.manifold ^ _swept_box(*m.bounds, u, float(samples[0]), float(samples[-1]), CLIP_MARGIN_MM)
        if mm.is_empty() or qq.is_empty():
            return None
        for t in samples:
            vol = (mm.translate(tuple(float(c) for c in t * u)) ^ qq).volume()
            if vol > allowed:
                return float(t), float(vol)
        return None
    t = t0
    search = SEARCH_MM[0]
    while t <= t1:
        g = m.manifold.translate(tuple(float(c) for c in t * u)).min_gap(q.manifold, search)
        if g < MIN_PASSING_GAP_MM:
            return float(t), float(g)
        t += g - MIN_PASSING_GAP_MM / 2 if g < search else search - MIN_PASSING_GAP_MM / 2
        search = min(SEARCH_MM[1], max(SEARCH_MM[0], 2.0 * g))
    return None


_SOURCE_DIGEST = hashlib.sha256(Path(__file__).read_bytes() + _assembly._SOURCE_DIGEST).digest()


def _path_key(p: Params, m: Placed, q: Placed, direction: str, contact: bool) -> str:
    """Everything one pair's way-in result depends on: both meshes (the moving part's first), the direction, whether
    the pair is a declared contact, the tolerances, and the source of this module and of cad/assembly.py. The
    travel window is the two meshes' bounds along the direction, so the digests cover it."""
    h = hashlib.sha256(_SOURCE_DIGEST)
    h.update(json.dumps([m.digest, q.digest, direction, contact, p.export.mesh_tolerance_mm,
                         p.print.clearance_sliding_mm, MIN_PASSING_GAP_MM]).encode())
    return h.hexdigest()


MISSING = object()
"""What :meth:`PathMemo.get` returns for a pair it has not stored (None is a stored clear way)."""


class PathMemo:
    """Memo of each pair's way-in result (a folder of small JSON files named by :func:`_path_key`: ``null`` for a
    clear way, ``[travel, measure]`` for a block), so that a rebuild proves again only the ways in where one of the
    two parts changed (a fin-span change: the fin's). Each file is written whole and renamed into place, so
    builds sharing a cache never read half a result."""

    def __init__(self, folder: str | Path):
        self.folder = Path(folder)
        self.hits = 0

    def get(self, key: str):
        """The stored result, or :data:`MISSING`."""
        try:
            value = json.loads((self.folder / key[:2] / key).read_text())
        except (OSError, ValueError):
            return MISSING
        self.hits += 1
        return None if value is None else (float(value[0]), float(value[1]))

    def put(self, key: str, value: tuple[float, float] | None) -> None:
        d = self.folder / key[:2]
        d.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=d, prefix=".tmp-")
        with os.fdopen(fd, "w") as fh:
            json.dump(None if value is None else list(value), fh)
        os.replace(tmp, d / key)


class _RoundMemo(PathMemo):
    """A :class:`PathMemo` in memory, for one planning."""

    def __init__(self):
        self.hits = 0
        self.stored: dict[str, tuple[float, float] | None] = {}

    def get(self, key: str):
        if key not in self.stored:
            return MISSING
        self.hits += 1
        return self.stored[key]

    def put(self, key: str, value: tuple[float, float] | None) -> None:
        self.stored[key] = value


def path_blocker(p: Params, moving: list[Placed], direction: str, still: list[Placed],
                 contacts: tuple[Contact, ...] = CONTACTS, memo: PathMemo | None = None
                 ) -> tuple[Blocked | None, float, int]:
    """Take ``moving`` (parts that move together) out along ``direction`` past ``still``: (the first block, or None;
    the travel to clear everything; the pairs proved, remembered ones included). See the module docstring.
    ``memo`` keeps each pair's result across builds (:class:`PathMemo`)."""
    u = np.asarray(AXES[direction], float)
    lo = np.min([m.bounds[0] for m in moving], axis=0)
    hi = np.max([m.bounds[1] for m in moving], axis=0)
    if not still:
        return None, CLEAR_MARGIN_MM, 0
    all_lo = np.min([q.bounds[0] for q in still], axis=0)
    all_hi = np.max([q.bounds[1] for q in still], axis=0)
    travel = _travel_out_mm(lo, hi, u, all_lo, all_hi)
    tol = p.export.mesh_tolerance_mm
    todo = []
    for m in moving:
        mlo, mhi = m.bounds
        for q in still:
            qlo, qhi = q.bounds
            win = _window(mlo, mhi, u, qlo, qhi, MIN_PASSING_GAP_MM + tol)
            if win is None or win[0] > travel:
                continue
            # the window ends where m's box leaves q's by the passing gap: inside the travel, which clears every
            # box by CLEAR_MARGIN_MM, so the result is the pair's own and can be remembered by the two meshes
            t0, t1 = win[0], min(win[1], travel)
            contact = contact_reason(m, q, contacts, p) is not None
            todo.append((_pair_cost(p, m, q, t0, t1, contact), len(todo), m, q, t0, t1, contact, t1 == win[1]))
    # the cheapest proofs first: a direction blocked by a part it passes (a gap proof, milliseconds) is given up
    # before the sampled slides of declared contacts (seconds) are run on it; the order is the meshes' own, so the
    # blocker named is the same with or without a memo
    todo.sort(key=lambda c: c[:2])
    for pairs, (_, _, m, q, t0, t1, contact, whole) in enumerate(todo, 1):
        key = _path_key(p, m, q, direction, contact) if memo is not None and whole else None
        res = memo.get(key) if key is not None else MISSING
        if res is MISSING:
            res = _pair_path(p, m, q, u, t0, t1, contact)
            if key is not None:
                memo.put(key, res)
        if res is not None:
            return Blocked(m.label, direction, q.label, res[0], res[1], contact), travel, pairs
    return None, travel, len(todo)


def _pair_cost(p: Params, m: Placed, q: Placed, t0: float, t1: float, contact: bool) -> tuple[int, float]:
    """A rough order of what :func:`_pair_path` costs on a pair: the gap proofs (few steps) before the sampled
    contacts, each kind by its triangles times its samples."""
    tris = len(m.faces) + len(q.faces)
    if not contact:
        return 0, float(tris)
    return 1, tris * max(1.0, (t1 - t0) / p.print.clearance_sliding_mm)


def bench_hosts(labels: list[str]) -> dict[str, str]:
    """Guest label -> host label of the :data:`BENCH` sub-assemblies among ``labels``."""
    out = {}
    for guest_pat, host_pat in BENCH:
        for g in labels:
            mg = re.fullmatch(guest_pat, g)
            if not mg:
                continue
            for h in labels:
                mh = re.fullmatch(host_pat, h)
                if mh and all(mg.group(k) == mh.group(k) for k in set(mg.groupdict()) & set(mh.groupdict())):
                    out[g] = h
    return out


def _rule(label: str) -> int:
    return next(i for i, (pat, _, _) in enumerate(REMOVAL) if re.fullmatch(pat, label))


def plan_steps(p: Params, parts: list[Placed], fasteners=(), glued: dict[str, str] | None = None,
               threads: bool = True, contacts: tuple[Contact, ...] = CONTACTS, memo: PathMemo | None = None
               ) -> Plan:
    """The assembly steps of ``parts`` (rigid, at rest), with ``fasteners`` (:class:`Fastener` records) assigned
    to the step that places the last of their parts, and (``threads``) the cabling steps of :func:`_with_threading`.
    Raises BuildError when no part still in place can be taken out (naming each one's first blocker). ``memo``
    remembers each pair's way-in result across builds (:class:`PathMemo`)."""
    glued = dict(glued or {})
    by_label = {q.label: q for q in parts}
    glued.update(bench_hosts(list(by_label)))
    unknown = {g for g in glued.values() if g not in by_label}
    if unknown:
        raise BuildError(f"assembly steps: glued into parts that are not built: {sorted(unknown)}")
    guests: dict[str, list[str]] = {}
    for g, host in glued.items():
        guests.setdefault(host, []).append(g)
    units = [q.label for q in parts if q.label not in glued]
    holders: dict[str, list] = {}
    for f in fasteners:
        for q in f.parts:
            holders.setdefault(q, []).append(f)
    present = set(by_label)
    hits0 = memo.hits if memo is not None else 0
    # without a memo across builds, one for this planning: every round tries the parts still in place again, and a
    # pair whose two meshes and direction it has proved need not be proved again (the default design without
    # one: 806 s of ways in, most of them the seam gasket's same slides round after round)
    paths = memo if memo is not None else _RoundMemo()
    removed: list[tuple[str, str, float]] = []
    plan = Plan([])
    while units:
        order = sorted(units, key=lambda lb: (_rule(lb), lb))
        why = []
        for lb in order:
            group = [lb] + guests.get(lb, [])
            waiting = sorted({a for q in group for f in holders.get(q, ()) for a in f.installed_after
                              if a in present and a not in group})
            if waiting:
                why.append(f"{lb}: held until {', '.join(waiting[:3])} come off (fasteners' installed_after)")
                continue
            prefer = REMOVAL[_rule(lb)][1]
            moving = [by_label[q] for q in group]
            still = [q for q in parts if q.label in present and q.label not in group]   # build order: reproducible
            found = None
            mine = []
            for d in list(prefer) + [d for d in AXES if d not in prefer]:
                plan.tried += 1
                blocked, travel, pairs = path_blocker(p, moving, d, still, contacts, paths)
                plan.pair_checks += pairs
                if blocked is None:
                    found = (d, travel)
                    break
                mine.append(str(blocked))
            why += mine
            if found is None:
                continue
            if prefer and found[0] != prefer[0]:
                plan.notes.append(f"{lb} goes in along {_opposite(found[0])}, not {_opposite(prefer[0])}: "
                                  f"{mine[0]}")
            removed.append((lb, found[0], found[1]))
            plan.checked_paths += 1
            present -= set(group)
            units.remove(lb)
            break
        else:
            raise BuildError("assembly steps: no part still in place can be taken out of the assembly along any "
                             "axis, so no order puts it together:\n" + "\n".join(f"  - {w}" for w in why[:30]))
    # reverse: the assembly order; consecutive parts of one rule and direction make one step
    placed_at: dict[str, int] = {}
    steps: list[Step] = []
    for lb, d, travel in reversed(removed):
        ins = _opposite(d)
        group = tuple([lb] + guests.get(lb, []))
        rule = _rule(lb)
        last = steps[-1] if steps else None
        after_a_screw_of_last = last is not None and any(
            set(group) & set(f.installed_after) and f.parts & set(last.parts)
            for f in fasteners)
        if last is not None and last.direction == ins and _rule(last.parts[0]) == rule and not after_a_screw_of_last:
            steps[-1] = Step(last.number, last.text, last.parts + group, ins, last.travel_mm + (travel,) * len(group))
        else:
            steps.append(Step(len(steps) + 1, REMOVAL[rule][2], group, ins, (travel,) * len(group)))
        for q in group:
            placed_at[q] = steps[-1].number
    steps = _with_threading(p, steps, set(by_label)) if threads else steps
    placed_at = {q: s.number for s in steps for q in s.parts}
    driven: dict[int, list[str]] = {}
    for f in fasteners:
        qs = f.parts
        missing = qs - set(placed_at)
        if missing:
            raise BuildError(f"assembly steps: fastener {f.label} joins parts that are not built: {sorted(missing)}")
        at = max(placed_at[q] for q in qs)
        late = [a for a in f.installed_after if a in placed_at and placed_at[a] <= at]
        if late:
            raise BuildError(f"assembly steps: fastener {f.label} is driven in step {at}, after {late[0]} (step "
                             f"{placed_at[late[0]]}) that must go on after it")
        driven.setdefault(at, []).append(f.label)
    plan.steps = [Step(s.number, s.text, s.parts, s.direction, s.travel_mm, tuple(sorted(driven.get(s.number, ()))),
                       s.threads, explode_distance_mm(s, by_label)) for s in steps]
    plan.fastener_count = sum(len(v) for v in driven.values())
    plan.pairs_remembered = memo.hits - hits0 if memo is not None else 0
    return plan


def _with_threading(p: Params, steps: list[Step], built: set[str]) -> list[Step]:
    """The cabling, as a builder does it from the tail forward: before a hull piece closes (the last of its halves
    goes on), the tubes seated in its bulkheads go in, the cables of the joints whose tendon sectors lie in it are
    anchored there (both sides, crimped), and every cable that runs through it is laid in its tubes. Before the
    head's lid, the guides' tubes go in and the cables are wound on the spools and tensioned. Renumbers the steps."""
    from swiftfin.cad.cables import tube_runs
    from swiftfin.layout.harness_plan import harness
    from swiftfin.layout.hull_plan import head_lid_labels, hull_pieces, part_label

    n = p.joints.count
    tubes = tube_runs(p)
    placed_at = {q: s.number for s in steps for q in s.parts}
    inserts: dict[int, list[Step]] = {}
    for pc in hull_pieces(p):
        halves = [lb for lb in {part_label(p, pc, "upper"), part_label(p, pc, "lower")} if lb in built]
        if not halves or pc.link == 0:
            continue
        closes = max(placed_at[lb] for lb in halves)
        anchored = [pc.rear_joint] if pc.rear_joint is not None else []
        through = [j for j in range(pc.link + 1, n + 1) if j not in anchored]
        seated = tuple(t.label for t in tubes if t.kind == "bulkhead" and t.holder == pc.name)
        words = []
        if seated:
            words.append(f"seat the PTFE tubes in {pc.name}'s bulkheads")
        for j in anchored:
            words.append(f"anchor both sides of cable {j} in joint_link_{j}'s tendon sector (crimp seats)")
        if through:
            words.append(f"lay cable{'s' if len(through) > 1 else ''} {', '.join(map(str, through))} forward "
                         f"through its tubes")
        if not words:
            continue
        cables = tuple(f"cable_{j}" for j in anchored + through)
        text = "Before " + pc.name + " closes: " + "; ".join(words)
        inserts.setdefault(closes, []).append(Step(0, text, (), "", (), threads=seated + cables))
    lid = [placed_at[lb] for lb in head_lid_labels(p) if lb in placed_at]
    head = tuple(t.label for t in tubes if t.link == 0) + tuple(f"cable_{j}" for j in range(1, n + 1))
    at = min(lid) if lid else len(steps) + 1
    in_head = sorted(pc.rear_joint for pc in hull_pieces(p) if pc.link == 0 and pc.rear_joint is not None)
    text = "".join(f"Anchor both sides of cable {j} in joint_link_{j}'s tendon sector (crimp seats). "
                   for j in in_head) + WIND_TEXT
    leads = tuple(h.label for h in harness(p)) if "electronics" in built else ()
    if leads:
        text = LEADS_TEXT + text
    inserts.setdefault(at, []).append(Step(0, text, (), "", (), threads=leads + head))
    out: list[Step] = []
    for s in steps:
        out += inserts.pop(s.number, [])
        out.append(s)
    for k in sorted(inserts):
        out += inserts[k]
    return [Step(i + 1, s.text, s.parts, s.direction, s.travel_mm, s.fasteners, s.threads) for i, s in enumerate(out)]


def explode_distance_mm(step: Step, parts: dict[str, Placed]) -> float:
    """How far the exploded view sets the step's parts back: their size along the direction, at most 60 mm."""
    if not step.direction:
        return 0.0
    k = "xyz".index(step.direction[1])
    ext = max(float(np.ptp(parts[q].vertices[:, k])) for q in step.parts)
    return min(60.0, 0.6 * ext + 10.0)


def steps_json(plan: Plan) -> str:
    """The plan as the build's ``assembly_steps.json`` (``swiftfin.report.sections.STEPS_NAME``): every step with its parts, insertion direction (a unit
    vector, body frame), the travel proved clear per part, its fasteners and threads; the counts; the notes."""
    steps = [{"number": s.number, "text": s.text, "parts": list(s.parts), "direction": s.direction,
              "vector": [float(v) for v in s.vector], "travel_mm": [round(t, 2) for t in s.travel_mm],
              "explode_mm": round(s.explode_mm, 1), "fasteners": list(s.fasteners), "threads": list(s.threads)}
             for s in plan.steps]
    return json.dumps({"steps": steps, "paths_proved": plan.checked_paths, "pair_paths": plan.pair_checks,
                       "directions_tried": plan.tried, "fasteners": plan.fastener_count, "notes": plan.notes},
                      indent=1) + "\n"
