"""``swiftfin solve`` (design_rules/synthesis.py): the nearest passing design, proven against the per-design rules
(``run_rules``, what ``swiftfin check`` runs: written apart from the vectorised rules the search uses) and against
closed forms where the answer is known."""
from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from swiftfin.core.params import ParamError, params_from_dict, to_dict
from swiftfin.core.schema import Params
from swiftfin.design_rules import RuleContext, Severity, run_rules
from swiftfin.design_rules.synthesis import DEFAULT_VARY, parse_vary, solve
from swiftfin.design_rules.vectorised import evaluate, seeded_designs

#: the default levers with the frequency held to 0.5 Hz and up: no design passes there
NARROW = tuple(v if not v.startswith("swimming.tail_beat_frequency_hz") else "swimming.tail_beat_frequency_hz=0.5:3"
               for v in DEFAULT_VARY)


def _failing(p: Params) -> set[str]:
    return {f.rule_id for f in run_rules(RuleContext(p)) if f.severity == Severity.FAIL}


@pytest.fixture(scope="module")
def one_rule_short() -> Params:
    """A seeded design that fails one rule only, the pretension band (5-20 % of its breaking strength)."""
    designs = seeded_designs(48)
    sev = evaluate(designs).severity
    fails = (sev == int(Severity.FAIL)).sum(axis=1)
    i = int(np.nonzero(fails == 1)[0][0])
    p = designs[i]
    assert _failing(p) == {"paper.pretension_fraction"}
    return p


def test_one_key_lands_on_the_closed_form_boundary(one_rule_short):
    """Searching the pretension alone, the nearest passing value is the band's edge, 10 % of the breaking strength
    (the design sits below it), to the bisection's resolution; the per-design rules pass there and fail just
    short of it."""
    p = one_rule_short
    hi = 0.9 * p.cable.breaking_strength_n
    r = solve(p, [parse_vary(f"cable.pretension_n=1:{hi}")])
    assert r.passes and r.keys_changed == 1 and r.failing == ()
    (c,) = r.changes
    edge = 0.10 * p.cable.breaking_strength_n
    assert p.cable.pretension_n < edge
    assert c.after == pytest.approx(edge, abs=(hi - 1) / 2 ** 20)
    assert c.buys == ("paper.pretension_fraction",)
    assert not _failing(r.design)
    short = params_from_dict({**to_dict(r.design), "cable": {**to_dict(r.design)["cable"],
                                                             "pretension_n": edge * (1 - 1e-4)}})
    assert _failing(short) == {"paper.pretension_fraction"}


def test_the_evolution_alone_finds_it_too(one_rule_short):
    """With the exhaustive stages off, the differential evolution and the thinning reach the same one change."""
    p = one_rule_short
    varies = [parse_vary(f"cable.pretension_n=1:{0.9 * p.cable.breaking_strength_n}"),
              parse_vary("swimming.tail_amplitude_m=0.03:0.12"), parse_vary("print.material=PLA,PETG,ASA")]
    r = solve(p, varies, exhaustive_up_to=0)
    assert r.passes and [c.key for c in r.changes] == ["cable.pretension_n"]
    assert r.changes[0].after == pytest.approx(0.10 * p.cable.breaking_strength_n, rel=1e-5)


@pytest.fixture(scope="module")
def paper_solved():
    return solve(Params(), [parse_vary(v) for v in DEFAULT_VARY])


def test_the_paper_fish_passes_with_few_changes_each_earning_its_place(paper_solved):
    """The paper's design (10 rules failing) reaches a passing design with at most 5 changed keys; the per-design
    rules agree; every change buys at least one rule (undone alone, something fails)."""
    r = paper_solved
    assert len(r.base_failing) == 10 and r.passes
    assert 1 <= r.keys_changed <= 5
    assert not _failing(r.design)
    assert all(c.buys for c in r.changes), [(c.key, c.buys) for c in r.changes]
    # the design the file will hold is one the loader accepts as it is
    assert params_from_dict(to_dict(r.design)) == r.design
    # the binding rule sits on its limit (the bisection's pull-back)
    assert r.binding and abs(r.binding[0][1]) < 1e-3


