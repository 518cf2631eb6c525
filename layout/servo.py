"""How a joint is driven, as numbers for the simulator files and the joint-log replay: the stepper's holding
stiffness seen at the joint through the capstan, the cable pair's stiffness, the joint's torque limit and the
rotor's reflected inertia, and :func:`joint_servo`, the drive of one joint with or without a bench measurement
(core.calibration). No CAD kernel: ``exports.robot_model`` writes these into the robot model and
``calibration.replay`` puts the same drive on a bench in MuJoCo.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swiftfin.core.schema import Params
from swiftfin.layout.geometry import cable_routes
from swiftfin.physics.capstan import cable_stiffness_n_m

UNCALIBRATED_DAMPING_NM_S_RAD = 1e-3
"""A hinge's viscous damping until a bench measures it (``swiftfin fit joint`` -> ``calibration.toml`` ->
``swiftfin build --calibration``) [N m s/rad]: a small placeholder, not a measurement. Engineering default."""
FRICTION_TIMECONST_S = 1e-3
"""Time constant of a measured hinge's dry friction in MuJoCo (``solreffriction``) [s]. MuJoCo's dry friction is a
soft constraint; its default 0.02 s lets a light link creep through the stuck band like a viscous damper, far from
the friction a bench measures (a replay of a bench log of 0.02 N m of hinge friction: 0.0060 rad of error with the
default against 0.0068 rad with no friction at all). Two steps of the MJCF's 0.5 ms, the stiffest MuJoCo allows
(its documentation: at least twice the time step)."""
SERVO_DERIVATIVE_TIME_S = 1.0 / (2 * math.pi * 50.0)
"""kv / kp of the joint position servo [s]: damping up to 50 Hz (the step loop is far faster than the wave)."""


def joint_stiffness_nm_rad(p: Params) -> float:
    """Small-angle stiffness of a stepper held in position, seen at the joint [N m/rad].

    A hybrid stepper's holding torque follows T = T_hold sin(pi/2 theta/theta_fs) (peak one full step from
    the detent), so its stiffness is T_hold pi / (2 theta_fs); the capstan multiplies a motor stiffness by
    (d_mount / r_spool)^2 at the joint.
    """
    fs = math.radians(p.motor.full_step_deg)
    ratio = p.joints.tendon_moment_arm_mm / (p.spool.drum_diameter_mm / 2)
    return p.motor.holding_torque_nm * math.pi / (2 * fs) * ratio**2


def in_series(*stiffnesses: float) -> float:
    """Springs in series: 1 / sum(1 / k) (an infinite one adds nothing)."""
    return 1.0 / sum(1.0 / k for k in stiffnesses)


def cable_route_length_m(p: Params, j: int) -> float:
    """Mean free length of joint ``j``'s (1-based) two cables [m]."""
    return float(np.mean([rt.length_mm for rt in cable_routes(p) if rt.joint == j - 1])) / 1000.0


def cable_side_stiffness_n_m(p: Params, length_m: float) -> float:
    """E A / L of one cable of the design over ``length_m`` [N/m]."""
    return cable_stiffness_n_m(p.cable.youngs_modulus_gpa * 1e9, p.cable.diameter_mm / 1000.0, length_m)


def cable_pair_stiffness_nm_rad(p: Params, j: int) -> float:
    """The design's pull-pull pair at joint ``j`` (1-based), seen at the joint: K = 2 (E A / L) d_mount^2 with L
    the mean route length of the joint's two cables [N m/rad]."""
    k = cable_side_stiffness_n_m(p, cable_route_length_m(p, j))
    return 2.0 * k * (p.joints.tendon_moment_arm_mm / 1000.0) ** 2


def drive_stiffness_nm_rad(p: Params, j: int) -> float:
    """The whole drive's stiffness at joint ``j`` (1-based): the cable pair in series with the stepper held at
    its step [N m/rad] (the stiffness the joint fit's base model uses, calibration/joint.py)."""
    return in_series(cable_pair_stiffness_nm_rad(p, j), joint_stiffness_nm_rad(p))


@dataclass(frozen=True)
class Servo:
    """A joint's drive in the simulators: hinge damping and dry friction, position servo gains."""
    damping_nm_s_rad: float
    friction_nm: float
    kp_nm_rad: float
    kv_nm_s_rad: float
    armature_kg_m2: float


def joint_servo(p: Params, j: int, measured=None) -> Servo:
    """Joint ``j``'s (1-based) drive. Without a measurement (``measured``: a core.calibration.JointCalibration or
    None): the stepper's holding stiffness as a position servo with a derivative up to 50 Hz, the cable rigid, the
    rotor's reflected inertia on the hinge, a placeholder hinge damping. With one, the model the joint fit measured
    it with (calibration/joint.py): the commanded angle drives the hinge through one stiffness, the measured one
    (the whole drive's, stepper and cables in series, as the fit sees it between command and joint; else the
    design's cable pair in series with the stepper, which the fit's base model assumed and the log did not
    contradict), the measured hinge damping as the only damping (kv = 0: the fit's damping is all the damping the bench saw), the measured dry
    friction, and no armature: the rotor sits behind the cable, not on the hinge.

    Measured on replays of simulated bench logs (calibration.replay): the rotor's reflected inertia on the hinge of a
    bench with 10 x softer cables left 0.0096 rad of error against 0.0012 rad without it; the measured stiffness put
    in series with the stepper's a second time, 0.0117 rad against the noise floor's 0.0013 on a heavy link whose
    resonance sits near the command's 14 Hz."""
    kp = joint_stiffness_nm_rad(p)
    if measured is None:
        return Servo(UNCALIBRATED_DAMPING_NM_S_RAD, 0.0, kp, kp * SERVO_DERIVATIVE_TIME_S, reflected_armature_kg_m2(p))
    drive = measured.get("joint_stiffness_nm_rad")
    return Servo(measured.get("hinge_damping_nm_s_rad", UNCALIBRATED_DAMPING_NM_S_RAD),
                 measured.get("hinge_friction_nm", 0.0),
                 drive if drive is not None else drive_stiffness_nm_rad(p, j), 0.0, 0.0)


def joint_torque_limit_nm(p: Params) -> float:
    """Joint torque at the motor's holding torque: tau_motor * d_mount / r_spool (cable tension x arm)."""
    return p.motor.holding_torque_nm * p.joints.tendon_moment_arm_mm / (p.spool.drum_diameter_mm / 2)


def reflected_armature_kg_m2(p: Params) -> float:
    """Rotor inertia seen at the joint: J_rotor (d_mount / r_spool)^2 (the spool turns d/r times the joint)."""
    ratio = p.joints.tendon_moment_arm_mm / (p.spool.drum_diameter_mm / 2)
    return p.motor.rotor_inertia_kg_m2 * ratio**2


