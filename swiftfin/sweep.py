"""Sweeps: many designs, each one a Dask task, gathered into one table.

    items = collect_designs(["designs/"])                       # parameter files, or folders of them
    rows = sweep(items, "sweep_out", stage="build")             # a LocalCluster on every core
    rows = sweep(items, "sweep_out", scheduler="tcp://host:8786")   # an existing Dask cluster

Each task runs one design in its own process: ``stage="check"`` the kernel-free rules (:func:`run_rules`);
``stage="build"`` a full ``swiftfin build`` into ``OUT/builds/<name>/`` (its own manifest) and then every rule,
the floating ones included, with that build's mass properties. A task never raises: a design the loader refuses,
a build that fails its checks or an error is a row with its status and message, never lost.

Layout of ``OUT`` (only these are written; nothing else in the folder is touched):

* ``results/<name>.json``: one row per design, written atomically when its task ends; it records the SHA-256 of
  the parameter file's bytes and the stage, so a re-run skips every design whose row matches its file (and, for
  a build, whose build folder's manifest hashes the same bytes): a sweep killed half way resumes where it stopped;
* ``builds/<name>/``: the build of each design (stage ``build``);
* ``results.csv``: every design's row, in the order given, rewritten at the end of each run.

Rows: ``design, params_file, params_sha256, stage, status (ok | refused | failed | error), message, verdict,
n_pass, n_info, n_warn, n_fail, failing, total_mass_kg, displaced_volume_l, wall_s``.
"""
from __future__ import annotations

import csv
import hashlib
import io
import json
import os
import time
from dataclasses import dataclass
from pathlib import Path

from swiftfin.core.errors import BuildError, UserError
from swiftfin.core.params import ParamError
from swiftfin.outdir import write_text_atomic
from swiftfin.progress import bar

STAGES = ("check", "build")
COLUMNS = ("design", "params_file", "params_sha256", "stage", "status", "message", "verdict", "n_pass", "n_info",
           "n_warn", "n_fail", "failing", "total_mass_kg", "displaced_volume_l", "wall_s")


@dataclass(frozen=True)
class SweepItem:
    name: str            # the design's name in the table and its folders (the file's stem)
    path: str            # the parameter file


def collect_designs(paths) -> list[SweepItem]:
    """Parameter files named, and the ``*.toml`` files of folders named (sorted). UserError for a path that does
    not exist, a folder without one, or two designs of the same name."""
    out: list[SweepItem] = []
    for given in paths:
        p = Path(given)
        if p.is_dir():
            files = sorted(p.glob("*.toml"))
            if not files:
                raise UserError(f"{p}: a folder with no parameter file (*.toml) in it")
        elif p.is_file():
            files = [p]
        else:
            raise UserError(f"{p}: no such parameter file or folder")
        out += [SweepItem(f.stem, str(f)) for f in files]
    seen: dict[str, str] = {}
    for it in out:
        if it.name in seen:
            raise UserError(f"two designs are named {it.name!r} ({seen[it.name]} and {it.path}): each design's "
                            f"name (its file's stem) must be unique, it names its folder and its row")
        seen[it.name] = it.path
    if not out:
        raise UserError("no designs to sweep: name parameter files or folders holding them")
    return out


def _sha256(path: str) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def run_design(path: str, name: str, out_root: str, stage: str, cache_dir: str | None = None) -> dict:
    """One design's row (see the module docstring), its result file written. Never raises for the design's own
    faults: they are its row's status and message."""
    from swiftfin.design_rules import RuleContext, Severity, run_rules
    from swiftfin.design_rules.rules import mass_properties_from_json
    from swiftfin.layout.design import load_design

    t0 = time.perf_counter()
    row = dict.fromkeys(COLUMNS, "")
    row.update(design=name, params_file=path, stage=stage, status="ok")
    try:
        row["params_sha256"] = _sha256(path)
        p = load_design(path)
        mp, records = None, None
        if stage == "build":
            from swiftfin.cache import FamilyCache
            from swiftfin.pipeline import build
            os.environ["SWIFTFIN_JOBS"] = "1"      # one core per task: the cluster spreads the designs
            out = Path(out_root) / "builds" / name
            build(path, out, cache=FamilyCache(cache_dir))
            raw = json.loads((out / "mass_properties.json").read_text(encoding="utf-8"))
            mp = mass_properties_from_json(raw)
            if mp is not None:
                row["total_mass_kg"] = mp.total_mass_kg
                row["displaced_volume_l"] = mp.displaced_volume_m3 * 1e3
            from swiftfin.design_rules.printing import records_from_manifest
            man = out / "manifest.json"
            _, records = records_from_manifest(json.loads(man.read_text(encoding="utf-8")), str(man))
        findings = run_rules(RuleContext(p, mass_properties=mp, print_records=records))
        sev = [f.severity for f in findings]
        row.update(verdict=max(sev).name, n_pass=sev.count(Severity.PASS), n_info=sev.count(Severity.INFO),
                   n_warn=sev.count(Severity.WARN),
                   n_fail=sev.count(Severity.FAIL),
                   failing=";".join(f.rule_id for f in findings if f.severity == Severity.FAIL))
    except ParamError as exc:
        row.update(status="refused", message=str(exc))
    except (UserError, BuildError) as exc:
        row.update(status="failed", message=str(exc))
    except Exception as exc:  # noqa: BLE001 - a task reports, it does not take the sweep down
        row.update(status="error", message=f"{type(exc).__name__}: {exc}")
    row["wall_s"] = round(time.perf_counter() - t0, 3)
    write_text_atomic(Path(out_root) / "results" / f"{name}.json", json.dumps(row, indent=1) + "\n")
    return row


