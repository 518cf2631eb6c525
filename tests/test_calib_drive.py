"""The ``drive`` family on synthetic logs with known parameters (before any real data), and its input checks."""
from __future__ import annotations

import numpy as np
import pytest

from swiftfin.calibration.drive import (DriveModel, EFFECTS, FAMILY, inverse_dynamics_data, load, read_drive_csv,
                               relative_error_pct)
from swiftfin.core.errors import UserError

FS = 1000.0


def _trajectory(seconds=30.0, seed=0):
    """Smooth position [m] with reversals and several speeds (content below 3 Hz), and its exact derivatives."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, seconds, 1.0 / FS)
    q = np.zeros_like(t)
    v = np.zeros_like(t)
    a = np.zeros_like(t)
    for f, amp in zip([0.11, 0.37, 0.83, 1.9, 2.7], [0.08, 0.03, 0.012, 0.004, 0.002]):
        ph = rng.uniform(0, 2 * np.pi)
        w = 2 * np.pi * f
        q += amp * np.sin(w * t + ph)
        v += amp * w * np.cos(w * t + ph)
        a += -amp * w**2 * np.sin(w * t + ph)
    return t, q, v, a


def _write(path, t, q, F, rotary=False):
    names = ("time_s", "position_rad", "torque_nm") if rotary else ("time_s", "position_m", "force_n")
    np.savetxt(path, np.column_stack([t, q, F]), delimiter=",", header=",".join(names), comments="", fmt="%.10g")
    return path


TRUE = {"M": 80.0, "Fv": 150.0, "Fc": 15.0, "F0": -4.0, "dFv": 60.0}


def _force(t, q, v, a, effects=("viscous", "coulomb", "offset"), noise=0.5, seed=1):
    F = TRUE["M"] * a
    if "viscous" in effects:
        F = F + TRUE["Fv"] * v
    if "coulomb" in effects:
        F = F + TRUE["Fc"] * np.sign(v)
    if "offset" in effects:
        F = F + TRUE["F0"]
    if "asym" in effects:
        F = F + TRUE["dFv"] * v * (v < 0)
    if "stribeck" in effects:
        F = F + 10.0 * np.sign(v) * np.exp(-(np.abs(v) / 0.01) ** 2)
    return F + noise * np.random.default_rng(seed).standard_normal(t.size)


def test_recovers_known_parameters_on_synthetic(tmp_path):
    t, q, v, a = _trajectory()
    path = _write(tmp_path / "drive.csv", t, q, _force(t, q, v, a, ("viscous", "coulomb", "offset", "asym")))
    d = inverse_dynamics_data(read_drive_csv(path))
    assert d.cutoff_hz == pytest.approx(100.0, rel=1e-6) and d.decimation == 10
    m = DriveModel(("viscous_friction", "coulomb_friction", "offset", "asymmetric_friction")).fit(d)
    c, s = m.coef_, m.stderr_
    assert c["inertia.M"] == pytest.approx(TRUE["M"], rel=0.01)
    assert c["viscous_friction.Fv"] == pytest.approx(TRUE["Fv"], rel=0.01)
    assert c["coulomb_friction.Fc"] == pytest.approx(TRUE["Fc"], rel=0.03)
    assert c["offset.F0"] == pytest.approx(TRUE["F0"], abs=0.3)
    assert c["asymmetric_friction.dFv_neg"] == pytest.approx(TRUE["dFv"], rel=0.03)
    # the stated uncertainty covers the error (within 4 sigma; noise is white here)
    for k, true in (("inertia.M", TRUE["M"]), ("viscous_friction.Fv", TRUE["Fv"])):
        assert abs(c[k] - true) < 4 * s[k] + 1e-3 * true
    assert not m.implausible()


def test_stribeck_velocity_found_by_search(tmp_path):
    t, q, v, a = _trajectory(seed=3)
    path = _write(tmp_path / "s.csv", t, q, _force(t, q, v, a, ("viscous", "coulomb", "stribeck"), noise=0.2))
    d = inverse_dynamics_data(read_drive_csv(path))
    m = DriveModel(("viscous_friction", "coulomb_friction", "stribeck")).fit(d)
    assert m.nonlinear_["vs"] == pytest.approx(0.01, rel=0.15)
    assert m.coef_["stribeck.Fs"] == pytest.approx(10.0, rel=0.15)


def test_engine_selects_the_injected_effects(tmp_path):
    """Forward selection on a synthetic log with viscous + Coulomb + offset: those three and nothing else."""
    from swiftfin.calibration.engine import Calibrator
    t, q, v, a = _trajectory(seconds=40.0, seed=5)
    F = _force(t, q, v, a, ("viscous", "coulomb", "offset"))
    tr = load(_write(tmp_path / "tr.csv", t, q, F))
    t2, q2, v2, a2 = _trajectory(seconds=20.0, seed=6)
    ho = load(_write(tmp_path / "ho.csv", t2, q2, _force(t2, q2, v2, a2, ("viscous", "coulomb", "offset"), seed=7)))
    cal = Calibrator(FAMILY, max_effects=5).fit(tr, ho)
    assert {e.name for e in cal.added_effects_} == {"viscous_friction", "coulomb_friction", "offset"}
    vals = {k: v for e in cal.added_effects_ for k, v in e.values.items()}
    assert vals["Fv_n_s_m"] == pytest.approx(TRUE["Fv"], rel=0.02)
    assert vals["Fc_n"] == pytest.approx(TRUE["Fc"], rel=0.05)
    assert vals["F0_n"] == pytest.approx(TRUE["F0"], abs=0.3)
    # held-out error down to the noise (0.5 N white, somewhat reduced by the decimation filter)
    assert cal.final_["rmse_holdout"] < 0.5
    assert relative_error_pct(ho.y, cal.predict(ho)) < 1.0


def test_rotary_header_and_units(tmp_path):
    t, q, v, a = _trajectory(seconds=10.0)
    log = read_drive_csv(_write(tmp_path / "r.csv", t, q, _force(t, q, v, a), rotary=True))
    assert log.rotary and log.units["force"] == "N m" and log.units["inertia"] == "kg m^2"


def test_effect_library_is_complete():
    names = {e.name for e in FAMILY.effects}
    assert names == {"viscous_friction", "coulomb_friction", "asymmetric_friction", "stribeck", "offset",
                     "position_dependent", "cubic_stiffness"} == set(EFFECTS)
    for e in FAMILY.effects:
        assert e.meaning and e.fingerprint


def test_bad_input_named(tmp_path):
    p = tmp_path / "bad.csv"
    p.write_text("time_s,position_m,forse_n\n" + "\n".join(f"{i * 1e-3},0,0" for i in range(100)))
    with pytest.raises(UserError, match="force_n"):
        read_drive_csv(p)
    p.write_text("time_s,position_m,force_n\n" + "\n".join(f"{min(i, 50) * 1e-3},{i},0" for i in range(100)))
    with pytest.raises(UserError, match="time_s"):
        read_drive_csv(p)
    t = np.arange(0, 5, 1e-3)
    flat = _write(tmp_path / "flat.csv", t, np.zeros_like(t), np.zeros_like(t))
    with pytest.raises(UserError, match="position_m"):
        load(flat)
