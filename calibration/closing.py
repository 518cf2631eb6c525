"""Close the loop (issue 14, item 4): the physical values a joint fit found, as a calibration file
(:mod:`swiftfin.core.calibration`) that ``swiftfin build`` and ``swiftfin check`` read back.

From the fit report's effects (``fit_report.json``'s ``added_effects``, each with its fitted parameters and
their standard errors) to the robot's quantities:

=====================  =====================================  ==================================================
effect                 quantity                               value
=====================  =====================================  ==================================================
viscous_friction       ``hinge_damping_nm_s_rad``             the bench's bearing damping (the bench file's, else
                                                              :data:`~swiftfin.calibration.joint.BENCH_BEARING_DAMPING_NM_S_RAD`)
                                                              plus the fitted ``damping_nm_s_rad``; without the
                                                              effect, the bearing damping alone (low confidence)
coulomb_friction       ``hinge_friction_nm``                  ``gain x friction_torque_nm`` (the play operator's
                                                              half-width is gain tau_c / K)
cable_compliance       ``joint_stiffness_nm_rad``;            the effect's own physical values
                       design ``cable.youngs_modulus_gpa``
backlash               ``dead_band_rad``                      ``gain x gap_rad``
cable_slack            ``dead_band_rad``                      twice the fitted slack (lost pretension: re-tension)
added_mass             ``added_inertia_kg_m2``                the effect's physical value (signed: J - J_prior)
quadratic_drag         ``drag_coefficient_nm_s2_rad2``        the effect's physical value (b as fitted)
effective_radius       ``spool_radius_ratio``                 1 + ``ratio_error``
offset, sensor_delay,  ``sensor_offset_rad``,                 as fitted (recorded only)
capstan_creep,         ``sensor_delay_s``,
lost_steps             ``creep_per_travel``, ``slip_rad``
stepper_torque         ``motor_holding_torque_nm``            the effect's physical value (recorded)
=====================  =====================================  ==================================================

An effect the fit named at low confidence, or as indistinguishable from another, is written with that
confidence, so that a reader of the file sees it; the commands apply every value in the file.
"""
from __future__ import annotations

import math
from pathlib import Path

from swiftfin.calibration.joint import BENCH_BEARING_DAMPING_NM_S_RAD
from swiftfin.core.calibration import Calibration, JointCalibration, Measured, sha256_file


def _p(e: dict, name: str) -> tuple[float, float]:
    v = e["params"][name]
    return float(v["value"]), float(v["std"])


def _phys(e: dict, name: str) -> tuple[float, float]:
    v = e["physical"][name]
    return float(v["value"]), float(v["std"])


def _gain_times(e: dict, name: str) -> tuple[float, float]:
    """gain x value, its standard error by first-order propagation (independent errors)."""
    g, sg = _p(e, "gain") if "gain" in e["params"] else (1.0, 0.0)
    v, sv = _p(e, name)
    return g * v, math.hypot(g * sv, v * sg)


def _confidence(e: dict) -> str:
    c = str(e.get("confidence", "low"))
    return "low" if e.get("indistinguishable_from") else (c if c in ("high", "medium", "low") else "low")


#: effect -> [(quantity, how its value and standard error come from the fitted effect)], the table of the module
#: docstring; a quantity named ``section.key`` is a design key the measurement revises. Hinge damping is handled
#: apart (the bench's bearing damping plus the fit's term).
MAPPING: dict[str, tuple[tuple[str, object], ...]] = {
    "coulomb_friction": (("hinge_friction_nm", lambda e: _gain_times(e, "friction_torque_nm")),),
    "cable_compliance": (("joint_stiffness_nm_rad", lambda e: _phys(e, "joint_stiffness_nm_rad")),
                         ("cable.youngs_modulus_gpa", lambda e: _phys(e, "effective_modulus_gpa"))),
    "backlash": (("dead_band_rad", lambda e: _gain_times(e, "gap_rad")),),
    "cable_slack": (("dead_band_rad", lambda e: _phys(e, "dead_band_rad")),),
    "added_mass": (("added_inertia_kg_m2", lambda e: _phys(e, "added_inertia_kg_m2")),),
    "quadratic_drag": (("drag_coefficient_nm_s2_rad2", lambda e: _phys(e, "drag_coefficient_nm_s2_rad2")),),
    "effective_radius": (("spool_radius_ratio", lambda e: (1.0 + _p(e, "ratio_error")[0], _p(e, "ratio_error")[1])),),
    "offset": (("sensor_offset_rad", lambda e: _p(e, "offset_rad")),),
    "sensor_delay": (("sensor_delay_s", lambda e: _p(e, "delay_s")),),
    "capstan_creep": (("creep_per_travel", lambda e: _p(e, "creep_per_travel")),),
    "lost_steps": (("slip_rad", lambda e: _p(e, "slip_rad")),),
    "stepper_torque": (("motor_holding_torque_nm", lambda e: _phys(e, "holding_torque_nm")),),
}


def joint_values(report: dict, bearing_damping_nm_s_rad: float = BENCH_BEARING_DAMPING_NM_S_RAD
                 ) -> tuple[dict[str, Measured], dict[str, Measured]]:
    """(the joint's measured quantities, the design keys they revise) from a joint fit's report.
    ``bearing_damping_nm_s_rad``: the bench's bare-hinge damping the fit's base model assumed (the bench file's).

    Without a viscous effect the hinge damping is that bearing damping, written as ``effect = "bench_bearing"``
    at low confidence: the base model assumed it and the log did not ask for more, which is weaker evidence than a
    fitted value, but a better value than the simulators' placeholder (a replay with the placeholder instead rang
    5 x too damped on a bench with a soft cable)."""
    joint: dict[str, Measured] = {"hinge_damping_nm_s_rad": Measured(bearing_damping_nm_s_rad, 0.0, "bench_bearing",
                                                                     "low")}
    design: dict[str, Measured] = {}
    for e in report.get("added_effects", []):
        name, conf = e["name"], _confidence(e)
        if name == "viscous_friction":
            c, sc = _p(e, "damping_nm_s_rad")
            joint["hinge_damping_nm_s_rad"] = Measured(bearing_damping_nm_s_rad + c, abs(sc), name, conf)
        for quantity, get in MAPPING.get(name, ()):
            v, sv = get(e)
            (design if "." in quantity else joint)[quantity] = Measured(v, abs(sv), name, conf)
    return joint, design


def calibration_from_report(report: dict, joint: int, log: str | Path, design_file: str | Path | None,
                            report_file: str | Path | None = None,
                            bearing_damping_nm_s_rad: float = BENCH_BEARING_DAMPING_NM_S_RAD) -> Calibration:
    """The calibration a joint fit's ``report`` gives for ``joint`` (1-based) of the design, with the log's and
    the design file's SHA-256 so that a reader knows what it was measured on."""
    values, design = joint_values(report, bearing_damping_nm_s_rad)
    src = {"log": str(log), "log_sha256": sha256_file(log)}
    if design_file is not None:
        src |= {"design": str(design_file), "design_sha256": sha256_file(design_file)}
    if report_file is not None:
        src["fit_report"] = str(report_file)
    if not report.get("added_effects"):
        src["note"] = "the fit added no effect: the design's model already explains the log"
    return Calibration(src, (JointCalibration(joint, values),), design)
