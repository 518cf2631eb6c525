"""The z-buffer's inner loop, compiled: every screen triangle's pixels, nearest first.

:func:`swiftfin.report.render.rasterize` did this in numpy, triangles batched by box size, each batch's pixels
sorted by depth: about 45 % of a picture's time (2.2 s of the 4.9 s the four renders of a fin-change rebuild
took). Here each triangle walks its own box once, so no triangle needs splitting and no sort is needed.

The rule is the numpy version's: a pixel belongs to a triangle when its centre (x + 0.5, y + 0.5) has all three
barycentric coordinates >= -1e-6; the nearest (largest depth) triangle wins, the first in index order on a tie.

Compiled by numba on first use and cached beside this file (or in numba's user cache when that folder is
read-only), as :mod:`swiftfin.design_rules.loads_kernel`.
"""
from __future__ import annotations

import math

from numba import njit

INSIDE_TOL = -1e-6
"""Barycentric tolerance at a pixel centre: a centre exactly on an edge shared by two triangles is covered."""


@njit(cache=True, nogil=True)
def fill(x, y, z, width, height, zbuf, fbuf, bbuf):  # pragma: no cover - compiled; its tests run it
    """Rasterise triangles ``(x, y, z)`` (each (m, 3), pixels, x right, y down, z larger = nearer) into the flat
    buffers ``zbuf`` (depth, -inf where empty), ``fbuf`` (triangle index, -1) and ``bbuf`` ((H W, 3) barycentric)."""
    m = x.shape[0]
    for i in range(m):
        xa, xb, xc = x[i, 0], x[i, 1], x[i, 2]
        ya, yb, yc = y[i, 0], y[i, 1], y[i, 2]
        area = (xb - xa) * (yc - ya) - (xc - xa) * (yb - ya)
        if abs(area) <= 1e-12:
            continue
        lo_x, hi_x = min(xa, xb, xc), max(xa, xb, xc)
        lo_y, hi_y = min(ya, yb, yc), max(ya, yb, yc)
        if hi_x < 0 or lo_x > width or hi_y < 0 or lo_y > height:
            continue
        x0 = max(0, min(width - 1, int(math.floor(lo_x - 0.5))))
        x1 = max(0, min(width - 1, int(math.ceil(hi_x - 0.5))))
        y0 = max(0, min(height - 1, int(math.floor(lo_y - 0.5))))
        y1 = max(0, min(height - 1, int(math.ceil(hi_y - 0.5))))
        inv = 1.0 / area
        za, zb, zc = z[i, 0], z[i, 1], z[i, 2]
        for py in range(y0, y1 + 1):
            cy = py + 0.5
            for px in range(x0, x1 + 1):
                cx = px + 0.5
                w0 = ((xb - cx) * (yc - cy) - (xc - cx) * (yb - cy)) * inv
                if w0 < INSIDE_TOL:
                    continue
                w1 = ((xc - cx) * (ya - cy) - (xa - cx) * (yc - cy)) * inv
                if w1 < INSIDE_TOL:
                    continue
                w2 = 1.0 - w0 - w1
                if w2 < INSIDE_TOL:
                    continue
                depth = w0 * za + w1 * zb + w2 * zc
                k = py * width + px
                if depth > zbuf[k]:
                    zbuf[k] = depth
                    fbuf[k] = i
                    bbuf[k, 0] = w0
                    bbuf[k, 1] = w1
                    bbuf[k, 2] = w2
