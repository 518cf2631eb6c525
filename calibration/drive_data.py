"""A drive log and its inverse-dynamics pre-processing (IDIM-LS: Butterworth filtfilt, central differences,
decimation), shared by the drive family (:mod:`swiftfin.calibration.drive`) and the EMPS reader
(:mod:`swiftfin.calibration.emps`)."""
from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy import signal

from swiftfin.calibration.io import Column, read_log
from swiftfin.core.errors import UserError




@dataclass(frozen=True)
class DriveLog:
    """A raw drive record. ``position`` in m (or rad if ``rotary``), ``force`` in N (or N m)."""
    time_s: np.ndarray
    position: np.ndarray
    force: np.ndarray
    rotary: bool = False
    source: str = ""

    @property
    def sample_rate_hz(self) -> float:
        return 1.0 / float(np.median(np.diff(self.time_s)))

    @property
    def units(self) -> dict:
        if self.rotary:
            return {"position": "rad", "velocity": "rad/s", "acceleration": "rad/s^2", "force": "N m",
                    "inertia": "kg m^2"}
        return {"position": "m", "velocity": "m/s", "acceleration": "m/s^2", "force": "N", "inertia": "kg"}


LINEAR_COLUMNS = (Column("time_s", "s", "time", doc="time stamp"),
                  Column("position_m", "m", doc="measured position of the load"),
                  Column("force_n", "N", doc="force applied by the actuator"))
ROTARY_COLUMNS = (Column("time_s", "s", "time", doc="time stamp"),
                  Column("position_rad", "rad", doc="measured angle of the load"),
                  Column("torque_nm", "N m", doc="torque applied by the actuator"))


def read_drive_csv(path, notes: list | None = None) -> DriveLog:
    """Read a ``drive`` CSV (linear or rotary, chosen by the header) with the checks of
    :func:`calibration.io.read_log` (columns, numbers, time stamps, NaN gaps; errors name file, column, row)."""
    path = Path(path)
    header: list[str] = []
    try:
        with path.open(newline="", encoding="utf-8-sig") as fh:
            header = [h.strip() for h in next(csv.reader(fh), [])]
    except (OSError, UnicodeDecodeError):
        pass  # read_log reports missing / unreadable files
    rotary = "position_rad" in header or "torque_nm" in header
    cols = ROTARY_COLUMNS if rotary else LINEAR_COLUMNS
    log = read_log(path, cols, family="drive")
    if notes is not None:
        notes.extend(log.notes)
    return DriveLog(log[cols[0].name], log[cols[1].name], log[cols[2].name], rotary=rotary, source=str(path))


@dataclass(frozen=True)
class InverseDynamicsData:
    """Filtered, differentiated and decimated signals, ready for a linear inverse-dynamics fit."""
    time_s: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    force: np.ndarray
    cutoff_hz: float
    decimation: int
    rotary: bool = False
    source: str = ""

    def __len__(self) -> int:
        return len(self.force)


def inverse_dynamics_data(log: DriveLog, cutoff_hz: float | None = None, decimation: int | None = None,
                          filter_order: int = 4, border: int = 49) -> InverseDynamicsData:
    """The IDIM-LS pre-processing (see module docstring). ``cutoff_hz`` default fs/10; ``decimation``
    default round(fs / cutoff_hz). Columns are decimated after the nonlinear regressors are formed, so this
    keeps the *undecimated* signals needed to build them: see :func:`regressor_columns`."""
    fs = log.sample_rate_hz
    cutoff = fs / 10.0 if cutoff_hz is None else float(cutoff_hz)
    if not 0.0 < cutoff < fs / 2.0:
        raise UserError(f"{log.source}: filter cutoff {cutoff} Hz must lie in (0, {fs / 2:g}) Hz "
                        f"(sample rate {fs:g} Hz)")
    q_dec = int(round(fs / cutoff)) if decimation is None else int(decimation)
    if len(log.time_s) < 3 * (border + 30 * max(q_dec, 1)):
        raise UserError(f"{log.source}: {len(log.time_s)} samples are too few to filter, differentiate and "
                        f"decimate by {q_dec}")
    dt = 1.0 / fs
    b, a = signal.butter(filter_order, cutoff / (fs / 2.0))
    q_f = signal.filtfilt(b, a, log.position)
    dq = np.gradient(q_f, dt)
    ddq = np.gradient(dq, dt)
    s = slice(border, None)
    return InverseDynamicsData(log.time_s[s], q_f[s], dq[s], ddq[s], log.force[s], cutoff, max(q_dec, 1),
                               log.rotary, log.source)


def decimate_columns(a: np.ndarray, q: int) -> np.ndarray:
    """Decimate each column (or a vector) as MATLAB ``decimate`` does: order-8 Chebyshev-I, zero phase."""
    a = np.asarray(a, dtype=float)
    if q <= 1:
        return a
    return signal.decimate(a, q, ftype="iir", axis=0, zero_phase=True)
