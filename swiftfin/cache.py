"""Rebuild cache: a part family's output is reused when nothing it depends on has changed.

What a family depends on is *measured*, not declared: while the family runs (and while its parts are exported)
it sees the parameters through :class:`RecordingParams`, a read-only proxy that records every dotted key read
(``spool.drum_diameter_mm``; a list field such as ``joints.stations_fraction`` or ``components`` is recorded
whole). The cache key of a run is

    family name + tool version + hash of the source of the family's module and every project module it
    imports (transitively) + the exporter's source  ->  "source key"
    source key + the recorded (key, value) pairs  ->  entry key

Because a family is a pure function of the values it reads, a run with the same source and the same values
at the recorded keys takes the same path through the code and reads the same keys, so the key-set recorded
by an earlier run can be looked up first (``keysets.json`` under the source key; ccache's "manifest" mode).

Layout of a cache directory (default ``.cache/swiftfin/`` under the working directory; ``SWIFTFIN_CACHE_DIR``
overrides it)::

    <family>/<source key>/keysets.json
    <family>/<source key>/<entry key>/entry.pkl      PartSpecs without solids, meshes, exported bytes
    <family>/<source key>/<entry key>/<label>.brep   each solid (OpenCascade BREP, no triangulation)
    assembly-pairs/<xx>/<pair key>                   assembly-check pairs that passed (cad/assembly.py)
    assembly-paths/<xx>/<path key>                   each pair's way-in result of the assembly steps
                                                     (cad/assembly_steps.py)

Storing an entry deletes the family's entries made by other versions of its source (unreachable).

Entries are written to a temporary folder and renamed into place, so an interrupted build never leaves a
half-written entry. The cache only ever holds what this program wrote; delete the folder to clear it.
"""
from __future__ import annotations

import ast
import dataclasses
import hashlib
import importlib.util
import json
import os
import pickle
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterator

from swiftfin import __version__
from swiftfin.core.params import get_key

PROJECT_PACKAGES = ("swiftfin",)
CACHE_ENV = "SWIFTFIN_CACHE_DIR"
DEFAULT_CACHE_DIR = Path(".cache") / "swiftfin"
FORMAT = 2  # bump when the layout of an entry changes (2: PartExport.volume_props, stage results)