def test_narrower_ranges_say_what_still_fails():
    """With the frequency held to 0.5 Hz and up no design passes: the result says so, its rules fail in the
    per-design run too, and it fails fewer rules than the design."""
    r = solve(Params(), [parse_vary(v) for v in NARROW])
    assert not r.passes and r.failing
    assert _failing(r.design) == set(r.failing)
    assert len(r.failing) < len(r.base_failing)


@pytest.mark.parametrize("text, words", [
    ("cable.diamter_mm=0.5:1", "expected KEY=LO:HI"),
    ("cable.diameter_mm=0.01:1", "within [0.1, 5]"),
    ("cable.diameter_mm=1:0.5", "LO < HI"),
    ("cable.diameter_mm=a:b", "two numbers"),
    ("motor.model=custom,17HS9999", "17HS9999"),
    ("cable.model=Dyneema SK75", "fibre maker's figures"),
    ("joints.stations_fraction=0.5:0.6", "cannot be searched"),
    ("joints.count=2:4", "integer key"),
    ("nonsense", "expected KEY=LO:HI"),
])
def test_bad_vary_is_named(text, words):
    with pytest.raises(ParamError) as err:
        parse_vary(text)
    assert words in str(err.value)


def _cli(*args, cwd):
    return subprocess.run([sys.executable, "-m", "swiftfin", "solve", *args], capture_output=True, text=True,
                          cwd=cwd)


def test_the_command_writes_only_a_passing_design_and_never_over_a_file(tmp_path, one_rule_short):
    design = tmp_path / "d.toml"
    from swiftfin.core.params import dump_toml
    design.write_text(dump_toml(one_rule_short), encoding="utf-8")
    vary = f"cable.pretension_n=1:{0.9 * one_rule_short.cable.breaking_strength_n:.1f}"
    r = _cli(str(design), "--vary", vary, "--out", "s.toml", "--json", "s.json", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "passes every kernel-free rule" in r.stdout and "paper.pretension_fraction" in r.stdout
    import json
    out = json.loads((tmp_path / "s.json").read_text())
    assert out["passes"] and out["changes"][0]["key"] == "cable.pretension_n"
    written = (tmp_path / "s.toml").read_bytes()
    check = subprocess.run([sys.executable, "-m", "swiftfin", "check", "s.toml"], capture_output=True, text=True,
                           cwd=tmp_path)
    assert check.returncode == 0, check.stdout[-2000:]
    # into a folder that does not exist yet: made, the file written whole
    r3 = _cli(str(design), "--vary", vary, "--out", "new/deeper/s.toml", cwd=tmp_path)
    assert r3.returncode == 0 and "Traceback" not in r3.stderr
    assert (tmp_path / "new" / "deeper" / "s.toml").read_bytes() == written
    # again into the same file: refused, the file untouched
    r2 = _cli(str(design), "--vary", vary, "--out", "s.toml", cwd=tmp_path)
    assert r2.returncode == 2 and "never overwrites" in r2.stderr and "Traceback" not in r2.stderr
    assert (tmp_path / "s.toml").read_bytes() == written


def test_the_command_exits_1_and_writes_nothing_when_none_passes(tmp_path):
    r = _cli("--vary", "cable.pretension_n=10:100", "--out", "s.toml", cwd=tmp_path)
    assert r.returncode == 1 and "NO design within the ranges passes" in r.stdout
    assert not (tmp_path / "s.toml").exists()


def test_the_command_refuses_bad_input_with_exit_2(tmp_path):
    r = _cli("--vary", "cable.pretension_n=-5:100", "--out", "s.toml", cwd=tmp_path)
    assert r.returncode == 2 and "cable.pretension_n" in r.stderr and "Traceback" not in r.stderr
    r = _cli("--samples", "3", cwd=tmp_path)
    assert r.returncode == 2 and "--samples" in r.stderr
    assert not list(tmp_path.iterdir())
