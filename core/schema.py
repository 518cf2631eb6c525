"""The parameter schema: every free parameter of a design, with its unit, range, default and source.

The default of every field is the paper's SwiftFin (``../shared/paper/swiftfin_paper.txt``) where the paper
gives a value, and a documented engineering default where it does not. ``swiftfin.toml`` at the repository
root is generated from this table (``swiftfin params --dump``) and a test keeps the two identical.

Names carry units (house style rule 3): ``_mm``, ``_deg``, ``_n``, ``_nm``, ``_kg``, ``_hz`` ...;
a name without a unit suffix is dimensionless.

Derived values (the joints' maximum angle, the groove length, the motor positions ...) are functions in
the layers that use them, never fields here (house style rule 2).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from swiftfin.catalogues.cables import cable_names
from swiftfin.catalogues.fasteners import dowel_diameters_mm, screw_diameters_mm
from swiftfin.catalogues.materials import material_names
from swiftfin.catalogues.motors import motor_names

SCREWS = screw_diameters_mm()      # the thread sizes of catalogues/fasteners.toml (M2, M2.5, M3, M4)
DOWELS = dowel_diameters_mm()      # the pin diameters of catalogues/pins.toml (ISO 8734)


def p(default: Any, lo: float | None = None, hi: float | None = None, doc: str = "", source: str = "",
      choices: tuple | None = None, length: tuple[int, int] | None = None) -> Any:
    """A schema field: default, inclusive range [lo, hi], a one-line doc and its source.

    ``choices`` restricts a string; ``length`` bounds the length of a list field.
    """
    meta = {"lo": lo, "hi": hi, "doc": doc, "source": source, "choices": choices, "length": length}
    return field(default=default, metadata=meta)


PAPER = "SwiftFin paper"

CUSTOM = "custom"
"""A section's ``model`` when it names no catalogue entry: every key from the file or its default."""


def _model_doc(table: str, section: str) -> str:
    return (f"A catalogue entry (catalogues/{table}) whose numbers fill the [{section}] keys this file leaves out; "
            f"a key given beside it must equal the entry's ('{CUSTOM}': no entry, every key from the file or its "
            f"default)")


@dataclass(frozen=True)
class Body:
    length_mm: float = p(520.0, 200.0, 2000.0,
                         "Fork length: nose tip to the fork of the caudal fin (the NACA chord)",
                         f"{PAPER} Table 2 (52 cm); read as fork length, the usual fish measure")
    naca_thickness_fraction: float = p(0.15, 0.06, 0.30,
                                       "Maximum hull width / length of the NACA 00xx profile (at 30 % of length)",
                                       f"{PAPER} Table 2 (NACA 0015)")
    height_to_width: float = p(1.6, 0.6, 2.5,
                               "Height / width of the elliptical cross-sections",
                               "Not in the paper; yellowfin depth/width ~1.4-1.6. 1.45 is the least that holds 4 "
                               "NEMA 17 stacks (motor + spool, 61 mm tall); 1.6 because the sealed head must float the "
                               "buildable fish (at 1.5 its dry compartment, which ends at a wall ahead of joint 1's "
                               "clevis, leaves it 64 g heavy)")
    nose_cap_fraction: float = p(0.03, 0.01, 0.10,
                                 "Length of the rounded (ellipsoidal) nose cap / body length",
                                 "Not in the paper; closes the NACA leading edge smoothly")
    hull_end_fraction: float = p(0.915, 0.80, 0.98,
                                 "Station where the hull ends and the caudal fin root begins / body length",
                                 "Not in the paper; tuna peduncle ends at about 0.9 fork length")


