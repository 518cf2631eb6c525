"""``swiftfin audit [--json FILE]``: recompute every number the paper derives from its own inputs.

Prints each entry's paper value, recomputed value and whether it holds (tolerance in
``swiftfin.design_rules.paper_audit.TOLERANCE``). Always exits 0: the audit reports on the paper, not on a design.
"""
from __future__ import annotations

from swiftfin.design_rules.paper_audit import TOLERANCE, audit_entries


def configure(ap) -> None:
    """Add this command's arguments to its parser (made by swiftfin.cli)."""
    ap.add_argument("--json", metavar="FILE", help="also write the entries as JSON")
    ap.set_defaults(func=run)


def _v(x) -> str:
    return "-" if x is None else f"{x:.4g}"


def run(args) -> int:
    entries = audit_entries()
    rows = [("entry", "where", "paper", "recomputed", "unit", "verdict")]
    for e in entries:
        verdict = {True: "holds", False: "DOES NOT HOLD", None: "cannot check"}[e.holds]
        rows.append((e.entry_id, e.where, _v(e.paper), _v(e.recomputed), e.unit, verdict))
    w = [max(len(r[i]) for r in rows) for i in range(6)]
    print(f"Audit of the SwiftFin paper ({TOLERANCE})\n")
    for n, r in enumerate(rows):
        print("  ".join(c.ljust(x) for c, x in zip(r, w)).rstrip())
        if n == 0:
            print("  ".join("-" * x for x in w))
    print("\nreasons:")
    for e in entries:
        print(f"  {e.entry_id}: {e.quantity}. {e.reason}")
    bad = [e.entry_id for e in entries if e.holds is False]
    print(f"\n{len(entries)} entries: {sum(e.holds is True for e in entries)} hold, {len(bad)} do not hold, "
          f"{sum(e.holds is None for e in entries)} cannot be checked")
    if args.json:
        from swiftfin.commands.check import _write_json
        _write_json(args.json, {"tolerance": TOLERANCE, "entries": [e.to_dict() for e in entries]})
    return 0