def done_row(out_root: str | Path, item: SweepItem, stage: str) -> dict | None:
    """The design's stored row when it is of the same file bytes and stage (and, for a build, its build is still
    there with a manifest of the same bytes); None when the design must run."""
    f = Path(out_root) / "results" / f"{item.name}.json"
    try:
        row = json.loads(f.read_text(encoding="utf-8"))
        sha = _sha256(item.path)
    except (OSError, ValueError):
        return None
    if row.get("params_sha256") != sha or row.get("stage") != stage:
        return None
    if stage == "build" and row.get("status") == "ok":
        try:
            manifest = json.loads((Path(out_root) / "builds" / item.name / "manifest.json").read_text())
        except (OSError, ValueError):
            return None
        if manifest.get("params_sha256") != sha:
            return None
    return row


def table_csv(rows: list[dict]) -> str:
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=COLUMNS, lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow({k: ("" if r.get(k) is None else r.get(k)) for k in COLUMNS})
    return buf.getvalue()


def sweep(items: list[SweepItem], out_root: str | Path, stage: str = "check", scheduler: str | None = None,
          workers: int | None = None, cache_dir: str | None = None, progress=None) -> tuple[list[dict], int]:
    """Every design's row, in the order of ``items``, and how many ran now (the others were done before). The
    designs still to do run as Dask tasks: on ``scheduler`` (an address) or on a LocalCluster of ``workers``
    processes (default: one per core), one thread each."""
    if stage not in STAGES:
        raise UserError(f"--stage {stage!r}: expected one of {', '.join(STAGES)}")
    out_root = Path(out_root)
    say = progress or (lambda text: None)
    rows: dict[str, dict] = {}
    todo = []
    for it in items:
        r = done_row(out_root, it, stage)
        if r is None:
            todo.append(it)
        else:
            rows[it.name] = r
    say(f"{len(items)} designs: {len(items) - len(todo)} done before, {len(todo)} to run ({stage})")
    if todo:
        from distributed import Client, LocalCluster, as_completed
        cluster = None
        if scheduler:
            client = Client(scheduler)
        else:
            cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1, threads_per_worker=1, processes=True,
                                   host="127.0.0.1", dashboard_address="127.0.0.1:0")   # loopback, any free port
            client = Client(cluster)
        try:
            futures = {client.submit(run_design, it.path, it.name, str(out_root.absolute()), stage,
                                     None if cache_dir is None else str(Path(cache_dir).absolute()),
                                     key=f"swiftfin-{stage}-{it.name}-{_sha256(it.path)[:12]}", pure=False): it
                       for it in todo}
            t0 = time.perf_counter()
            done_bar = bar(len(todo), f"sweep ({stage})", "design")
            for n, fut in enumerate(as_completed(futures), 1):
                try:
                    r = fut.result()
                except Exception as exc:  # noqa: BLE001 - a lost worker: the row says so, the next run retries it
                    it = futures[fut]
                    r = dict.fromkeys(COLUMNS, "")
                    r.update(design=it.name, params_file=it.path, stage=stage, status="error",
                             message=f"the task was lost ({type(exc).__name__}: {exc}); run the sweep again")
                rows[r["design"]] = r
                say(f"[{n}/{len(todo)}] {r['design']}: {r['status']}"
                    + (f", {r['verdict']}" if r["status"] == "ok" else "") + f" ({time.perf_counter() - t0:.0f} s)")
                done_bar.update()
            done_bar.close()
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    ordered = [rows[it.name] for it in items]
    write_text_atomic(out_root / "results.csv", table_csv(ordered))
    return ordered, len(todo)