@dataclass(frozen=True)
class Hull:
    wall_thickness_mm: float = p(2.0, 0.8, 6.0, "Hull shell wall thickness", "Engineering default (>= 2 line widths)")
    bulkhead_thickness_mm: float = p(3.0, 1.2, 8.0, "Thickness of the bulkheads closing each segment",
                                     "Engineering default")
    loft_stations: int = p(9, 4, 40, "Cross-sections per hull segment used by the loft",
                           "Engineering default (hull half-width error < 0.05 mm at 9)")
    split_halves: bool = p(True, doc="Split each hull segment into upper and lower halves at z = 0 "
                                     "(flat print face, assembly access); false is refused: a whole head "
                                     "encloses the screws of its motors and spools", source="Engineering default")
    screw_diameter_mm: float = p(2.0, min(SCREWS), max(SCREWS), "Screws joining hull halves and bulkheads (M2)",
                                 "Engineering default; sizes of catalogues/fasteners.toml", choices=SCREWS)
    flooded_from_joint: int = p(1, 1, 9, "Hull segments behind this joint are free-flooding: water enters through "
                                "their bulkhead cable holes and a vent at the top and bottom; ahead of it the "
                                "hull is sealed (joints.count + 1: all sealed)",
                                "Design choice: cables cross every tail bulkhead, so the tail cannot stay dry; "
                                "the head is dry, its cables leave through the PTFE tubes potted in its rear "
                                "bulkhead")
    vent_hole_diameter_mm: float = p(4.0, 1.5, 12.0, "Vent holes at the top and bottom of each flooded segment "
                                     "(air out at the top, water in at the bottom)", "Engineering default")
    seam_screw_spacing_mm: float = p(40.0, 10.0, 200.0, "Largest spacing along the body of the screws joining the "
                                     "upper and lower hull halves (on each side, +y and -y)",
                                     "Engineering default: M2 into inserts every 30-50 mm keeps a 2 mm PLA rim "
                                     "closed (flange bolt pitch <= 10-20 wall thicknesses, VDI 2230 practice)")
    splice_fit_clearance_mm: float = p(0.1, 0.0, 0.5, "Gap between a station splice's tab and the pad of the rear "
                                       "piece it slides under (the splice screw closes it)",
                                       "FDM close fit 0.05-0.15 mm per side (Prusa knowledge base, 'Tolerances'); "
                                       "0.1 chosen")
    seam_dowel_diameter_mm: float = p(2.0, min(DOWELS), max(DOWELS), "Dowel pins aligning the hull halves (one on "
                                      "each side of every piece, ISO 8734, in reamed bores)",
                                      "Engineering default; sizes of catalogues/pins.toml", choices=DOWELS)
    cable_gland_length_mm: float = p(14.0, 2.0, 60.0, "Packed length of each cable's gland through the dry "
                                     "compartment's rear wall, which is this thick (plus the tube seat's shoulder): "
                                     "the PTFE tube, potted in the wall, holds a close PTFE sleeve packed with grease "
                                     "round the cable",
                                     "Design: the cable's stroke (moment arm x stop angle, 10 mm at joint 4) plus the "
                                     "grease plug that holds the design depth (catalogues/seals.toml); the wall's "
                                     "front face then stands just behind the bay guide")
    drive_bay_length_mm: float = p(45.0, 20.0, 200.0, "From the rear motor's aft face to joint 1's axis: the room "
                                   "behind the motor row for the bay guide's bends, the dry compartment's rear wall "
                                   "(as thick as its glands) and joint 1's clevis; more moves the motors forward",
                                   "Design: the bay guide's drop and turn (5/8 of a guide bend radius behind the "
                                   "motor), the 14 mm glands and the clevis room fit with 0.28 mm to spare")


@dataclass(frozen=True)
class Joints:
    count: int = p(4, 1, 8, "Number of tail joints (one stepper each)", f"{PAPER} Table 2 (4 DOF)")
    stations_fraction: tuple = p((0.555, 0.62, 0.695, 0.765), 0.05, 0.95,
                                 "Joint axis stations / body length, nose to tail, strictly increasing",
                                 "Not in the paper; the motor row ahead of joint 1 and the 15 mm tendon sector "
                                 "inside the NACA 0015 tail bound them to about 0.52-0.76; joint 1 at 0.555 "
                                 "rather than the 0.545 the motors allow, so the built fish trims level (at "
                                 "0.545 its COM sits 3.5 mm ahead of its COB and no lead inside the hull "
                                 "levels it)",
                                 length=(1, 8))
    tendon_moment_arm_mm: float = p(15.0, 4.0, 60.0, "Radius of the tendon sector on each link (d_mount)",
                                    f"{PAPER} §3.4 (15 mm)")
    pin_diameter_mm: float = p(3.0, min(DOWELS), max(DOWELS), "Hinge pin diameter (ISO 8734 steel dowel)",
                               "Engineering default; sizes of catalogues/pins.toml", choices=DOWELS)
    stop_margin_deg: float = p(5.0, 0.0, 30.0,
                               "Hard stop beyond the largest joint angle the wave model demands",
                               "Engineering default")
    link_thickness_mm: float = p(6.0, 3.0, 20.0, "Height of the link plate (along the hinge axis)",
                                 "Engineering default")


