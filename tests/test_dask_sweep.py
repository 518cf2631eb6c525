"""``swiftfin sweep``: designs as Dask tasks on a LocalCluster (2 workers), gathered into one table; the same rows
as running the designs one by one; a stopped sweep resumes; refused designs keep their row."""
from __future__ import annotations

import csv
import json
import subprocess
import sys
from pathlib import Path

import pytest

from swiftfin.core.params import dump_toml
from swiftfin.design_rules.vectorised import seeded_designs
from swiftfin.sweep import COLUMNS, SweepItem, collect_designs, run_design, sweep
from tests.conftest import session_cache_dir

N_DESIGNS = 20


def _same(a: dict, b: dict) -> bool:
    return all(a[k] == b[k] for k in COLUMNS if k != "wall_s")


@pytest.fixture(scope="module")
def designs(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("designs")
    for i, p in enumerate(seeded_designs(N_DESIGNS, seed=7)):
        (d / f"d{i:02d}.toml").write_text(dump_toml(p), encoding="utf-8")
    (d / "zz_refused.toml").write_text("[cable]\npretension_n = -3\n", encoding="utf-8")
    return d


@pytest.fixture(scope="module")
def swept(designs, tmp_path_factory):
    out = tmp_path_factory.mktemp("sweep")
    items = collect_designs([designs])
    rows, ran = sweep(items, out, stage="check", workers=2)
    return items, out, rows, ran


def test_a_local_cluster_sweep_equals_the_designs_one_by_one(swept, tmp_path):
    items, out, rows, ran = swept
    assert ran == len(items) == N_DESIGNS + 1
    alone = [run_design(it.path, it.name, str(tmp_path), "check") for it in items]
    assert [r["design"] for r in rows] == [it.name for it in items]
    for a, b in zip(rows, alone):
        assert _same(a, b), (a, b)
    with open(out / "results.csv", newline="") as fh:
        table = list(csv.DictReader(fh))
    assert [r["design"] for r in table] == [it.name for it in items]
    refused = next(r for r in table if r["design"] == "zz_refused")
    assert refused["status"] == "refused" and "cable.pretension_n = -3" in refused["message"]
    # a design the loader takes may still be refused by a fastener plan (a BuildError: its row says which)
    others = [r for r in table if r["design"] != "zz_refused"]
    assert all((r["status"] == "ok" and r["verdict"]) or (r["status"] == "failed" and r["message"]) for r in others)
    assert sum(r["status"] == "ok" for r in others) >= N_DESIGNS // 2


def test_a_stopped_sweep_resumes_where_it_stopped(swept, designs, tmp_path):
    """Copy a finished sweep, lose eight rows (as a killed run never wrote them) and change one design's file: the
    next run runs exactly those nine, and the table is the one a fresh sweep gives."""
    import shutil
    items, out, rows, _ = swept
    out2 = tmp_path / "out"
    shutil.copytree(out, out2)
    lost = [it.name for it in items[3:11]]
    for name in lost:
        (out2 / "results" / f"{name}.json").unlink()
    d2 = tmp_path / "designs"
    shutil.copytree(designs, d2)
    changed = d2 / "d15.toml"
    changed.write_text(changed.read_text().replace("[motor]", "[motor]\n# edited"), encoding="utf-8")
    items2 = collect_designs([d2])
    rows2, ran = sweep(items2, out2, stage="check", workers=2)
    assert ran == len(lost) + 1
    for a, b in zip(rows, rows2):
        assert all(a[k] == b[k] for k in COLUMNS if k not in ("wall_s", "params_file", "params_sha256")), a["design"]
    assert sweep(items2, out2, stage="check", workers=2)[1] == 0        # nothing left to do


def test_collect_refuses_what_it_cannot_sweep(tmp_path):
    from swiftfin.core.errors import UserError
    with pytest.raises(UserError, match="no such parameter file"):
        collect_designs([tmp_path / "nothing"])
    (tmp_path / "empty").mkdir()
    with pytest.raises(UserError, match="no parameter file"):
        collect_designs([tmp_path / "empty"])
    a, b = tmp_path / "a", tmp_path / "b"
    a.mkdir(), b.mkdir()
    for d in (a, b):
        (d / "same.toml").write_text("", encoding="utf-8")
    with pytest.raises(UserError, match="two designs are named 'same'"):
        collect_designs([a, b])


def test_the_command_writes_the_table_and_leaves_other_files_alone(designs, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    mine = out / "notes.txt"
    mine.write_text("mine", encoding="utf-8")
    r = subprocess.run([sys.executable, "-m", "swiftfin", "sweep", str(designs / "d00.toml"), str(designs / "d01.toml"),
                        "--out", str(out), "--stage", "check", "--workers", "1"],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 1, r.stderr[-2000:]      # the seeded designs fail rules: exit 1, every row written
    assert "2 designs (2 run now, 0 done before)" in r.stdout and "Traceback" not in r.stderr
    assert mine.read_text() == "mine"
    with open(out / "results.csv", newline="") as fh:
        assert len(list(csv.DictReader(fh))) == 2
    bad = subprocess.run([sys.executable, "-m", "swiftfin", "sweep", str(tmp_path / "none.toml"), "--out",
                          str(tmp_path / "o2")], capture_output=True, text=True, timeout=600)
    assert bad.returncode == 2 and "no such parameter file" in bad.stderr and "Traceback" not in bad.stderr
    assert not (tmp_path / "o2").exists()


@pytest.mark.slow
def test_a_build_sweep_builds_each_design_into_its_own_folder(tmp_path, tmp_path_factory):
    """The shipped design, built as a task: its folder has the build's manifest, the row carries the build's mass
    and every rule with it (the floating ones evaluated), and a second run skips it. The build shares the session's
    rebuild cache with tests/test_build.py (a few seconds when that ran first, a cold build alone)."""
    cache = str(session_cache_dir(tmp_path_factory))
    from swiftfin.layout.design import default_design_path
    d = tmp_path / "designs"
    d.mkdir()
    (d / "swiftfin.toml").write_bytes(Path(default_design_path()).read_bytes())
    items = [SweepItem("swiftfin", str(d / "swiftfin.toml"))]
    out = tmp_path / "out"
    rows, ran = sweep(items, out, stage="build", workers=1, cache_dir=cache)
    (row,) = rows
    assert ran == 1 and row["status"] == "ok", row["message"]
    manifest = json.loads((out / "builds" / "swiftfin" / "manifest.json").read_text())
    assert manifest["params_sha256"] == row["params_sha256"]
    mp = json.loads((out / "builds" / "swiftfin" / "mass_properties.json").read_text())
    assert row["total_mass_kg"] == pytest.approx(mp["total"]["mass_kg"], rel=1e-12)
    from swiftfin.design_rules.rules import RULES
    # float.* and print.* evaluated (the build's mass properties and its parts' print records): none NOT_EVALUATED
    assert row["n_pass"] + row["n_info"] + row["n_warn"] + row["n_fail"] == len(RULES)
    assert sweep(items, out, stage="build", workers=1, cache_dir=cache)[1] == 0
