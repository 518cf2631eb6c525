"""Calibration engine: measured data -> base model -> residual -> named physical effects -> report.

The engine knows no physics. A *family* (``joint``, ``drive``, ``body``) supplies a base model built from the
paper's equations and a library of candidate *effects*, each a physical mechanism the base model lacks, with
parameters, bounds and a fingerprint in the residual. The :class:`Calibrator` fits the base model, diagnoses
the residual, then adds effects one at a time (forward selection) while an effect lowers the error on held-out
data by a significant margin with physically plausible parameters, and stops when the residual is white or no
candidate helps. It is an estimator (house style rule 12): ``Calibrator(family).fit(train, holdout) -> self``,
learned values end in ``_``, every fitted parameter carries a standard uncertainty.

The engine is split by job; this module is the facade that keeps the names importable from one place
(``from swiftfin.calibration.engine import Calibrator, Context, Effect, Family, Param``):

* :mod:`calibration.model`: the data model (Param, Context, Effect, Family, FittedEffect, concat_contexts),
  how to add a family, and the model structure the engine assumes;
* :mod:`calibration.families`: the registry (get_family, available_families; the names are in
  ``FAMILY_MODULES``);
* :mod:`calibration.statistics`: acf, Ljung-Box, effective sample size, the held-out F-test and block test;
* :mod:`calibration.diagnostics`: residual diagnosis (Diagnosis, diagnose: structure left, white or not);
* :mod:`calibration.selection`: the estimator (Calibrator: forward selection, pruning, uncertainties, the
  report dict) and the selection criterion, stated once;
* :mod:`swiftfin.core.jsonable`: numpy scalars, arrays and dataclasses -> JSON types (``_jsonable`` here).

Code inside the package imports from those modules directly; this facade is for users, tests and benchmarks.
"""
from __future__ import annotations

from swiftfin.calibration import FAMILY_MODULES
from swiftfin.calibration.diagnostics import Diagnosis, diagnose
from swiftfin.calibration.families import available_families, get_family
from swiftfin.calibration.model import Context, Effect, Family, FittedEffect, Param, concat_contexts
from swiftfin.calibration.selection import Calibrator
from swiftfin.calibration.selection import _single_thread_blas  # noqa: F401  (bench/ imports it from here)
from swiftfin.calibration.statistics import (acf, block_test, effective_sample_fraction, effective_sample_size,
                                             heldout_f_test, ljung_box)
from swiftfin.core.jsonable import jsonable as _jsonable  # noqa: F401  (the old name, kept importable)

__all__ = ["Param", "Context", "Effect", "Family", "FittedEffect", "Calibrator", "Diagnosis", "diagnose",
           "acf", "ljung_box", "block_test", "heldout_f_test", "effective_sample_fraction", "effective_sample_size",
           "concat_contexts", "get_family", "available_families",
           "FAMILY_MODULES"]