@dataclass(frozen=True)
class Motor:
    model: str = p(CUSTOM, doc=_model_doc("motors.toml", "motor"), source="catalogues/motors.toml (sources per number)",
                   choices=(CUSTOM,) + motor_names())
    frame_size_mm: float = p(42.3, 20.0, 60.0, "Square frame size (NEMA 17 = 42.3 mm)", "NEMA ICS 16")
    body_length_mm: float = p(40.0, 15.0, 80.0, "Body length without shaft", "17HS4401 datasheet (40 mm)")
    shaft_diameter_mm: float = p(5.0, 2.0, 8.0, "Shaft diameter", "NEMA 17 (5 mm)")
    shaft_flat_depth_mm: float = p(0.5, 0.0, 1.5, "Depth of the D-flat on the shaft", "17HS4401 datasheet (0.5 mm)")
    shaft_length_mm: float = p(24.0, 8.0, 40.0, "Shaft length beyond the mounting face", "17HS4401 datasheet (24 mm)")
    pilot_diameter_mm: float = p(22.0, 10.0, 40.0, "Centring boss diameter", "NEMA 17 (22 mm)")
    pilot_height_mm: float = p(2.0, 0.0, 5.0, "Centring boss height", "NEMA 17 (2 mm)")
    hole_spacing_mm: float = p(31.0, 10.0, 50.0, "Mounting hole square spacing", "NEMA 17 (31 mm)")
    mount_screw_diameter_mm: float = p(3.0, min(SCREWS), max(SCREWS), "Mounting screws (M3)",
                                       "NEMA 17; sizes of catalogues/fasteners.toml", choices=SCREWS)
    mount_hole_depth_mm: float = p(4.5, 1.5, 20.0, "Depth of thread in the motor's tapped mounting holes (the "
                                   "screws must reach far enough and not bottom out)",
                                   "17HS4401 drawing (4 x M3, 4.5 mm deep)")
    mass_kg: float = p(0.28, 0.05, 1.0, "Motor mass", "17HS4401 datasheet (280 g)")
    rotor_inertia_kg_m2: float = p(5.4e-6, 1e-7, 1e-4, "Rotor inertia", "17HS4401 datasheet (54 g cm^2)")
    holding_torque_nm: float = p(0.42, 0.01, 5.0, "Holding torque", f"{PAPER} Table 2 (0.42 N m)")
    phase_current_a: float = p(1.5, 0.05, 10.0, "Phase current the driver holds (peak of the microstep sine; the "
                               "A4988's current limit); holding_torque_nm and the pull-out curve must be the "
                               "motor's at this current", "17HS4401 rated 1.7 A; 1.5 A set, as for the pull-out curve")
    phase_resistance_ohm: float = p(1.5, 0.05, 50.0, "Winding resistance per phase", "17HS4401 datasheet (1.5 ohm)")
    full_step_deg: float = p(1.8, 0.9, 15.0, "Full step angle", f"{PAPER} §2.5.2 (1.8 deg)")
    microsteps: int = p(16, 1, 256, "Microstepping factor", f"{PAPER} Table 2 (A4988, 1/16)",
                        choices=(1, 2, 4, 8, 16, 32, 64, 128, 256))
    pullout_curve_steps_per_s: tuple = p((0.0, 500.0, 1000.0, 2000.0, 4000.0, 8000.0), 0.0, 1e6,
                                         "Pull-out curve: full-step rates, increasing", 
                                         "Typical 17HS4401 at 12 V, 1.5 A; replace with your motor and supply",
                                         length=(2, 64))
    pullout_curve_torque_nm: tuple = p((0.40, 0.38, 0.33, 0.24, 0.13, 0.05), 0.0, 10.0,
                                       "Pull-out torque at each rate of the curve",
                                       "Typical 17HS4401 at 12 V, 1.5 A; replace with your motor and supply",
                                       length=(2, 64))


@dataclass(frozen=True)
class Spool:
    drum_diameter_mm: float = p(20.0, 4.0, 100.0, "Capstan drum diameter at the cable's centre line (2 r_spool)",
                                f"{PAPER} Table 2 (20 mm)")
    wraps: float = p(2.0, 0.5, 10.0, "Cable wraps on the drum (wrap angle / 2 pi)", f"{PAPER} Table 2 (4 pi rad)")
    groove_margin_turns: float = p(0.5, 0.0, 5.0, "Extra groove turns beyond wraps and travel",
                                   "Engineering default")
    groove_pitch_mm: float = p(1.8, 0.5, 10.0, "Axial pitch of the helical groove; the ridge between turns (pitch - groove "
                               "width at the drum surface) must be at least print.line_width_mm",
                               "Issue 12: the 1.6 mm pitch left 0.34 mm ridges; groove 1.26 mm wide + a 0.45 mm line")
    groove_depth_mm: float = p(0.5, 0.1, 3.0, "Radial depth of the groove", "Engineering default (half the cable)")
    flange_height_mm: float = p(3.0, 0.5, 20.0, "Flange height above the drum surface", "Engineering default")
    flange_thickness_mm: float = p(1.6, 0.8, 6.0, "Flange thickness", "Engineering default (4 line widths)")
    hub_length_mm: float = p(8.0, 3.0, 30.0, "Hub length below the drum (carries the set screw)",
                             "Engineering default")
    set_screw_diameter_mm: float = p(3.0, min(SCREWS), max(SCREWS), "Set screw (M3, on the shaft flat)",
                                     "Engineering default; sizes of catalogues/fasteners.toml", choices=SCREWS)
    tension_storage_turns: float = p(0.75, 0.0, 5.0, "Relative turns the split spool's two halves may take to "
                                     "pretension the cable (half at each end of the groove); must cover the cable's "
                                     "creep, its stretch at pretension and the assembly tolerance "
                                     "(swiftfin.layout.tension.tensioner_numbers)",
                                     "Sized for the longest default route (joint 4: 0.73 turn needed)")
    index_screw_diameter_mm: float = p(2.0, min(SCREWS), max(SCREWS), "Screw that locks the split spool's halves "
                                       "through one aligned pair of vernier index holes (self-tapped in the lower half)",
                                       "Engineering default; sizes of catalogues/fasteners.toml", choices=SCREWS)
    index_holes_upper: int = p(7, 2, 40, "Index holes in the upper half of the split spool (vernier with the lower; "
                               "coprime counts give 360 / (upper x lower) deg steps)",
                               "Engineering default (5.7 deg steps with 9 below). Issue 12: 10 holes (4 deg) left "
                               "0.23 mm between the index hole nearest the anchor (18 deg off) and the upper crimp's "
                               "seat; 7 puts it 25.7 deg off, 0.98 mm of wall on the 20 mm drum")
    index_holes_lower: int = p(9, 2, 40, "Index holes in the lower half of the split spool", "Engineering default")
    mu_cable_drum: float = p(0.35, 0.02, 1.0, "Cable-on-drum friction coefficient", f"{PAPER} §2.3.1 (nylon on PLA 0.35)")
    mu_dynamic: float = p(0.15, 0.01, 1.0, "Dynamic friction coefficient in eq. 26", f"{PAPER} §2.3.4 (0.15)")


