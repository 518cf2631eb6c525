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

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from swiftfin.calibration.drive_data import DriveLog
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
        raise UserError(f"{path}: missing variable(s) {missing}")
    t, qm, vir = (np.asarray(d[k], dtype=float).ravel() for k in ("t", "qm", "vir"))
    gtau = float(np.asarray(d["gtau"]).item())
    pulses = np.asarray(d["pulses_N"], dtype=float).ravel() if "pulses_N" in d else None
    log = DriveLog(t, qm, gtau * vir, rotary=False, source=str(path))
    return EmpsRun(log, np.asarray(d["qg"], dtype=float).ravel(), pulses, gtau,
                   float(np.asarray(d["kp"]).item()), float(np.asarray(d["kv"]).item()))


def load_emps_pair(project_root=None) -> tuple[EmpsRun, EmpsRun]:
    """(estimation run, validation run with pulses)."""
    base = emps_dir(project_root)
    return load_emps(base / ESTIMATION_FILE), load_emps(base / VALIDATION_FILE)
