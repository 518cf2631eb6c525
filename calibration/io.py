"""Reading measured logs (CSV) for calibration: columns declared by each family, checked before any fit.

A family declares the columns it needs as :class:`Column` (name with its unit suffix, unit, kind and a
plausible range); :func:`read_log` reads the CSV and checks, all at once where it can:

* the file exists and has a header; every required column is present (a misnamed one gets the closest name);
* every cell parses as a number (the message names the row and the column); no row has more cells than the
  header (a decimal comma, ``0,5``, would shift the columns);
* a UTF-8 byte-order mark before the header (Excel's "CSV UTF-8") is accepted;
* time stamps are finite and strictly increasing (duplicates and steps backwards are named by row);
* NaN gaps: a gap of at most ``max_gap_rows`` rows inside the record is filled by linear interpolation and
  reported in ``LogData.notes`` (the CLI prints them as warnings); longer gaps, or gaps at the ends, are refused
  with their rows;
* angles in a ``_rad`` column whose magnitude exceeds the column's ``max_abs`` but would fit once read as
  degrees are refused as "looks like degrees".

Rows are numbered as in a spreadsheet: the header is row 1, the first data row is row 2.
Every problem raises :class:`swiftfin.core.errors.UserError` (exit 2) naming the file, the column and the row.
Extra columns are allowed and ignored.
"""
from __future__ import annotations

import csv
import difflib
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from swiftfin.core.errors import UserError


@dataclass(frozen=True)
class Column:
    """A column a family needs.

    name : str        exact header name, unit in the name (``joint_angle_rad``).
    unit : str        its unit (``rad``, ``s``, ``m``, ``N``).
    kind : str        ``"time"``, ``"angle"`` (checked for degrees) or ``"value"``.
    max_abs : float   largest plausible magnitude (``inf``: no check). For angles in rad it is also the
                      degree-detection bound: values above it that fit below it once multiplied by pi/180
                      are reported as degrees.
    doc : str         meaning, for messages and the report.
    optional : bool   used when present, not required (a second sensor); checked like the others when there.
    """

    name: str
    unit: str
    kind: str = "value"
    max_abs: float = math.inf
    doc: str = ""
    optional: bool = False


@dataclass
class LogData:
    """A checked log: one float array per declared column (extra columns dropped)."""

    path: str
    columns: dict[str, np.ndarray]
    n: int
    notes: list[str] = field(default_factory=list)

    def __getitem__(self, name: str) -> np.ndarray:
        return self.columns[name]


def _row(i: int) -> int:
    """Spreadsheet row of data index i (header = row 1)."""
    return i + 2


def _ranges(idx: np.ndarray) -> list[tuple[int, int]]:
    """Consecutive runs of indices as (first, last)."""
    if idx.size == 0:
        return []
    br = np.flatnonzero(np.diff(idx) != 1)
    starts = np.r_[idx[0], idx[br + 1]]
    ends = np.r_[idx[br], idx[-1]]
    return list(zip(starts.tolist(), ends.tolist()))


def _fmt_rows(runs: list[tuple[int, int]], limit: int = 5) -> str:
    parts = [f"row {_row(a)}" if a == b else f"rows {_row(a)}-{_row(b)}" for a, b in runs[:limit]]
    more = f" and {len(runs) - limit} more" if len(runs) > limit else ""
    return ", ".join(parts) + more


def check_time(t: np.ndarray, name: str, noun: str = "row", number=_row) -> list[str]:
    """Problems of a time column: missing (NaN) or infinite stamps, duplicates, steps backwards; empty if fine.
    Data index i is named ``f"{noun} {number(i)}"`` (default: its spreadsheet row; a .mat file: ``sample i+1``)."""
    t = np.asarray(t, dtype=float)
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        runs = _ranges(bad)
        shown = ", ".join(f"{noun} {number(a)}" if a == b else f"{noun}s {number(a)}-{number(b)}" for a, b in runs[:5])
        more = f" and {len(runs) - 5} more" if len(runs) > 5 else ""
        return [f"column '{name}': missing time stamps at {shown}{more}"]
    problems = []
    dt = np.diff(t)
    dup = np.flatnonzero(dt == 0)
    back = np.flatnonzero(dt < 0)
    if dup.size:
        i = int(dup[0])
        problems.append(f"column '{name}': duplicated time stamp {t[i]:.9g} s at {noun}s {number(i)} and "
                        f"{number(i + 1)}" + (f" ({dup.size} duplicates)" if dup.size > 1 else ""))
    if back.size:
        i = int(back[0])
        problems.append(f"column '{name}': time goes backwards at {noun} {number(i + 1)} "
                        f"({t[i]:.9g} s -> {t[i + 1]:.9g} s)" + (f" ({back.size} times)" if back.size > 1 else ""))
    return problems