@dataclass(frozen=True)
class Cable:
    model: str = p(CUSTOM, doc=_model_doc("cables.toml", "cable"), source="catalogues/cables.toml (sources per number)",
                   choices=(CUSTOM,) + cable_names())
    material: str = p("braided nylon", doc="Cable material", source=f"{PAPER} Table 2",
                      choices=("braided nylon", "dyneema", "vectran", "steel"))
    diameter_mm: float = p(1.0, 0.1, 5.0, "Cable diameter", f"{PAPER} Table 2 (1.0 mm)")
    breaking_strength_n: float = p(300.0, 5.0, 20000.0, "Breaking strength",
                                   "Typical 1.0 mm braided nylon cord (25-40 kgf); measure yours")
    pretension_n: float = p(45.0, 0.0, 20000.0, "Static pretension of each side",
                            f"{PAPER} §7.2 (10-20 % of breaking strength); 15 % chosen")
    youngs_modulus_gpa: float = p(2.0, 0.05, 250.0, "Effective Young's modulus of the cable (on its full section)",
                                  "Braided nylon 1-3 GPa effective (nylon 6.6 fibre 2-4 GPa)")
    bending_stiffness_n_m2: float = p(1.0e-5, 0.0, 1.0, "Bending stiffness EI (eq. 23)",
                                      "About 1/10 of a solid 1 mm nylon rod (braid)")
    linear_density_g_m: float = p(0.7, 0.01, 100.0, "Mass per metre", "Typical 1 mm braided nylon")
    eta_hysteresis: float = p(0.98, 0.5, 1.0, "Internal hysteresis efficiency (eq. 28)", f"{PAPER} §2.3.5 (0.98)")
    creep_allowance_fraction: float = p(0.03, 0.0, 0.2, "Permanent stretch (creep and bedding-in of the braid) the "
                                        "tensioner must take up over the cable's life, per length of free cable",
                                        "Nylon 6.6 braids set 2-5 % under sustained load near 15-20 % of break "
                                        "(rope makers' elongation data); 3 % chosen: measure yours")
    assembly_tolerance_mm: float = p(3.0, 0.0, 50.0, "Length error of one cable side as assembled (crimp placed "
                                     "by hand against a mark); the tensioner takes up one per side",
                                     "Engineering default")


@dataclass(frozen=True)
class Guides:
    ptfe_tube_id_mm: float = p(2.0, 0.5, 6.0, "PTFE tube inner diameter", "Common 2 x 4 mm PTFE tube")
    ptfe_tube_od_mm: float = p(4.0, 1.0, 10.0, "PTFE tube outer diameter", "Common 2 x 4 mm PTFE tube")
    min_bend_radius_mm: float = p(20.0, 2.0, 100.0, "Minimum bend radius of the PTFE tube",
                                  "2 x 4 mm PTFE tube (20-25 mm)")
    mu_ptfe: float = p(0.05, 0.01, 0.5, "Cable-on-PTFE friction coefficient", f"{PAPER} §2.3.3 (0.05)")
    ptfe_density_kg_m3: float = p(2180.0, 1500.0, 2500.0, "Density of the PTFE tube",
                                  "PTFE 2.13-2.20 g/cm^3 (ASTM D4894 resin datasheets)")
    screw_diameter_mm: float = p(2.0, min(SCREWS), max(SCREWS), "Guide mounting screws (M2)",
                                 "Engineering default; sizes of catalogues/fasteners.toml", choices=SCREWS)


