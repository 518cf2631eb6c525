"""A design rule's result: the Finding, and the ordered Severity whose worst value is the verdict."""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from enum import IntEnum


class Severity(IntEnum):
    """Ordered: the verdict of a set of findings is the worst (max). Only FAIL fails ``swiftfin check``."""
    PASS = 0
    INFO = 1
    NOT_EVALUATED = 2   # the rule's inputs are missing; ``detail`` says which
    WARN = 3
    FAIL = 4


@dataclass(frozen=True)
class Finding:
    """One rule applied to one design.

    ``value`` and ``limit`` are in ``unit``; ``comparison`` reads "value <comparison> limit" (">=", "<=", "in"
    for a band, where ``limit`` is (lo, hi)). ``margin`` is the relative distance to the limit, positive when the
    rule holds: (value - limit)/limit for ">=", (limit - value)/limit for "<=", and for a band the smaller of the
    two relative distances to its ends. A rule not evaluated has value, limit and margin None.
    """
    rule_id: str
    value: float | None
    limit: float | tuple[float, float] | None
    margin: float | None
    severity: Severity
    source: str
    unit: str = "-"
    comparison: str = ">="
    detail: str = ""

    def __post_init__(self):
        nums = [self.value, self.margin] + (list(self.limit) if isinstance(self.limit, tuple) else [self.limit])
        for v in nums:
            if v is not None and not math.isfinite(v):
                raise ValueError(f"rule {self.rule_id}: non-finite number {v!r} in a finding")
        if self.severity is not Severity.NOT_EVALUATED and self.value is None:
            raise ValueError(f"rule {self.rule_id}: an evaluated finding needs a value")
        if self.severity is Severity.NOT_EVALUATED and not self.detail:
            raise ValueError(f"rule {self.rule_id}: a rule not evaluated must say why")

    def to_dict(self) -> dict:
        d = asdict(self)
        d["severity"] = self.severity.name
        if isinstance(self.limit, tuple):
            d["limit"] = list(self.limit)
        return d

    def value_text(self) -> str:
        """The value for a person: 4 significant digits, and a value that is zero to rounding (a pitch of 2e-13
        deg of a level fish) as 0."""
        if self.value is None:
            return "-"
        scale = max([abs(v) for v in (self.limit if isinstance(self.limit, tuple) else (self.limit,))
                     if v is not None] or [1.0])
        v = 0.0 if abs(self.value) < 1e-9 * max(scale, 1e-300) else self.value
        return _g(v)

    def margin_text(self) -> str:
        """The margin for a person: the relative distance to the limit in percent while it is within 100 %,
        beyond that how many times the limit the value is (a cable that stretches 849x its allowance reads
        "849x the limit", not "-84780 %")."""
        if self.margin is None:
            return "-"
        if self.margin < -1.0 and not isinstance(self.limit, tuple) and self.limit:
            return f"{self.value / self.limit:.3g}x the limit"
        return f"{100 * self.margin:+.0f} %"

    def limit_text(self) -> str:
        if self.limit is None:
            return "-"
        if isinstance(self.limit, tuple):
            return f"in [{_g(self.limit[0])}, {_g(self.limit[1])}]"
        return f"{self.comparison} {_g(self.limit)}"


def _g(v: float) -> str:
    return f"{v:.4g}"


def verdict(findings) -> Severity:
    """The worst severity of the findings (PASS for none)."""
    return max((f.severity for f in findings), default=Severity.PASS)


def at_least(rule_id: str, value: float, limit: float, source: str, unit: str = "-", detail: str = "",
             below: Severity = Severity.FAIL) -> Finding:
    """Finding for 'value >= limit' (severity ``below`` when it does not hold)."""
    margin = (value - limit) / limit if limit != 0 else value - limit
    return Finding(rule_id, float(value), float(limit), float(margin),
                   Severity.PASS if value >= limit else below, source, unit, ">=", detail)


def at_most(rule_id: str, value: float, limit: float, source: str, unit: str = "-", detail: str = "",
            above: Severity = Severity.FAIL) -> Finding:
    """Finding for 'value <= limit' (severity ``above`` when it does not hold)."""
    margin = (limit - value) / limit if limit != 0 else limit - value
    return Finding(rule_id, float(value), float(limit), float(margin),
                   Severity.PASS if value <= limit else above, source, unit, "<=", detail)


def within(rule_id: str, value: float, lo: float, hi: float, source: str, unit: str = "-", detail: str = "",
           outside: Severity = Severity.FAIL) -> Finding:
    """Finding for 'lo <= value <= hi'."""
    m_lo = (value - lo) / lo if lo != 0 else value - lo
    m_hi = (hi - value) / hi if hi != 0 else hi - value
    ok = lo <= value <= hi
    return Finding(rule_id, float(value), (float(lo), float(hi)), float(min(m_lo, m_hi)),
                   Severity.PASS if ok else outside, source, unit, "in", detail)


def not_evaluated(rule_id: str, source: str, reason: str, unit: str = "-") -> Finding:
    return Finding(rule_id, None, None, None, Severity.NOT_EVALUATED, source, unit, "", reason)
