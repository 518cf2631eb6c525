"""The validation gate every build passes before anything is written: tensors, sums, COMs, OCC against mesh.

Every part and link inertia tensor is symmetric, positive-definite and obeys the triangle inequality
(:func:`check_tensor`); the link masses add up to the total; every link COM lies inside the skinned hull
envelope and its parts' bounding boxes; and the exact B-rep (OCC) and the exported mesh agree within
:data:`GATE_MESH_REL_TOL` on volume, centroid and inertia (:func:`validate`, issue 3, item 5).
"""
from __future__ import annotations

import math

import numpy as np

from swiftfin.core import units
from swiftfin.core.errors import BuildError
from swiftfin.core.schema import Params
from swiftfin.exports.brep import mesh_volume_props, solid_volume_props
from swiftfin.exports.parallel import memoized
from swiftfin.exports.water import envelope_section_mm
from swiftfin.layout import geometry as layout

GATE_MESH_REL_TOL = 0.01     # OCC vs mesh agreement [-] (issue 3, item 5)


# ----------------------------------------------------------------------------------------------- validation gate
def check_tensor(name: str, I, mass: float) -> None:
    """Symmetric, positive-definite, triangle inequalities on the principal moments; raises BuildError."""
    I = np.asarray(I, dtype=float)
    scale = max(np.abs(I).max(), 1e-300)
    if not np.all(np.isfinite(I)) or not math.isfinite(mass) or mass <= 0:
        raise BuildError(f"{name}: mass {mass!r} kg or inertia not finite/positive")
    if np.abs(I - I.T).max() > 1e-9 * scale:
        raise BuildError(f"{name}: inertia tensor not symmetric")
    ev = np.linalg.eigvalsh(I)
    if ev.min() <= 0:
        raise BuildError(f"{name}: inertia tensor not positive-definite (principal moments {ev.tolist()!r})")
    a, b, c = sorted(ev)
    if a + b < c * (1 - 1e-9):
        raise BuildError(f"{name}: principal moments {ev.tolist()!r} break the triangle inequality")


def _inside_box(pt, lo, hi, tol=1e-9) -> bool:
    return bool(np.all(pt >= np.asarray(lo) - tol) and np.all(pt <= np.asarray(hi) + tol))


def validate(params: Params, report, parts=None, meshes: dict | None = None, memo=None) -> list[str]:
    """The gate every build passes (issue 3, item 5). Returns the checks done; raises BuildError on a failure.
    ``report``: a :class:`swiftfin.exports.massprops.MassReport` (not imported here: massprops imports this).

    * every part and link tensor: symmetric, positive-definite, triangle inequalities;
    * link masses add up to the total (1e-9 relative);
    * every link COM inside the skinned hull envelope (elliptic section at its station) if its station is
      within the hull, else (the tail link with the fin) inside the union of its parts' bounding boxes, and
      always inside that union;
    * OCC and mesh (trimesh) agree within 1 % on volume, on the COM (1 % of the bounding-box diagonal) and on
      the inertia tensor (1 % of its norm), for every part whose mesh is given (the exported STL meshes);
    * the mesh of each part is watertight.
    """
    done = []
    for pt in report.parts:
        check_tensor(f"part {pt.label}", pt.inertial.inertia, pt.inertial.mass_kg)
    for lk in report.links:
        check_tensor(f"link {lk.name}", lk.inertial.inertia, lk.inertial.mass_kg)
    done.append("tensors: symmetric, positive-definite, triangle inequality")
    msum = sum(lk.inertial.mass_kg for lk in report.links)
    if abs(msum - report.total.mass_kg) > 1e-9 * report.total.mass_kg:
        raise BuildError(f"links: masses sum to {msum!r} kg, total is {report.total.mass_kg!r} kg")
    done.append("link masses sum to the total")
    for lk in report.links:
        members = [pt for pt in report.parts if pt.link == lk.index]
        lo = np.min([pt.bbox_m[0] for pt in members], axis=0)
        hi = np.max([pt.bbox_m[1] for pt in members], axis=0)
        c = lk.com_body_m
        if not _inside_box(c, lo, hi):
            raise BuildError(f"link {lk.name}: COM {c.tolist()!r} m outside its parts' bounding box")
        s_mm = -units.length_mm(c[0])
        if 0 <= s_mm <= layout.hull_end_mm(params):
            a, b = envelope_section_mm(params, s_mm)
            y, z = units.length_mm(c[1]), units.length_mm(c[2])
            if a <= 0 or (y / a) ** 2 + (z / b) ** 2 > 1.0:
                raise BuildError(f"link {lk.name}: COM {c.tolist()!r} m outside the hull envelope")
    done.append("link COMs inside the hull envelope (and their parts' bounding boxes)")
    if meshes:
        for pt in report.parts:
            mesh = meshes.get(pt.label)
            if mesh is None:
                continue
            part = next((q for q in parts if q.label == pt.label), None) if parts else None
            if part is None:
                if not mesh.is_watertight:
                    raise BuildError(f"part {pt.label}: exported mesh is not watertight")
                continue
            # the mesh is the part's tessellation at the export's tolerances: stored by the part's content
            tight, b = memoized(memo, "mesh_props", (part.label,),
                                [params.export.mesh_tolerance_mm, params.export.mesh_angular_tolerance_deg],
                                lambda mesh=mesh: (bool(mesh.is_watertight), mesh_volume_props(mesh)))
            if not tight:
                raise BuildError(f"part {pt.label}: exported mesh is not watertight")
            a = memoized(memo, "solid_props", (part.label,), None, lambda part=part: solid_volume_props(part.solid))
            if abs(b.volume_mm3 - a.volume_mm3) > GATE_MESH_REL_TOL * a.volume_mm3:
                raise BuildError(f"part {pt.label}: OCC volume {a.volume_mm3:.6g} mm^3 vs mesh {b.volume_mm3:.6g}"
                                 f" mm^3 differ by more than 1 %")
            diag = float(np.linalg.norm(np.asarray(mesh.bounds[1]) - mesh.bounds[0]))
            if np.linalg.norm(np.subtract(a.centroid_mm, b.centroid_mm)) > GATE_MESH_REL_TOL * diag:
                raise BuildError(f"part {pt.label}: OCC and mesh centroids differ by more than 1 % of the size")
            Ia, Ib = np.asarray(a.second_moment_mm5), np.asarray(b.second_moment_mm5)
            if np.linalg.norm(Ia - Ib) > GATE_MESH_REL_TOL * np.linalg.norm(Ia):
                raise BuildError(f"part {pt.label}: OCC and mesh inertia tensors differ by more than 1 %")
        done.append("OCC and mesh agree within 1 % (volume, centroid, inertia); meshes watertight")
    return done