@dataclass(frozen=True)
class CaudalFin:
    span_mm: float = p(160.0, 30.0, 800.0, "Tip-to-tip span of the lunate fin", "Not in the paper; ~0.3 L for tuna")
    aspect_ratio: float = p(6.0, 1.5, 12.0, "span^2 / planform area", "Tuna caudal fins 4.5-7.5 (Magnuson 1978)")
    sweep_deg: float = p(35.0, 0.0, 60.0, "Leading-edge sweep", "Not in the paper; tuna 30-40 deg")
    thickness_fraction: float = p(0.12, 0.04, 0.25, "Section thickness / chord (NACA 00xx)", "Engineering default")
    min_thickness_mm: float = p(1.2, 0.4, 5.0, "Thinnest printable section (trailing edge and tips)",
                                "Engineering default (>= 2 line widths)")
    mount_length_mm: float = p(15.0, 5.0, 60.0, "Length of the root tang that slots into the peduncle",
                               "Engineering default")
    root_fit_clearance_mm: float = p(0.1, 0.0, 0.5, "Gap on each side between the fin's root tang and the "
                                     "peduncle's socket (a close fit; the screws draw the tang onto one face)",
                                     "FDM close fit 0.05-0.15 mm per side for parts that must not rattle "
                                     "(Prusa knowledge base, 'Tolerances'); 0.1 chosen")


@dataclass(frozen=True)
class Swimming:
    tail_beat_frequency_hz: float = p(3.0, 0.1, 20.0, "Design (maximum) tail-beat frequency", f"{PAPER} Table 2 (3 Hz)")
    tail_amplitude_m: float = p(0.10, 0.005, 1.0, "Tail-tip amplitude A_max = A(L)", f"{PAPER} §3.1 (0.10 m)")
    head_amplitude_m: float = p(0.0, 0.0, 0.2, "Amplitude at the nose c0 = A(0)", f"{PAPER} §3.1 (A(0) ~ 0)")
    envelope_linear_coefficient: float = p(0.0, -1.0, 1.0, "c1 of A(x) = c0 + c1 x + c2 x^2 [m/m]",
                                           f"{PAPER} eq. 45 (0)")
    wavelength_body_lengths: float = p(1.25, 0.3, 5.0, "Body wavelength / body length", f"{PAPER} §3.2 (1.25)")
    speed_m_s: float = p(1.97, 0.0, 20.0, "Forward speed at the design point (measured)", f"{PAPER} Table 2 (1.97 m/s)")


@dataclass(frozen=True)
class Environment:
    water_density_kg_m3: float = p(1000.0, 900.0, 1100.0, "Water density", "Fresh water at 20 C (998); 1000 used")
    water_viscosity_pa_s: float = p(1.0e-3, 1e-4, 1e-2, "Dynamic viscosity", "Water at 20 C")
    gravity_m_s2: float = p(9.81, 0.0, 20.0, "Gravity", "Standard")
    buoyancy_band_fraction: float = p(0.05, 0.0, 0.5,
                                      "Allowed |buoyancy - weight| / weight for near-neutral trim",
                                      "Engineering default")
    max_static_pitch_deg: float = p(5.0, 0.0, 45.0, "Largest pitch the fish may settle at in still water "
                                    "(atan of the COM's lead over the COB / the COB's height over the COM)",
                                    "Engineering default")
    trim_ballast: bool = p(True, doc="Add the lead ballast that makes the fish neutral and level (mass and place "
                                     "computed from the mass model; it is listed as the part trim_ballast)",
                           source="Engineering default")
    ballast_density_kg_m3: float = p(11340.0, 2000.0, 20000.0, "Density of the trim ballast's metal (the shot set "
                                       "in epoxy: catalogues/ballast.toml, layout/ballast_plan.py)",
                                       "Lead (11.34 g/cm^3)")
    flotation_foam_segments: int = p(3, 0, 8, "Flooded hull segments, from hull.flooded_from_joint aft, that get a "
                                     "block of closed-cell foam glued into their lower half under the cables "
                                     "(the lift a fish heavier than its displacement needs; the lead then trims "
                                     "what is left). 0: none",
                                     "Design choice: the fasteners, tubes and cables of a buildable fish weigh "
                                     "more than the sealed head's spare displacement (exports/water.py); the third "
                                     "block lifts the tail so the trim lead can level the fish with the wiring's "
                                     "leads weighed (with two, it would sit 14 mm ahead of the nose)")
    foam_density_kg_m3: float = p(100.0, 30.0, 900.0, "Density of the flotation foam",
                                  "Closed-cell PVC foam for marine cores, e.g. Divinycell H100 (100 kg/m^3, "
                                  "DIAB datasheet); it does not soak up water, unlike open-cell or EPS foam")
    design_depth_m: float = p(0.5, 0.05, 100.0, "Deepest water the fish is built for: its seals must hold the "
                              "water's pressure there (with the seal table's safety factor)",
                              "Design choice: a test tank; the fish swims near the surface")
    water_temperature_c: float = p(20.0, 0.0, 40.0, "Water temperature", "Engineering default (a pool or a tank)")
    heat_transfer_water_w_m2_k: float = p(200.0, 10.0, 10000.0, "Convection from the hull to the water",
                                          "Natural convection in water 100-1000 W/m^2 K (Incropera & DeWitt, Table "
                                          "1.1); the low end: the fish held still on a bench")
    heat_transfer_air_w_m2_k: float = p(5.0, 1.0, 50.0, "Natural convection inside the closed dry compartment "
                                        "(air to the wall, air to a motor's case)",
                                        "Natural convection in gases 2-25 W/m^2 K (Incropera & DeWitt, Table 1.1); "
                                        "a small closed cavity sits near the low end")


