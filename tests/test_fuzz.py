"""Property-based fuzzing (hypothesis) of the commands' inputs: parameter files and measured logs.

Whatever the input, a command exits 0, 1 or 2, prints no traceback, and on exit 2 writes nothing (the input
file is untouched, no output appears). The parameter files mix the schema's real keys with values of every type
and size (in range, out of range, NaN, inf, huge integers, strings, lists, nested tables) and keys that do not
exist; the logs mix real column names with corrupted numbers, cells and headers. Seeded (derandomised) and
bounded in examples, so the test costs the same on every run; a failure prints the input that caused it.
"""
from __future__ import annotations

import dataclasses
import math

import pytest
import tomli_w
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from swiftfin.cli import main
from swiftfin.core.schema import SECTIONS, Params

FUZZ = settings(max_examples=60, deadline=None, derandomize=True, database=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])

# every (section, key, default, schema metadata: range, choices)
KEYS = [(sec, f.name, getattr(getattr(Params(), sec), f.name), dict(f.metadata))
        for sec in SECTIONS if dataclasses.is_dataclass(getattr(Params(), sec))
        for f in dataclasses.fields(getattr(Params(), sec))]

scalars = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True, width=64),
    st.integers(min_value=-(10**30), max_value=10**30),
    st.booleans(),
    st.text(max_size=20),
)
values = st.recursive(scalars, lambda inner: st.one_of(st.lists(inner, max_size=4),
                                                       st.dictionaries(st.text(max_size=8), inner, max_size=3)),
                      max_leaves=8)


def _near(default, meta: dict):
    """Values for a key: mostly inside its documented range (so that many files are valid and the later checks
    run), else scaled from the default, or of another type."""
    if isinstance(default, bool):
        return st.one_of(st.booleans(), values)
    lo, hi = meta.get("lo"), meta.get("hi")
    if isinstance(default, int) and lo is not None and hi is not None:
        inside = st.integers(int(math.ceil(lo)), int(math.floor(hi)))
        return st.one_of(inside, inside, inside, st.integers(-10, 10**6), values)
    if isinstance(default, float) and lo is not None and hi is not None:
        inside = st.floats(min_value=lo, max_value=hi)
        return st.one_of(inside, inside, inside, st.just(default),
                         st.floats(min_value=-1e6, max_value=1e6, allow_nan=False).map(lambda k: default * k), values)
    if isinstance(default, (int, float)):
        return st.one_of(st.floats(min_value=-1e6, max_value=1e6, allow_nan=False).map(lambda k: default * k),
                         st.just(default), values)
    if isinstance(default, tuple):
        return st.one_of(st.lists(st.floats(min_value=-2, max_value=1e4, allow_nan=False), max_size=10), values)
    return values


@st.composite
def parameter_files(draw) -> dict:
    doc: dict = {}
    for i in draw(st.lists(st.integers(0, len(KEYS) - 1), max_size=6, unique=True)):
        sec, key, default, meta = KEYS[i]
        doc.setdefault(sec, {})[key] = draw(_near(default, meta))
    if draw(st.integers(0, 3)) == 0:
        doc.setdefault(draw(st.sampled_from([*SECTIONS, "bogus"])), {})[draw(st.text(min_size=1, max_size=12))] = \
            draw(values)
    if draw(st.integers(0, 5)) == 0:
        doc[draw(st.text(min_size=1, max_size=10))] = draw(values)      # a key at the top level
    return doc


def _toml(doc: dict) -> str | None:
    def clean(v):     # TOML has no null; tomli_w refuses NaN in keys etc.: drop what it cannot write
        if isinstance(v, dict):
            return {str(k): clean(x) for k, x in v.items()}
        if isinstance(v, list):
            return [clean(x) for x in v]
        return v
    try:
        return tomli_w.dumps(clean(doc))
    except (TypeError, ValueError):
        return None


def _run(args, capsys) -> tuple[int, str]:
    code = main(args)
    out = capsys.readouterr()
    return code, out.out + out.err