def read_log(path: str | Path, columns: tuple[Column, ...] | list[Column], *, max_gap_rows: int = 10,
             min_rows: int = 50, family: str = "") -> LogData:
    """Read and check a CSV log (see the module docstring). ``columns[0]`` must be the time column."""
    path = Path(path)
    what = f"{family} log " if family else ""
    if not path.exists():
        raise UserError(f"{what}{path}: file not found")
    if path.is_dir():
        raise UserError(f"{what}{path}: is a directory, expected a CSV file")
    try:
        with path.open(newline="", encoding="utf-8-sig") as fh:   # -sig: Excel's "CSV UTF-8" starts with a BOM
            rows = list(csv.reader(fh))
    except UnicodeDecodeError:
        raise UserError(f"{what}{path}: not a text CSV file") from None
    rows = [r for r in rows if r and not (len(r) == 1 and not r[0].strip())]
    if not rows:
        raise UserError(f"{what}{path}: empty file, expected a header "
                        f"'{','.join(c.name for c in columns)}' and data rows")
    header = [h.strip() for h in rows[0]]
    columns = [c for c in columns if not c.optional or c.name in header]
    missing = [c for c in columns if c.name not in header]
    if missing:
        msgs = []
        for c in missing:
            close = difflib.get_close_matches(c.name, header, n=1, cutoff=0.5)
            hint = f" (did you mean '{close[0]}'? rename it to '{c.name}')" if close else ""
            msgs.append(f"missing column '{c.name}' [{c.unit}]{hint}")
        raise UserError(f"{what}{path}: " + "; ".join(msgs) + f". Header found: {','.join(header)}; "
                        f"required: {','.join(c.name for c in columns if not c.optional)}")
    body = rows[1:]
    n = len(body)
    if n < min_rows:
        raise UserError(f"{what}{path}: {n} data rows, too short to identify anything (need at least {min_rows})")
    out: dict[str, np.ndarray] = {}
    problems: list[str] = []
    long_rows = [i for i, r in enumerate(body) if len(r) > len(header) and any(c.strip() for c in r[len(header):])]
    if long_rows:
        i = long_rows[0]
        problems.append(f"row {_row(i)}: {len(body[i])} cells but the header names {len(header)} columns "
                        f"({','.join(body[i])})" + (f" ({len(long_rows)} such rows)" if len(long_rows) > 1 else "")
                        + "; likely cause: a decimal comma (write 0.5, not 0,5) or a stray separator")
    for c in columns:
        j = header.index(c.name)
        a = np.empty(n)
        bad = []
        for i, r in enumerate(body):
            cell = r[j].strip() if j < len(r) else ""
            if cell == "" or cell.lower() in ("nan", "na", "null"):
                a[i] = np.nan
                continue
            try:
                a[i] = float(cell)
            except ValueError:
                bad.append((i, cell))
                a[i] = np.nan
        if bad:
            i, cell = bad[0]
            more = f" ({len(bad)} such cells)" if len(bad) > 1 else ""
            problems.append(f"column '{c.name}' row {_row(i)}: '{cell}' is not a number{more}")
        if np.isinf(a).any():
            i = int(np.flatnonzero(np.isinf(a))[0])
            problems.append(f"column '{c.name}' row {_row(i)}: infinite value")
            a[np.isinf(a)] = np.nan
        out[c.name] = a
    if problems:
        raise UserError(f"{what}{path}: " + "; ".join(problems))

    notes: list[str] = []
    tcol = columns[0]
    t = out[tcol.name]
    problems += check_time(t, tcol.name)
    for c in columns[1:]:
        a = out[c.name]
        nan = np.flatnonzero(np.isnan(a))
        if nan.size:
            runs = _ranges(nan)
            long = [(s, e) for s, e in runs if e - s + 1 > max_gap_rows or s == 0 or e == n - 1]
            if long:
                problems.append(f"column '{c.name}': {len(long)} gap(s) of missing values too long to fill "
                                f"(more than {max_gap_rows} rows, or at the start/end) at {_fmt_rows(long)}")
            elif not problems:
                good = ~np.isnan(a)
                out[c.name] = np.interp(t, t[good], a[good])
                notes.append(f"{path}: column '{c.name}': filled {nan.size} missing value(s) in {len(runs)} short "
                             f"gap(s) by linear interpolation at {_fmt_rows(runs)}")
        a = out[c.name]
        if c.kind == "angle" and c.unit == "rad" and math.isfinite(c.max_abs):
            finite = a[np.isfinite(a)]
            if finite.size:
                i = int(np.nanargmax(np.abs(a)))
                peak = float(abs(a[i]))
                if peak > c.max_abs:
                    if peak * math.pi / 180 <= c.max_abs:
                        problems.append(f"column '{c.name}' row {_row(i)}: value {a[i]:.4g} looks like degrees "
                                        f"(a {c.doc or 'angle'} in rad stays within +-{c.max_abs:.3g}); "
                                        f"convert to radians or check the column")
                    else:
                        problems.append(f"column '{c.name}' row {_row(i)}: value {a[i]:.4g} rad beyond the "
                                        f"plausible +-{c.max_abs:.3g} rad")
        elif c.kind != "time" and math.isfinite(c.max_abs):
            i = int(np.nanargmax(np.abs(a))) if np.isfinite(a).any() else 0
            if np.isfinite(a).any() and abs(a[i]) > c.max_abs:
                problems.append(f"column '{c.name}' row {_row(i)}: value {a[i]:.4g} {c.unit} beyond the plausible "
                                f"+-{c.max_abs:.3g} {c.unit}")
    if problems:
        raise UserError(f"{what}{path}: " + "; ".join(problems))
    return LogData(str(path), out, n, notes)


def write_log(path: str | Path, columns: dict[str, np.ndarray], fmt: str = "%.9g") -> None:
    """Write columns (in order) as a CSV with a header."""
    names = list(columns)
    data = np.column_stack([np.asarray(columns[k], float) for k in names])
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    np.savetxt(path, data, delimiter=",", header=",".join(names), comments="", fmt=fmt)


def split_holdout_arg(value: str | None) -> tuple[str | None, float | None]:
    """``--holdout`` is a file or a fraction in (0, 1). Returns (file, None) or (None, fraction)."""
    if value is None:
        return None, 0.3
    try:
        f = float(value)
    except ValueError:
        return value, None
    if not 0.0 < f < 1.0:
        raise UserError(f"--holdout {value}: a fraction must lie strictly between 0 and 1 (e.g. 0.3), "
                        f"or give a file")
    return None, f