@dataclass(frozen=True)
class Power:
    battery_energy_wh: float = p(4.5, 0.1, 1000.0, "Energy of the battery", f"{PAPER} Table 2 (9 V, 500 mAh)")
    battery_usable_fraction: float = p(0.8, 0.1, 1.0, "Share of the energy usable before the cut-off voltage",
                                       "Engineering default for Li-ion (cut-off at ~3.0 V a cell)")
    driver_rds_on_ohm: float = p(0.75, 0.0, 5.0, "On-resistance of a driver's bridge, source plus sink",
                                 "Allegro A4988 datasheet (320 + 430 mohm typical at 25 C)")
    electronics_power_w: float = p(0.4, 0.0, 50.0, "Controller, sensors and the drivers' logic",
                                   "Arduino Nano + MPU6050 + 4 A4988 logic ~40 mA from 9 V through a linear regulator")
    run_time_required_min: float = p(15.0, 0.1, 1000.0, "Swimming time one charge must give at the design gait",
                                     "Engineering default (a pool test session)")


@dataclass(frozen=True)
class Hydro:
    """Coefficients of the swimming load model (physics/loads.py). Each is uncertain: see its sensitivity."""
    body_added_mass_coefficient: float = p(1.0, 0.0, 2.0,
                                           "Multiplier on the strip added mass rho pi (h/2)^2 of a body section "
                                           "of height h in lateral motion",
                                           "Lighthill 1960 slender-body theory; Newman 1977 Marine Hydrodynamics "
                                           "§4.13 (ellipse: rho pi b^2, b the half-axis across the motion): 1.0")
    body_drag_coefficient: float = p(1.2, 0.1, 3.0,
                                     "Cross-flow drag coefficient of a body section (on its height h)",
                                     "Taylor 1952 resistive theory; Hoerner 1965 Fluid-Dynamic Drag ch. 3 "
                                     "(circular cylinder, subcritical Re: 1.2)")
    fin_added_mass_coefficient: float = p(1.0, 0.0, 2.0,
                                          "Multiplier on the strip added mass rho pi (b/2)^2 per unit chord of "
                                          "the caudal fin of span b",
                                          "Strip theory (1.0); finite-span plates of AR 6 are ~0.85 "
                                          "(Brennen 1982, NCEL CR 82.016)")
    fin_lift_slope_factor: float = p(1.0, 0.0, 2.0,
                                     "Multiplier on the fin lift slope a = 2 pi AR / (AR + 2) [1/rad]",
                                     "Helmbold/lifting-line slope for a finite wing (Anderson, Fundamentals of "
                                     "Aerodynamics §5.3): 1.0")
    fin_drag_coefficient_90: float = p(1.28, 0.5, 2.5,
                                       "Normal-force coefficient of the fin broadside to the flow: adds "
                                       "C_D90 sin^2(alpha) to the quasi-steady normal force",
                                       "Hoerner 1965 ch. 3 (flat plate of finite aspect ratio 1.2-1.3)")
    fin_normal_coefficient_max: float = p(2.0, 0.5, 5.0,
                                          "Cap on the fin's quasi-steady normal-force coefficient (stall)",
                                          "Dickinson, Lehmann & Sane 1999 (Science 284): delayed-stall C_N ~2.3 "
                                          "at 40 deg; static flat plate ~1.2. 2.0 chosen")


