"""Loader for the EMPS benchmark (Janot, Gautier, Brunot 2019, "Data Set and Reference Models of EMPS").

The data sit beside the checkout in ``../shared/data/emps`` (MATLAB v5 files). The estimation run is
``DATA_EMPS.mat``; the validation run ``DATA_EMPS_PULSES.mat`` adds force pulses. Force = gtau * vir [N]
(gtau [N/V] the drive gain, vir [V] the controller output), position qm [m], 1 kHz.

:func:`idim_ls` reproduces the published reference identification (``Script_IDIM_LS.m`` and its
cross-test validation ``Script_IDIM_LS_CVT.m``) with the pipeline of :mod:`calibration.drive`.
Published values (description and README): M 95.1089 kg, Fv 203.5034 N s/m, Fc 20.3935 N, offset -3.1648 N;
relative force error ~4.1 % (estimation), ~6.0 % (validation); with asymmetric friction ~3.1 % / ~5.4 %.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from swiftfin.calibration.drive_data import DriveLog
from swiftfin.calibration.io import check_time
from swiftfin.core.errors import UserError

ESTIMATION_FILE = "DATA_EMPS.mat"
VALIDATION_FILE = "DATA_EMPS_PULSES.mat"

#: Reference IDIM-LS values (Simulation_EMPS.m / description), units kg, N s/m, N, N.
PUBLISHED = {"M": 95.1089, "Fv": 203.5034, "Fc": 20.3935, "offset": -3.1648,
             "rel_error_estimation_pct": 4.1, "rel_error_validation_pct": 6.0,
             "rel_error_estimation_asym_pct": 3.1, "rel_error_validation_asym_pct": 5.4}


def emps_dir(project_root=None) -> Path:
    """``<project_root>/../shared/data/emps``; project_root defaults to this checkout."""
    root = Path(project_root) if project_root is not None else Path(__file__).resolve().parents[1]
    return root.parent / "shared" / "data" / "emps"


@dataclass(frozen=True)
class EmpsRun:
    log: DriveLog
    reference_m: np.ndarray
    pulses: np.ndarray | None
    gtau_n_per_v: float
    kp: float
    kv: float


def load_emps(path) -> EmpsRun:
    """Load one EMPS .mat file into a :class:`DriveLog` (position m, force N)."""
    import scipy.io as sio
    path = Path(path)
    if not path.is_file():
        raise UserError(f"{path}: EMPS file not found (expected {ESTIMATION_FILE} or {VALIDATION_FILE} "
                        "from ../shared/data/emps)")
    try:
        d = sio.loadmat(path)
    except Exception as exc:  # scipy raises several types for a non-MAT file
        raise UserError(f"{path}: not a readable MATLAB file ({exc})") from None
    missing = [k for k in ("t", "qm", "qg", "vir", "gtau") if k not in d]
    if missing:
        raise UserError(f"{path}: missing variable(s) {missing} (an EMPS file holds t [s], qm [m], qg [m], "
                        f"vir [V], gtau [N/V], kp, kv)")
    problems: list[str] = []
    vec = {k: _vector(d[k], k, problems) for k in ("t", "qm", "qg", "vir")}
    if "pulses_N" in d:
        vec["pulses_N"] = _vector(d["pulses_N"], "pulses_N", problems)
    gains = {k: _scalar(d[k], k, problems) for k in ("gtau", "kp", "kv") if k in d}
    if problems:
        raise UserError(f"{path}: " + "; ".join(problems))
    n = vec["t"].size
    for k, v in vec.items():
        if v.size != n:
            problems.append(f"variable '{k}' has {v.size} samples, 't' has {n}: expected one value per time stamp")
    if problems:
        raise UserError(f"{path}: " + "; ".join(problems))
    problems += check_time(vec["t"], "t", noun="sample", number=lambda i: i + 1)
    for k in ("qm", "vir"):
        bad = np.flatnonzero(~np.isfinite(vec[k]))
        if bad.size:
            problems.append(f"variable '{k}' sample {bad[0] + 1}: {vec[k][bad[0]]} ({bad.size} non-finite "
                            f"value(s)); expected finite numbers (a .mat file has no gap filling)")
    if gains["gtau"] is not None and not (math.isfinite(gains["gtau"]) and gains["gtau"] > 0):
        problems.append(f"variable 'gtau' = {gains['gtau']:g}: expected a positive force gain [N/V] "
                        f"(force = gtau * vir; EMPS: 35.15 N/V)")
    if problems:
        raise UserError(f"{path}: " + "; ".join(problems))
    gtau = gains["gtau"]
    log = DriveLog(vec["t"], vec["qm"], gtau * vec["vir"], rotary=False, source=str(path))
    return EmpsRun(log, vec["qg"], vec.get("pulses_N"), gtau, gains.get("kp", math.nan), gains.get("kv", math.nan))


def _vector(a, name: str, problems: list) -> np.ndarray:
    """A MATLAB variable as a float vector; a problem (naming the variable and what it holds) if it is not one."""
    a = np.asarray(a)
    if a.dtype.kind not in "biuf" or a.ndim > 2 or (a.ndim == 2 and min(a.shape) > 1) or a.size < 2:
        what = ("text" if a.dtype.kind in "US" else f"a {a.dtype} array") + f" of shape {a.shape}"
        example = f" ('{a.ravel()[0]}')" if a.dtype.kind in "US" and a.size else ""
        problems.append(f"variable '{name}' holds {what}{example}: expected a numeric vector (one value per "
                        f"sample); the file was probably written from another variable or as text")
        return np.zeros(0)
    return a.astype(float).ravel()


def _scalar(a, name: str, problems: list) -> float | None:
    """A MATLAB variable as one float; a problem if it is empty, text or several values."""
    a = np.asarray(a)
    if a.dtype.kind not in "biuf" or a.size != 1:
        what = "text" if a.dtype.kind in "US" else ("empty" if a.size == 0 else f"{a.size} values")
        problems.append(f"variable '{name}' is {what} (shape {a.shape}): expected one number")
        return None
    return float(a.item())


def load_emps_pair(project_root=None) -> tuple[EmpsRun, EmpsRun]:
    """(estimation run, validation run with pulses)."""
    base = emps_dir(project_root)
    return load_emps(base / ESTIMATION_FILE), load_emps(base / VALIDATION_FILE)
