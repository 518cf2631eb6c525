"""Load a design: schema validation plus the geometric feasibility of the layout, reported together."""
from __future__ import annotations

from pathlib import Path

from swiftfin.layout.geometry import layout_problems
from swiftfin.layout.joints import joint_link_problems
from swiftfin.core.params import ParamError, params_from_dict, read_toml
from swiftfin.core.schema import Params

DEFAULT_DESIGN = "swiftfin.toml"   # the name of a design in the working folder, and of the one shipped


def packaged_design_path() -> Path:
    """The default design shipped inside the package (the paper's SwiftFin; the repository's swiftfin.toml)."""
    from importlib.resources import files

    return Path(str(files("swiftfin") / DEFAULT_DESIGN))


def default_design_path() -> Path:
    """``swiftfin.toml`` in the working folder when there is one, otherwise the shipped default design."""
    here = Path(DEFAULT_DESIGN)
    return here if here.is_file() else packaged_design_path()


def check_design(params: Params, source: str) -> Params:
    """Raise ParamError listing every geometric impossibility of a schema-valid design."""
    problems = layout_problems(params)
    if not problems:  # the links' own room (tendon wrap, stops, flange bolts) assumes a feasible layout
        problems = joint_link_problems(params)
    if problems:
        raise ParamError(source, problems)
    return params


def load_design(path: str | Path | None = None) -> Params:
    """Parse, validate and check a parameter file. Raises :class:`ParamError` with every problem."""
    path = default_design_path() if path is None else path
    params = params_from_dict(read_toml(path), str(path))
    return check_design(params, str(path))