@FUZZ
@given(doc=parameter_files(), command=st.sampled_from(["params", "check"]))
def test_any_parameter_file(tmp_path_factory, capsys, doc, command):
    text = _toml(doc)
    if text is None:
        return
    d = tmp_path_factory.mktemp("fuzz")
    f = d / "design.toml"
    f.write_text(text, encoding="utf-8")
    code, out = _run([command, str(f)], capsys)
    event(f"{command} exit {code}")
    assert code in (0, 1, 2), out
    assert "Traceback" not in out
    assert f.read_text(encoding="utf-8") == text
    assert sorted(p.name for p in d.iterdir()) == ["design.toml"]
    if code == 2:
        assert "design.toml" in out and "error" in out


@FUZZ
@given(data=st.binary(max_size=400))
def test_any_bytes_as_a_parameter_file(tmp_path_factory, capsys, data):
    d = tmp_path_factory.mktemp("fuzzb")
    f = d / "design.toml"
    f.write_bytes(data)
    code, out = _run(["params", str(f)], capsys)
    assert code in (0, 2) and "Traceback" not in out
    assert f.read_bytes() == data


JOINT_HEADER = ["time_s", "motor_angle_rad", "joint_angle_rad", "cable_tension_n"]
DRIVE_HEADER = ["time_s", "position_m", "force_n"]
cells = st.one_of(st.floats(allow_nan=True, allow_infinity=True, width=32).map(lambda x: repr(float(x))),
                  st.integers(-10**6, 10**6).map(str), st.sampled_from(["", "nan", "x", "1,5", "1e999", " "]))


@st.composite
def logs(draw) -> tuple[str, str]:
    family = draw(st.sampled_from(["joint", "drive"]))
    header = list(JOINT_HEADER if family == "joint" else DRIVE_HEADER)
    if draw(st.integers(0, 4)) == 0:
        header = draw(st.lists(st.sampled_from(header + ["position_mm", "t", ""]), min_size=1, max_size=5))
    n = draw(st.integers(0, 60))
    kind = draw(st.sampled_from(["smooth", "cells"]))
    rows = []
    for i in range(n):
        if kind == "smooth":    # a plausible log, possibly corrupted in one cell
            t = i * draw(st.sampled_from([0.001, 1.0, -0.001]))
            row = [repr(t)] + [repr(math.sin(0.5 * i + k)) for k in range(len(header) - 1)]
        else:
            row = [draw(cells) for _ in header]
        rows.append(",".join(row))
    return family, "\n".join([",".join(header), *rows]) + "\n"


@FUZZ
@given(log=logs())
def test_any_log(tmp_path_factory, capsys, log):
    from tests.conftest import DEFAULT_DESIGN

    family, text = log
    d = tmp_path_factory.mktemp("fuzzlog")
    f = d / "log.csv"
    f.write_text(text)
    out_dir = d / "fit"
    code, out = _run(["fit", family, str(f), "--out", str(out_dir), "--no-plots", "--design", str(DEFAULT_DESIGN)],
                     capsys)
    event(f"fit {family} exit {code}")
    assert code in (0, 1, 2), out
    assert "Traceback" not in out
    assert f.read_text() == text
    if code == 2:
        assert not out_dir.exists()


@pytest.mark.parametrize("family", ["joint", "drive"])
def test_the_fuzz_reaches_the_fitting(tmp_path, capsys, family):
    """Not only refusals: a well-formed log of each family gets through the checks to a fit (exit 0), so the
    fuzz above exercises the code behind the checks too."""
    from tests.conftest import DEFAULT_DESIGN

    if family == "joint":
        assert main(["synth", "joint", "--out", str(tmp_path / "log.csv"), "--duration", "3",
                     "--design", str(DEFAULT_DESIGN)]) == 0
    else:
        t = [i * 0.001 for i in range(6000)]
        x = [0.1 * math.sin(2 * math.pi * 0.5 * s) for s in t]
        v = [0.1 * math.pi * math.cos(2 * math.pi * 0.5 * s) for s in t]
        a = [-0.1 * (math.pi ** 2) * math.sin(2 * math.pi * 0.5 * s) for s in t]
        rows = [f"{s!r},{p!r},{95 * acc + 200 * vel + 20 * math.copysign(1, vel)!r}"
                for s, p, vel, acc in zip(t, x, v, a)]
        (tmp_path / "log.csv").write_text("time_s,position_m,force_n\n" + "\n".join(rows) + "\n")
    code, out = _run(["fit", family, str(tmp_path / "log.csv"), "--out", str(tmp_path / "fit"), "--no-plots",
                      "--design", str(DEFAULT_DESIGN)], capsys)
    assert code == 0, out
