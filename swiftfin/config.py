"""Load a design: schema validation plus the geometric feasibility of the layout, reported together."""
from __future__ import annotations

from pathlib import Path

from cad.layout import layout_problems
from cad.link import joint_link_problems
from swiftfin.params import ParamError, params_from_dict, read_toml
from swiftfin.schema import Params

DEFAULT_DESIGN = "swiftfin.toml"


def check_design(params: Params, source: str) -> Params:
    """Raise ParamError listing every geometric impossibility of a schema-valid design."""
    problems = layout_problems(params)
    if not problems:  # the links' own room (tendon wrap, stops, flange bolts) assumes a feasible layout
        problems = joint_link_problems(params)
    if problems:
        raise ParamError(source, problems)
    return params


def load_design(path: str | Path = DEFAULT_DESIGN) -> Params:
    """Parse, validate and check a parameter file. Raises :class:`ParamError` with every problem."""
    params = params_from_dict(read_toml(path), str(path))
    return check_design(params, str(path))