@dataclass(frozen=True)
class Rules:
    """Limits of the design rules (design_rules/). The paper's guidelines (§7.2) are the defaults where it has one."""
    drum_to_cable_min: float = p(20.0, 1.0, 100.0, "Minimum drum diameter / cable diameter",
                                 f"{PAPER} §7.2 (>= 20 x cable diameter)")
    pretension_min_fraction: float = p(0.10, 0.0, 1.0, "Minimum pretension / breaking strength",
                                       f"{PAPER} §7.2 (10-20 %)")
    pretension_max_fraction: float = p(0.20, 0.0, 1.0, "Maximum pretension / breaking strength",
                                       f"{PAPER} §7.2 (10-20 %)")
    holding_torque_factor: float = p(2.0, 1.0, 10.0, "Holding torque / peak motor torque while swimming",
                                     f"{PAPER} §7.2 (>= 2 x peak swimming load)")
    cable_diameter_max_mm: float = p(1.5, 0.1, 10.0, "Largest cable diameter", f"{PAPER} §7.2 (<= 1.5 mm)")
    elongation_max_fraction: float = p(0.005, 0.0001, 0.5, "Largest cable strain at the peak working tension",
                                       f"{PAPER} §7.2 (< 0.5 %)")
    ptfe_mu_max: float = p(0.1, 0.01, 1.0, "Largest cable-on-guide friction coefficient", f"{PAPER} §7.2 (< 0.1)")
    guides_per_route_max: int = p(2, 0, 20, "Redirecting guides on one cable route before a warning",
                                  f"{PAPER} eq. 29 (SwiftFin budgets two redirecting guides)")
    capstan_slip_margin: float = p(2.0, 1.0, 10.0,
                                   "Capstan holding capacity T_slack e^(mu theta) / T_tight needed at peak load",
                                   "Engineering default (factor 2 on friction: mu of printed PLA varies ~2x)")
    cable_safety_factor: float = p(3.0, 1.0, 20.0, "Breaking strength / peak cable tension",
                                   "Engineering default for synthetic cord in cyclic use (3-5)")
    pullout_safety_factor: float = p(1.5, 1.0, 5.0, "Pull-out torque / needed motor torque at every step rate",
                                     "Oriental Motor stepper sizing guide (1.5-2 on the speed-torque curve)")
    position_error_limit_fraction: float = p(0.02, 0.001, 0.5,
                                             "Largest joint position error / joint amplitude",
                                             f"{PAPER} §2.5.3 (the servo's 2 % amplitude error is what the "
                                             "capstan is meant to beat)")
    strouhal_min: float = p(0.25, 0.0, 2.0, "Lower end of the efficient Strouhal band", f"{PAPER} §2.5.3 (0.25)")
    strouhal_max: float = p(0.35, 0.0, 2.0, "Upper end of the efficient Strouhal band", f"{PAPER} §2.5.3 (0.35)")
    wall_min_line_widths: float = p(2.0, 1.0, 10.0, "Thinnest printed wall / extrusion line width",
                                    "FDM practice (two perimeters make a closed wall)")
    softening_margin_k: float = p(10.0, 0.0, 50.0, "Kelvin a printed part must stay below its material's heat "
                                  "deflection temperature", "Engineering default (HDT is measured at 0.45 MPa; "
                                  "creep starts below it)")


@dataclass(frozen=True)
class Print:
    bed_x_mm: float = p(250.0, 50.0, 2000.0, "Printer bed X", "Prusa MK4 (250 x 210 x 220)")
    bed_y_mm: float = p(210.0, 50.0, 2000.0, "Printer bed Y", "Prusa MK4")
    bed_z_mm: float = p(220.0, 50.0, 2000.0, "Printer build height", "Prusa MK4")
    nozzle_diameter_mm: float = p(0.4, 0.1, 2.0, "Nozzle diameter", "Prusa default")
    line_width_mm: float = p(0.45, 0.1, 2.0, "Extrusion line width", "PrusaSlicer default for 0.4 mm")
    layer_height_mm: float = p(0.2, 0.05, 0.6, "Layer height", "PrusaSlicer 0.20 mm QUALITY")
    perimeters: int = p(3, 1, 20, "Perimeter loops", "Engineering default")
    top_layers: int = p(5, 0, 50, "Solid top layers", "PrusaSlicer default")
    bottom_layers: int = p(4, 0, 50, "Solid bottom layers", "PrusaSlicer default")
    infill_fraction: float = p(0.20, 0.0, 1.0, "Sparse infill density", "Engineering default")
    infill_pattern: str = p("gyroid", doc="Sparse infill pattern", source="PrusaSlicer",
                            choices=("gyroid", "grid", "rectilinear", "cubic", "honeycomb", "line"))
    filament_density_kg_m3: float = p(1240.0, 800.0, 2500.0, "Filament density", "PLA (1.24 g/cm^3)")
    material: str = p("PLA", doc="Printed material (its softening temperature and conductivity from "
                      "catalogues/materials.toml)", source="SwiftFin paper (PLA parts)", choices=material_names())
    filament_diameter_mm: float = p(1.75, 1.0, 3.0, "Filament diameter", "Standard")
    clearance_sliding_mm: float = p(0.3, 0.0, 2.0, "Radial clearance for sliding fits (pins, shafts)",
                                    "FDM practice (0.2-0.4 mm)")
    clearance_assembly_mm: float = p(0.5, 0.0, 10.0, "Minimum gap between parts in the assembly",
                                     "Engineering default")
    support_angle_deg: float = p(45.0, 20.0, 80.0, "A face leaning further than this from the vertical needs "
                                 "support (the print orientation is chosen to need least)",
                                 "FDM practice (45 deg overhangs print without support)")
    max_bridge_mm: float = p(10.0, 1.0, 100.0, "A nearly horizontal ceiling may bridge this far between the edges "
                             "that have material below (longer bridges are reported with their part and place)",
                             "FDM practice (about 5 mm always, 10 mm with part cooling; PrusaSlicer lays bridges as "
                             "thick threads)")


@dataclass(frozen=True)
class Export:
    mesh_tolerance_mm: float = p(0.05, 0.001, 1.0, "Linear deflection of the tessellation", "Engineering default")
    mesh_angular_tolerance_deg: float = p(10.0, 1.0, 45.0, "Angular deflection of the tessellation",
                                          "Engineering default")
    visual_triangle_budget: int = p(20000, 500, 1000000, "Triangles per link in the simulator visual meshes",
                                    "Engineering default")


