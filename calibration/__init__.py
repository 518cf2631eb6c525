

#: family name -> module defining ``FAMILY`` (imported on first use so a missing family does not break others)
FAMILY_MODULES: dict[str, str] = {
    "joint": "swiftfin.calibration.joint",
    "drive": "swiftfin.calibration.drive",
    "body": "swiftfin.calibration.body",
}
