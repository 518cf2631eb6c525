"""The README is the user's manual: every command, every benchmark and the two set-up commands are in it.

A README edit once cut 381 lines (the commands, the solve and sweep sections, the layout, the audit) and the
suite stayed green; these tests fail on such a cut, naming what went missing."""
from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()


def _sections() -> list[str]:
    return re.findall(r"^#{2,3} (.+)$", README, flags=re.M)


def test_every_command_has_its_own_section_or_example():
    from swiftfin.cli import COMMANDS

    missing = [name for name in COMMANDS if not re.search(rf"swiftfin {name}\b", README)]
    assert not missing, f"README.md never shows 'swiftfin {missing[0]}' (commands missing: {missing})"


def test_every_benchmark_is_reported():
    benches = sorted(p.name for p in (ROOT / "bench").glob("bench_*.py"))
    missing = [b for b in benches if f"bench/{b}" not in README]
    assert not missing, f"README.md does not report bench/{missing[0]} (missing: {missing})"


def test_the_two_set_up_commands_and_the_sections_users_look_for():
    assert "make build" in README and "make test" in README
    titles = " | ".join(_sections())
    for words in ("Set up a fresh machine", "Commands", "The parameter file", "Layout of the code",
                  "Design rules", "swiftfin solve", "swiftfin sweep", "swiftfin audit", "The build",
                  "Mass, buoyancy and simulators", "Measured data", "The design report"):
        assert words in titles, f"README.md has no section on {words!r} (sections: {titles})"
