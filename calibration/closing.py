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
added_mass             ``added_inertia_kg_m2``                as fitted
quadratic_drag         ``drag_coefficient_nm_s2_rad2``        the effect's physical value (b = (b/K) K)
effective_radius       ``spool_radius_ratio``                 1 + ``ratio_error``
offset, sensor_delay,  ``sensor_offset_rad``,                 as fitted (recorded only)
capstan_creep,         ``sensor_delay_s``,
lost_steps             ``creep_per_travel``, ``slip_rad``
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

        def put(q: str, vs: tuple[float, float], into=joint) -> None:
            into[q] = Measured(vs[0], abs(vs[1]), name, conf)
        if name == "viscous_friction":
            c, sc = _p(e, "damping_nm_s_rad")
            put("hinge_damping_nm_s_rad", (bearing_damping_nm_s_rad + c, sc))
        elif name == "coulomb_friction":
            put("hinge_friction_nm", _gain_times(e, "friction_torque_nm"))
        elif name == "cable_compliance":
            put("joint_stiffness_nm_rad", _phys(e, "joint_stiffness_nm_rad"))
            put("cable.youngs_modulus_gpa", _phys(e, "effective_modulus_gpa"), design)
        elif name == "backlash":
            put("dead_band_rad", _gain_times(e, "gap_rad"))
        elif name == "cable_slack":
            put("dead_band_rad", _phys(e, "dead_band_rad"))
        elif name == "added_mass":
            put("added_inertia_kg_m2", _p(e, "added_inertia_kg_m2"))
        elif name == "quadratic_drag":
            put("drag_coefficient_nm_s2_rad2", _phys(e, "drag_coefficient_nm_s2_rad2"))
        elif name == "effective_radius":
            v, s = _p(e, "ratio_error")
            put("spool_radius_ratio", (1.0 + v, s))
        elif name == "offset":
            put("sensor_offset_rad", _p(e, "offset_rad"))
        elif name == "sensor_delay":
            put("sensor_delay_s", _p(e, "delay_s"))
        elif name == "capstan_creep":
            put("creep_per_travel", _p(e, "creep_per_travel"))
        elif name == "lost_steps":
            put("slip_rad", _p(e, "slip_rad"))
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
