"""Stepper motors, read from ``motors.toml`` beside this module (every number's source is in the file).

``motor("17HS19-2004S1")`` gives the :class:`StepperMotor`; ``motor_params(name)`` the keys of a design's
``[motor]`` section the entry fills (the fields the maker's sheet gives; the rest stay the design's own). A
field the table leaves out is None: we could not trace it to a named source, and we do not guess.

The lowest layer: it reads its own data file and imports nothing else of swiftfin.
"""
from __future__ import annotations

import tomllib
from dataclasses import dataclass, field, fields
from functools import cache
from pathlib import Path

from swiftfin.catalogues.table import by_name, is_positive_number

HERE = Path(__file__).resolve().parent

#: The entry's fields a design's ``[motor]`` section takes under the same name; ``rated_current_a`` fills
#: ``motor.phase_current_a`` (:data:`RENAMED`): the schema defines the holding torque as the motor's at the current
#: the driver holds, and a maker's holding torque is at the rated current, so a design naming a model holds that
#: current (one that holds less gives its own, scaled numbers as ``model = "custom"``). ``gear_ratio`` has no
#: schema key yet.
PARAM_KEYS = ("frame_size_mm", "body_length_mm", "mass_kg", "rotor_inertia_kg_m2", "holding_torque_nm",
              "rated_current_a", "phase_resistance_ohm", "full_step_deg")
RENAMED = {"rated_current_a": "phase_current_a"}


@dataclass(frozen=True)
class StepperMotor:
    """One model (SI unless the name says otherwise; None: not published or not traced to a source)."""
    name: str
    maker: str
    frame_size_mm: float | None = None
    body_length_mm: float | None = None
    mass_kg: float | None = None
    rotor_inertia_kg_m2: float | None = None
    holding_torque_nm: float | None = None         # at the rated current
    rated_current_a: float | None = None
    phase_resistance_ohm: float | None = None
    phase_inductance_h: float | None = None
    full_step_deg: float | None = None
    gear_ratio: float = 1.0                         # motor turns per output turn (a gearbox on the shaft)
    sources: dict = field(default_factory=dict)     # field -> where its number comes from

    def params(self) -> dict[str, float]:
        """The ``[motor]`` keys this entry gives, with their values."""
        return {RENAMED.get(k, k): getattr(self, k) for k in PARAM_KEYS if getattr(self, k) is not None}


_NUMBERS = tuple(f.name for f in fields(StepperMotor) if f.name not in ("name", "maker", "sources"))


@cache
def motors() -> tuple[StepperMotor, ...]:
    """Every model of ``motors.toml``. Raises ValueError listing every malformed entry (a number without a source,
    an unknown field, a value that is not a positive number)."""
    raw = tomllib.loads((HERE / "motors.toml").read_text(encoding="utf-8"))
    out, problems = [], []
    for name, row in raw.items():
        row = dict(row)
        sources = row.pop("sources", {})
        maker = row.pop("maker", "")
        for k, v in row.items():
            if k not in _NUMBERS:
                problems.append(f"[{name}] unknown field {k!r} (known: {', '.join(_NUMBERS)})")
            elif not is_positive_number(v):
                problems.append(f"[{name}] {k} = {v!r}: expected a positive number")
            elif k not in sources:
                problems.append(f"[{name}] {k} has no source in [{name}.sources]")
        if not maker:
            problems.append(f"[{name}] needs a maker")
        if problems:
            continue
        out.append(StepperMotor(name, maker, **{k: float(v) for k, v in row.items()}, sources=dict(sources)))
    if problems:
        raise ValueError("catalogues/motors.toml: " + "; ".join(problems))
    return tuple(out)


def motor_names() -> tuple[str, ...]:
    return tuple(m.name for m in motors())


def motor(name: str) -> StepperMotor:
    return by_name(motors(), name, "motor", "motors.toml")


def motor_params(name: str) -> dict[str, float]:
    """The ``[motor]`` keys the catalogue entry ``name`` fills (see :data:`PARAM_KEYS`)."""
    return motor(name).params()