@dataclass(frozen=True)
class DomainRandomisation:
    """Uncertainty of the mass model's inputs: mass_properties.json gives each link's mass and inertia over
    the corners of this box (for domain randomisation in simulators)."""
    filament_density_fraction: float = p(0.03, 0.0, 0.5, "Relative uncertainty of the filament density",
                                         "PLA datasheets give 1.21-1.27 g/cm^3 around 1.24 (+/- 2.5 %)")
    infill_absolute: float = p(0.05, 0.0, 0.5, "Absolute uncertainty of the effective infill fraction",
                               "Slicer infill vs nominal differs by a few % (gyroid line overlap, anchors)")
    wall_thickness_fraction: float = p(0.10, 0.0, 0.5, "Relative uncertainty of the printed wall thickness",
                                       "Extrusion multiplier and line width vary 5-10 % between printers")
    bought_mass_fraction: float = p(0.05, 0.0, 0.5, "Relative uncertainty of catalogue masses",
                                    "Datasheet tolerances (NEMA 17 motors +/- 5 %)")


@dataclass(frozen=True)
class Component:
    """A bought part: catalogue mass and simple box geometry at a station along the body."""
    name: str = p("", doc="Component name")
    mass_kg: float = p(0.0, 0.0, 10.0, "Catalogue mass")
    size_mm: tuple = p((10.0, 10.0, 10.0), 0.1, 1000.0, "Box size x, y, z", length=(3, 3))
    station_fraction: float = p(0.1, 0.0, 1.0, "Station of the box centre / body length")
    z_mm: float = p(0.0, -500.0, 500.0, "Height of the box centre above the body axis")
    source: str = p("", doc="Where the mass comes from")


DEFAULT_COMPONENTS = (
    Component(name="battery", mass_kg=0.046, size_mm=(48.5, 26.5, 17.5), station_fraction=0.27, z_mm=-41.5,
              source=f"{PAPER} Table 2 (9 V, 500 mAh); PP3 Li-ion cell 46 g. Placed low under the motors: ballast"),
    Component(name="electronics", mass_kg=0.030, size_mm=(45.0, 15.0, 30.0), station_fraction=0.077, z_mm=-6.0,
              source="Arduino Nano (7 g) + 4 x A4988 carriers (4 x 3 g) + MPU6050 + wiring, board on edge in the nose, "
                     "lengthwise and 6 mm low (its cradle needs two perimeters of floor over the narrowing nose "
                     "under a 3 mm pad): the trim lead is poured above it (layout/ballast_plan.py)"),
)
# (the screws, inserts, nuts and pins are no longer a lumped component: each fastener record carries its catalogue
# mass at its place, exports/line_masses.py fastener_masses)


@dataclass(frozen=True)
class Params:
    body: Body = field(default_factory=Body)
    hull: Hull = field(default_factory=Hull)
    joints: Joints = field(default_factory=Joints)
    motor: Motor = field(default_factory=Motor)
    spool: Spool = field(default_factory=Spool)
    cable: Cable = field(default_factory=Cable)
    guides: Guides = field(default_factory=Guides)
    caudal_fin: CaudalFin = field(default_factory=CaudalFin)
    swimming: Swimming = field(default_factory=Swimming)
    environment: Environment = field(default_factory=Environment)
    hydro: Hydro = field(default_factory=Hydro)
    power: Power = field(default_factory=Power)
    rules: Rules = field(default_factory=Rules)
    print: Print = field(default_factory=Print)
    export: Export = field(default_factory=Export)
    domain_randomisation: DomainRandomisation = field(default_factory=DomainRandomisation)
    components: tuple = field(default=DEFAULT_COMPONENTS)

    # Params key the layout's memo caches (functools.lru_cache): the dataclass's own hash walks every section's every
    # field on each lookup, 8 % of drawing seeded designs (790 000 hash calls for 40 designs, 2026-11-30). The hash
    # is the same (the fields' tuple), worked out once per object and kept out of its pickle: a string's hash
    # differs between processes (PYTHONHASHSEED), and Params go to the sweep's workers.
    def __hash__(self) -> int:
        h = self.__dict__.get("_hash")
        if h is None:
            h = hash(tuple(getattr(self, name) for name in self.__dataclass_fields__))
            object.__setattr__(self, "_hash", h)
        return h

    def __getstate__(self) -> dict:
        state = dict(self.__dict__)
        state.pop("_hash", None)
        return state


SECTIONS = {"body": Body, "hull": Hull, "joints": Joints, "motor": Motor, "spool": Spool, "cable": Cable,
            "guides": Guides, "caudal_fin": CaudalFin, "swimming": Swimming, "environment": Environment, "hydro": Hydro, "power": Power, "rules": Rules,
            "print": Print, "export": Export,
            "domain_randomisation": DomainRandomisation}
