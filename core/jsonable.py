"""Plain JSON types from numpy scalars, numpy arrays and dataclasses: the one helper every JSON writer uses.

``json.dumps(jsonable(obj), allow_nan=False)`` then works: dicts (keys made ``str``), lists and tuples are
converted item by item, numpy and Python floats become ``float`` (NaN and infinities become ``None``, JSON's
null), numpy integers ``int``, numpy booleans ``bool``, arrays nested lists and dataclass instances dicts of
their fields. Anything else (str, int, bool, None) is returned as it is.
"""
from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np


def jsonable(obj: Any) -> Any:
    """``obj`` with every numpy scalar, array and dataclass instance turned into plain JSON types (see above)."""
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if isinstance(obj, (np.floating, float)):
        v = float(obj)
        return v if math.isfinite(v) else None
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, np.ndarray):
        return jsonable(obj.tolist())
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {f.name: jsonable(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    return obj


__all__ = ["jsonable"]