# --------------------------------------------------------------------------------------------- recording
def _canonical(value: Any) -> Any:
    """JSON-able form of a parameter value (dataclasses as dicts, tuples as lists)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: _canonical(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, (tuple, list)):
        return [_canonical(v) for v in value]
    return value


class RecordingParams:
    """Read-only view of a frozen Params (or one of its sections) that records every key read into ``reads``.

    ``isinstance(view, Params)`` holds; the view is hashable by identity and equal only to itself, so no
    memo keyed on params can hand a family a value computed without recording its reads.
    """

    __slots__ = ("_obj", "_prefix", "_reads")

    def __init__(self, obj: Any, reads: dict[str, Any], prefix: str = ""):
        object.__setattr__(self, "_obj", obj)
        object.__setattr__(self, "_prefix", prefix)
        object.__setattr__(self, "_reads", reads)

    @property
    def __class__(self):  # noqa: D105  isinstance() sees the wrapped class
        return type(object.__getattribute__(self, "_obj"))

    def __getattr__(self, name: str) -> Any:
        obj = object.__getattribute__(self, "_obj")
        value = getattr(obj, name)
        if name.startswith("__"):
            return value
        key = object.__getattribute__(self, "_prefix") + name
        reads = object.__getattribute__(self, "_reads")
        if dataclasses.is_dataclass(value) and not isinstance(value, type):
            return _view(value, reads, key + ".")
        if not callable(value):
            reads[key] = _canonical(value)
        return value

    def __setattr__(self, name, value):
        raise dataclasses.FrozenInstanceError(f"cannot assign to field '{name}'")

    def __repr__(self) -> str:
        return f"RecordingParams({object.__getattribute__(self, '_obj')!r})"

    __hash__ = object.__hash__

    def __eq__(self, other) -> bool:
        return self is other


_VIEW_CLASSES: dict[type, type] = {}


def _view(obj: Any, reads: dict[str, Any], prefix: str = "") -> RecordingParams:
    """A RecordingParams whose class carries the dataclass's fields, so that dataclasses.replace / fields /
    asdict accept it (they read every field through the view, so every field is recorded)."""
    cls = type(obj)
    view_cls = _VIEW_CLASSES.get(cls)
    if view_cls is None:
        view_cls = type(f"Recording{cls.__name__}", (RecordingParams,),
                        {"__slots__": (), "__dataclass_fields__": cls.__dataclass_fields__,
                         "__dataclass_params__": cls.__dataclass_params__})
        _VIEW_CLASSES[cls] = view_cls
    return view_cls(obj, reads, prefix)


def record_reads(params) -> tuple[RecordingParams, dict[str, Any]]:
    reads: dict[str, Any] = {}
    return _view(params, reads), reads


# --------------------------------------------------------------------------------------------- source hash
_FILE_MEMO: dict[str, Path | None] = {}


def _module_file(name: str) -> Path | None:
    if name.split(".")[0] not in PROJECT_PACKAGES:
        return None
    if name in _FILE_MEMO and (_FILE_MEMO[name] is None or _FILE_MEMO[name].is_file()):
        return _FILE_MEMO[name]
    _FILE_MEMO[name] = _find_module_file(name)
    return _FILE_MEMO[name]


def _find_module_file(name: str) -> Path | None:
    try:
        spec = importlib.util.find_spec(name)
    except (ImportError, ValueError):
        return None
    if spec is None or not spec.origin or not spec.origin.endswith(".py"):
        return None
    return Path(spec.origin)


_IMPORTS_MEMO: dict[tuple[str, str], frozenset[str]] = {}    # (module, SHA-256 of its source) -> its imports


def _imports(name: str, path: Path) -> set[str]:
    data = path.read_bytes()
    memo_key = (name, hashlib.sha256(data).hexdigest())
    if memo_key in _IMPORTS_MEMO:                              # parsing is the cost; the source decides
        return set(_IMPORTS_MEMO[memo_key])
    out = _parse_imports(name, path, data)
    _IMPORTS_MEMO[memo_key] = frozenset(out)
    return out


def _parse_imports(name: str, path: Path, data: bytes) -> set[str]:
    tree = ast.parse(data.decode("utf-8"))
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - node.level + 1] if node.level > 1 else base
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            out.add(mod)
            out.update(f"{mod}.{a.name}" for a in node.names)  # "from cad import hull" imports a module
    return out


def module_closure(*names: str) -> dict[str, Path]:
    """Every project module the given modules import, transitively (static: from the source's import lines)."""
    todo, seen = list(names), {}
    while todo:
        name = todo.pop()
        if name in seen:
            continue
        path = _module_file(name)
        if path is None:
            continue
        seen[name] = path
        todo.extend(sorted(_imports(name, path) - set(seen)))
    return seen


DATA_PACKAGES = ("swiftfin.catalogues",)
"""Packages whose modules read data files beside them (``*.toml``): those files count as their source."""


def source_hash(*module_names: str) -> str:
    h = hashlib.sha256()
    for name, path in sorted(module_closure(*module_names).items()):
        h.update(name.encode() + b"\0" + path.read_bytes() + b"\0")
        if name.startswith(DATA_PACKAGES):
            for data in sorted(path.parent.glob("*.toml")):
                h.update(data.name.encode() + b"\0" + data.read_bytes() + b"\0")
    return h.hexdigest()


# --------------------------------------------------------------------------------------------- store
def default_cache_dir() -> Path:
    env = os.environ.get(CACHE_ENV)
    return Path(env) if env else Path.cwd() / DEFAULT_CACHE_DIR


def _json_hash(obj: Any) -> str:
    return hashlib.sha256(json.dumps(obj, sort_keys=True, separators=(",", ":")).encode()).hexdigest()


@contextmanager
def command_cache(no_cache: bool, cache_dir: str | Path | None) -> Iterator["FamilyCache"]:
    """The cache a command builds through: ``cache_dir`` (None: :func:`default_cache_dir`), or with ``no_cache`` a
    temporary one, removed when the command is done (every solid and stage is made afresh, and stages one process
    makes are still shared within it)."""
    if not no_cache:
        yield FamilyCache(cache_dir)
        return
    with tempfile.TemporaryDirectory(prefix="swiftfin-no-cache-") as tmp:
        yield FamilyCache(tmp)


class FamilyCache:
    """Entries of one cache directory. ``lookup`` then (on a miss) ``store``; :meth:`memoize` does both for any
    pure function of the parameters (the report's plots)."""

    def __init__(self, root: str | Path | None = None):
        self.root = Path(root) if root is not None else default_cache_dir()

    def source_key(self, family: str, modules: tuple[str, ...]) -> str:
        return _json_hash([FORMAT, family, __version__, source_hash(*modules)])[:32]

    def _dir(self, family: str, skey: str) -> Path:
        return self.root / family / skey

    def _keysets(self, family: str, skey: str) -> list[list[str]]:
        f = self._dir(family, skey) / "keysets.json"
        try:
            return json.loads(f.read_text())
        except (OSError, ValueError):
            return []

    def _forget_other_sources(self, family: str, skey: str) -> None:
        """Entries made by other versions of the family's source are unreachable: delete them, so the cache
        grows with the designs built, not with every edit of the code."""
        for d in (self.root / family).iterdir():
            if d.is_dir() and d.name != skey and not d.name.startswith("."):
                shutil.rmtree(d, ignore_errors=True)

    @staticmethod
    def entry_key(reads: dict[str, Any], inputs: str = "") -> str:
        """The entry of a run that read ``reads`` (parameter key -> value) and, beside the parameters, the inputs
        whose digest is ``inputs`` ("" for a part family, which reads the parameters only)."""
        return _json_hash(sorted(reads.items()) if not inputs else [sorted(reads.items()), inputs])[:32]

    def lookup(self, family: str, skey: str, params, inputs: str = "") -> tuple[str, Any] | None:
        """(entry key, payload) of a stored run whose recorded keys have the same values in ``params`` (and that
        read the same other ``inputs``, by their digest)."""
        for keyset in self._keysets(family, skey):
            try:
                reads = {k: _canonical(get_key(params, k)) for k in keyset}
            except AttributeError:
                continue
            ekey = self.entry_key(reads, inputs)
            d = self._dir(family, skey) / ekey
            try:
                with (d / "entry.pkl").open("rb") as fh:
                    payload = pickle.load(fh)
            except (OSError, pickle.UnpicklingError, EOFError, AttributeError, ImportError):
                continue
            return ekey, (d, payload)
        return None

    def memoize(self, name: str, modules: tuple[str, ...], params, fn, inputs: str = ""):
        """``fn(params)``, stored under the parameter keys it reads (like a part family): a change of any
        other parameter reuses it. ``inputs``: the digest of whatever else ``fn`` reads (the parts' meshes of a
        check on the solids), part of the entry's key. An exception is not stored."""
        skey = self.source_key(name, modules)
        hit = self.lookup(name, skey, params, inputs)
        if hit is not None:
            return hit[1][1]
        view, reads = record_reads(params)
        out = fn(view)
        self.store(name, skey, reads, out, {}, inputs)
        return out

    def store(self, family: str, skey: str, reads: dict[str, Any], payload: Any,
              breps: dict[str, bytes], inputs: str = "") -> str:
        """Write one entry atomically and add its key-set to the family's list. Returns the entry key."""
        ekey = self.entry_key(reads, inputs)
        base = self._dir(family, skey)
        base.mkdir(parents=True, exist_ok=True)
        final = base / ekey
        if not final.exists():
            tmp = Path(tempfile.mkdtemp(prefix=f".{ekey}.", dir=base))
            try:
                for label, data in breps.items():
                    (tmp / f"{label}.brep").write_bytes(data)
                with (tmp / "entry.pkl").open("wb") as fh:
                    pickle.dump(payload, fh, protocol=pickle.HIGHEST_PROTOCOL)
                os.replace(tmp, final)
            except OSError:
                shutil.rmtree(tmp, ignore_errors=True)
                if not final.exists():
                    raise
        self._forget_other_sources(family, skey)
        keyset = sorted(reads)
        sets = self._keysets(family, skey)
        if keyset not in sets:
            sets.append(keyset)
            fd, tmpname = tempfile.mkstemp(prefix=".keysets.", dir=base)
            with os.fdopen(fd, "w") as fh:
                json.dump(sets, fh, indent=1)
            os.replace(tmpname, base / "keysets.json")
        return ekey


# --------------------------------------------------------------------------------------------- later stages
class StageCache:
    """Results of the build's later stages (per-part mass properties and B-rep volume properties, the water
    behind the hull end, link meshes, part pictures), each keyed only by its own inputs and its own code:

        stage name + tool version + hash of the stage's modules (and what they import)
          + the content of the parts it reads (their BREP's SHA-256) + its other inputs  ->  one pickle

    under ``<cache dir>/stages/<stage>/<xx>/<key>.pkl``, written atomically. Editing the MJCF writer leaves the
    mass properties cached; changing one part recomputes only what reads that part.
    """

    def __init__(self, root: str | Path, stage_modules: dict[str, tuple[str, ...]]):
        self.root = Path(root) / "stages"
        self.stage_modules = dict(stage_modules)
        self._source: dict[str, str] = {}

    def _source_key(self, stage: str) -> str:
        if stage not in self._source:
            self._source[stage] = source_hash(*self.stage_modules[stage])
        return self._source[stage]

    def get(self, stage: str, key: Any, compute):
        """``compute()``'s result for ``key`` (JSON-able), from the store when there."""
        ekey = _json_hash([FORMAT, stage, __version__, self._source_key(stage), key])
        path = self.root / stage / ekey[:2] / f"{ekey}.pkl"
        try:
            with path.open("rb") as fh:
                return pickle.load(fh)
        except (OSError, pickle.UnpicklingError, EOFError, AttributeError, ImportError, IndexError, TypeError):
            pass
        value = compute()
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            fd, tmpname = tempfile.mkstemp(prefix=".stage.", dir=path.parent)
            with os.fdopen(fd, "wb") as fh:
                pickle.dump(value, fh, protocol=pickle.HIGHEST_PROTOCOL)
            os.replace(tmpname, path)
        except OSError:
            pass        # a cache that cannot be written is only slower
        return value

    def memo(self, part_keys: dict[str, str]):
        """The ``memo(stage, labels, extra, compute)`` the export and report layers take: keyed by the named
        parts' content (``part_keys``: label -> SHA-256 of its BREP) and ``extra``."""
        def memo(stage: str, labels: tuple[str, ...], extra, compute):
            if any(label not in part_keys for label in labels):
                return compute()            # a part this build did not make: no content key to file it under
            return self.get(stage, [[part_keys[label] for label in labels], extra], compute)
        return memo


# --------------------------------------------------------------------------------------------- BREP
def brep_bytes(shape) -> bytes:
    """OpenCascade BREP text of a shape, without triangulation (so it does not depend on earlier meshing)."""
    from OCP.BRepTools import BRepTools

    topo = getattr(shape, "wrapped", shape)
    with tempfile.NamedTemporaryFile(suffix=".brep", delete=False) as fh:
        name = fh.name
    try:
        BRepTools.Clean_s(topo)
        if not BRepTools.Write_s(topo, name):
            raise RuntimeError("BREP write failed")
        return Path(name).read_bytes()
    finally:
        os.unlink(name)


def brep_roundtrip(shape, label: str):
    """The shape as it comes back from its BREP text: what a cached build sees. Building every output from
    this form makes a cold build and a cached one byte-identical (the text form normalises e.g. -0.0)."""
    data = brep_bytes(shape)
    with tempfile.NamedTemporaryFile(suffix=".brep", delete=False) as fh:
        fh.write(data)
        name = fh.name
    try:
        return shape_from_brep(Path(name), label), data
    finally:
        os.unlink(name)


def shape_from_brep(path: Path, label: str):
    """The build123d shape stored in a BREP file, with its label."""
    import build123d as bd

    shape = bd.import_brep(str(path))
    solids = shape.solids() if hasattr(shape, "solids") else []
    if len(solids) == 1 and not isinstance(shape, bd.Solid):
        shape = solids[0]
    shape.label = label
    return shape
