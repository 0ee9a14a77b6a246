"""Material instances: `"format": "matedit.instance"` files.

An instance names a `parent` (a material, or another instance, by a path relative to the
instance file) and overrides some of the parent's parameters:

    {"format": "matedit.instance", "version": 2, "name": "Red paint",
     "parent": "../materials/worn_painted_steel.json",
     "parameters": {"paint_color": [0.5, 0.05, 0.03], "rust_on": false},
     "parent_parameters": {"paint_color": "color", ...},
     "preview": {"mesh": "sphere"}}

Parameter types are `scalar` (a number), `vector` (4 numbers), `color` (3 numbers),
`texture` (a path relative to the instance file) and `switch` (true or false, a static
switch). `parent_parameters` is written on save: the parent's parameters and types as the
instance last saw them. An override whose name the parent no longer has, but once had, is an
orphan (the parameter was renamed or removed): a warning, and the override stays in the file.
A name the parent never had is an error naming it, as is a value of the wrong type.

`resolve` walks the parent chain (a cycle is an error naming the files) and builds the
*effective material*: the root material with every override applied, anchored at the
instance's path, so compiling, rendering and exporting it need no other code. Where no static
switch is overridden its shaders and structure hash are the parent's (uniform defaults live
in the reflection, not in the GLSL).

Reading and writing follow the material format: bounded reads, JSON with no duplicate keys,
unknown top-level fields kept on save, atomic writes, sorted keys.
"""

from __future__ import annotations

import copy
import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from matedit.graph.model import MaterialDocument
from matedit.graph.names import identifier_problem
from matedit.graph.nodes import REGISTRY
from matedit.graph.numbers import describe_number, gpu_number_problem, gpu_numbers_problem
from matedit.io import library
from matedit.io.atomic import atomic_write_text
from matedit.io.document import (
    INSTANCE_FORMAT,
    FormatError,
    check_saves,
    load,
    parse_json_text,
    read_document_text,
    rebase_references,
    reference_from,
)
from matedit.io.jsontext import JSONTextError, parse_json
from matedit.io.migrations import CURRENT_VERSION

FORMAT = INSTANCE_FORMAT
MAX_CHAIN = 64  # parents deep; far beyond any real use, it bounds a hostile chain
TYPES = ("scalar", "vector", "color", "texture", "switch")
# Parameter kinds and their instance types, from the catalogue (NodeDef.parameter).
TYPE_OF_KIND = {k: d.parameter for k, d in REGISTRY.items() if d.parameter is not None}
TOP_FIELDS = frozenset({"format", "version", "name", "description", "parent", "parameters",
                        "parent_parameters", "preview"})
PREVIEW_FILES = ("mesh", "environment")


class InstanceError(ValueError):
    """A problem with an instance or its parent chain, naming the file (and parameter)."""

    def __init__(self, file: str | os.PathLike | None, message: str,
                 parameter: str | None = None) -> None:
        self.file, self.parameter, self.reason = (str(file) if file else None), parameter, \
            message
        where = f"parameter {parameter}: " if parameter else ""
        super().__init__(f"{self.file or '<instance>'}: {where}{message}")


@dataclass
class InstanceDocument:
    parent: str = ""
    parameters: dict[str, Any] = field(default_factory=dict)
    parent_parameters: dict[str, str] = field(default_factory=dict)
    name: str = ""
    description: str = ""
    preview: dict[str, Any] = field(default_factory=dict)
    path: Path | None = None
    extra: dict[str, Any] = field(default_factory=dict)  # unknown fields, kept on save

    def parent_path(self) -> Path:
        if library.is_library_ref(self.parent):
            return library.library_path(self.parent)  # ValueError out of the library
        base = Path(self.path).parent if self.path else Path.cwd()
        return base / self.parent


@dataclass(frozen=True)
class ParameterInfo:
    """One parameter of a material as panels and instances see it."""

    name: str
    type: str  # one of TYPES
    node: str
    kind: str
    default: Any  # the material's own value
    settings: dict[str, Any]  # presentation: group, order, ui_min, ui_max, tooltip, ...
    # Where the value goes: a parameter node's `value`; for a layer's input, the layer
    # stack's port (`LAYER_VISIBLE` for a layer's visibility switch)
    port: str = "value"

    @property
    def group(self) -> str:
        g = self.settings.get("group", "")
        return g if isinstance(g, str) else ""

    @property
    def order(self) -> float:
        o = self.settings.get("order", 0)
        return float(o) if isinstance(o, (int, float)) and not isinstance(o, bool) else 0.0


@dataclass(frozen=True)
class Problem:
    severity: str  # "error" | "warning"
    file: str
    message: str
    parameter: str | None = None

    def format(self) -> str:
        where = f"parameter {self.parameter}: " if self.parameter else ""
        return f"{self.file}: {where}{self.message}"


@dataclass
class ResolvedInstance:
    instance: InstanceDocument
    chain: list[Path]  # real paths: the instance, its parents, ..., the root material last
    material: MaterialDocument  # the root material as loaded
    parameters: dict[str, ParameterInfo]  # the material's parameters
    inherited: dict[str, Any]  # what the instance's parent gives each parameter
    values: dict[str, Any]  # effective value per parameter (inherited, then overridden)
    document: MaterialDocument  # the effective material, anchored at the instance's path
    problems: list[Problem] = field(default_factory=list)

    @property
    def errors(self) -> list[Problem]:
        return [p for p in self.problems if p.severity == "error"]

    @property
    def warnings(self) -> list[Problem]:
        return [p for p in self.problems if p.severity == "warning"]

    def overridden(self, name: str) -> bool:
        return name in self.instance.parameters


# --- reading and writing ------------------------------------------------------------------

def _v1_to_v2(raw: dict) -> dict:
    """Version 1 drafts listed overrides as [{"name": ..., "value": ...}] under "overrides";
    version 2 maps name -> value under "parameters"."""
    out = {k: v for k, v in raw.items() if k != "overrides"}
    params: dict[str, Any] = {}
    for i, o in enumerate(raw.get("overrides", [])):
        if not (isinstance(o, dict) and isinstance(o.get("name"), str) and "value" in o):
            raise FormatError(None, f"overrides[{i}]: expected {{'name': ..., 'value': ...}}")
        params[o["name"]] = o["value"]
    out["parameters"] = {**params, **(raw.get("parameters") or {})}
    out["version"] = 2
    return out


MIGRATIONS = {1: _v1_to_v2}


def is_instance_text(text: str) -> bool:
    """True when `text` is JSON whose top level says "format": "matedit.instance"."""
    try:
        raw = parse_json(text)
    except JSONTextError:
        return False  # the material reader reports why
    return isinstance(raw, dict) and raw.get("format") == FORMAT


def is_instance_file(path: str | os.PathLike) -> bool:
    try:
        return is_instance_text(read_document_text(path))
    except FormatError:
        return False


def loads(text: str, file: str | None = None, path: Path | None = None) -> InstanceDocument:
    raw = parse_json_text(text, file)
    return from_dict(raw, file, path)


def load_instance(path: str | os.PathLike) -> InstanceDocument:
    p = Path(path)
    return loads(read_document_text(p), str(p), p)


def _expect(cond: bool, file, msg, fld=None) -> None:
    if not cond:
        raise FormatError(file, msg, field=fld)


def from_dict(raw: Any, file: str | None = None, path: Path | None = None) -> InstanceDocument:
    _expect(isinstance(raw, dict), file, "top level must be a JSON object")
    _expect(raw.get("format") == FORMAT, file,
            f"'format' must be {FORMAT!r}, got {raw.get('format')!r}", "format")
    version = raw.get("version")
    _expect(isinstance(version, int) and not isinstance(version, bool) and version >= 1, file,
            f"'version' must be a positive integer, got {version!r}", "version")
    if version > CURRENT_VERSION:
        raise FormatError(file, f"written by a newer matedit (file version {version}, this "
                          f"build reads up to {CURRENT_VERSION}); update matedit to open it",
                          field="version")
    while version < CURRENT_VERSION:
        try:
            raw = MIGRATIONS[version](raw)
        except FormatError as exc:
            raise FormatError(file, f"cannot migrate from version {version}: {exc.reason}") \
                from None
        except (TypeError, AttributeError, KeyError) as exc:
            raise FormatError(file, f"cannot migrate from version {version}: {exc}") from None
        version = raw["version"]
    doc = InstanceDocument(path=Path(path) if path else None)
    doc.extra = {k: v for k, v in raw.items() if k not in TOP_FIELDS}
    for key in ("name", "description"):
        val = raw.get(key, "")
        _expect(isinstance(val, str), file, f"'{key}' must be a string", key)
        setattr(doc, key, val)
    parent = raw.get("parent")
    _expect(isinstance(parent, str) and parent.strip() != "" and "\0" not in parent, file,
            "'parent' must name the parent material or instance, relative to this file",
            "parent")
    doc.parent = parent
    params = raw.get("parameters", {})
    _expect(isinstance(params, dict), file, "'parameters' must be an object", "parameters")
    doc.parameters = dict(params)
    known = raw.get("parent_parameters", {})
    _expect(isinstance(known, dict) and all(v in TYPES for v in known.values()), file,
            f"'parent_parameters' must map names to one of {', '.join(TYPES)}",
            "parent_parameters")
    doc.parent_parameters = dict(known)
    preview = raw.get("preview", {})
    _expect(isinstance(preview, dict), file, "'preview' must be an object", "preview")
    for key in PREVIEW_FILES:
        _expect(key not in preview or isinstance(preview[key], str), file,
                f"'preview.{key}' must be a string (a built-in name or a file path)",
                f"preview.{key}")
    doc.preview = dict(preview)
    check_saves(to_dict(doc), file)
    from matedit.io.schema import check_document_shape

    check_document_shape(raw, file)  # the published JSON Schema, after the rules above
    return doc


def to_dict(doc: InstanceDocument) -> dict:
    out: dict[str, Any] = {**doc.extra, "format": FORMAT, "version": CURRENT_VERSION,
                           "name": doc.name, "description": doc.description,
                           "parent": doc.parent, "parameters": doc.parameters}
    if doc.parent_parameters:
        out["parent_parameters"] = doc.parent_parameters
    if doc.preview:
        out["preview"] = doc.preview
    return out


def dumps(doc: InstanceDocument) -> str:
    return json.dumps(to_dict(doc), sort_keys=True, indent=2, ensure_ascii=False,
                      allow_nan=False) + "\n"


def _relative(target: Path, new_dir: Path) -> str:
    return Path(os.path.relpath(os.path.realpath(target), os.path.realpath(new_dir))).as_posix()


def rebase(doc: InstanceDocument, new_path: Path, parameters: dict[str, ParameterInfo] | None
           = None) -> None:
    """Rewrites the parent, texture overrides and preview files for a file at `new_path`."""
    old_dir = Path(doc.path).parent if doc.path else Path.cwd()
    new_dir = Path(new_path).parent
    if not library.is_library_ref(doc.parent) and not Path(doc.parent).is_absolute():
        parent = reference_from(Path(os.path.realpath(old_dir / doc.parent)),
                                Path(os.path.realpath(new_dir)))
        # In the same folder only a parent in the library changes (to its library name).
        if library.is_library_ref(parent) or \
                os.path.realpath(old_dir) != os.path.realpath(new_dir):
            doc.parent = parent
    if os.path.realpath(old_dir) == os.path.realpath(new_dir):
        return
    for name, value in doc.parameters.items():
        known = (parameters or {}).get(name)
        is_tex = (known.type == "texture") if known else doc.parent_parameters.get(name) == \
            "texture"
        if is_tex and isinstance(value, str) and value and not Path(value).is_absolute():
            doc.parameters[name] = _relative(old_dir / value, new_dir)
    for key in PREVIEW_FILES:
        v = doc.preview.get(key)
        if isinstance(v, str) and _is_file_ref(key, v) and not Path(v).is_absolute():
            doc.preview[key] = _preview_relative(old_dir / v, new_dir, key)


def _is_file_ref(key: str, value: str) -> bool:
    """A preview mesh or environment naming a file, not a built-in (bare or `builtin:`)."""
    from matedit.io.inputs import BUILTIN_PREFIX, builtin_name

    return bool(value) and not value.startswith(BUILTIN_PREFIX) and \
        builtin_name(value, key) is None


def _preview_relative(target: Path, new_dir: Path, key: str) -> str:
    """`_relative` for a preview file, spelled so that it cannot read as a built-in."""
    from matedit.io.inputs import as_reference

    return as_reference(_relative(target, new_dir), key)


def save_instance(doc: InstanceDocument, path: str | os.PathLike | None = None,
                  resolved: ResolvedInstance | None = None) -> Path:
    """Atomic save. With a new path the parent and file references are rebased; with
    `resolved`, `parent_parameters` records the parent's parameters as they are now (orphan
    overrides keep their old entry, so they stay recognisable as orphans)."""
    target = Path(path) if path is not None else doc.path
    if target is None:
        raise ValueError("no path to save to")
    from matedit.io.atomic import saves_to_opened_path

    follow = saves_to_opened_path(target, doc.path)  # a link is followed only there
    rebase(doc, target, resolved.parameters if resolved else None)
    if resolved is not None:
        known = {n: p.type for n, p in resolved.parameters.items()}
        for name in doc.parameters:
            if name not in known and name in doc.parent_parameters:
                known[name] = doc.parent_parameters[name]
        doc.parent_parameters = dict(sorted(known.items()))
    atomic_write_text(target, dumps(doc), follow_link=follow)
    doc.path = target
    return target


# --- parameters of a material ---------------------------------------------------------------

def material_parameters(doc: MaterialDocument, layers: bool = False,
                        resolver=None) -> dict[str, ParameterInfo]:
    """The parameters a material exposes (the top graph's parameter and switch nodes). With
    `layers`, also every layer's unwired inputs on each layer stack (named as the stack's
    port, `<layer>_<input>`, grouped by layer name) and a visibility switch per layer above
    the base (`<layer>_visible`), as an instance sees them."""
    out: dict[str, ParameterInfo] = {}
    for nid in sorted(doc.graph.nodes):
        n = doc.graph.nodes[nid]
        if n.kind not in TYPE_OF_KIND:
            continue
        name = n.settings.get("name", "param")
        if not isinstance(name, str) or identifier_problem(name) or name in out:
            continue  # reported by the material's own validation
        d = REGISTRY[n.kind]
        settings = {**d.setting_defaults(), **n.settings}
        t = TYPE_OF_KIND[n.kind]
        if t == "texture":
            default: Any = settings.get("path", "")
        elif t == "switch":
            default = settings.get("value", True)
        else:
            default = n.values.get("value", d.values[0].default if d.values else 0.0)
        out[name] = ParameterInfo(name, t, nid, n.kind, copy.deepcopy(default), settings)
    if layers:
        for name, p in _layer_parameters(doc, resolver).items():
            out.setdefault(name, p)  # a parameter node of the same name wins
    return out


LAYER_VISIBLE = "@visible"  # a layer's visibility switch: no port, the layer's entry
LAYER_ORDER = 10_000  # layer parameters' `order`, past any a parameter node sets
_LAYER_TYPES = {"float": "scalar", "vec3": "color", "vec4": "vector"}


def _layer_parameters(doc: MaterialDocument, resolver) -> dict[str, ParameterInfo]:
    from matedit.graph.nodes import Role, role_of
    from matedit.graph.ports import layer_entries, node_ports
    from matedit.io.document import FileResolver

    resolver = resolver if resolver is not None else FileResolver()
    out: dict[str, ParameterInfo] = {}
    wired = {(l.dst, l.dst_port) for l in doc.graph.links}
    for nid in sorted(doc.graph.nodes):
        n = doc.graph.nodes[nid]
        if role_of(n.kind) != Role.LAYER_STACK:
            continue
        try:
            ports = {p.name: p for p in node_ports(n, resolver, doc).inputs}
        except (LookupError, ValueError, OSError):
            continue  # the material's own validation reports it
        for index, e in enumerate(layer_entries(n)):
            lid, title = e["id"], str(e.get("name") or e["id"])
            prefix = f"{lid}_"
            # after the material's own parameters, in a group and among groups; top layer
            # last, as the stack reads from the base up
            order = LAYER_ORDER + 100 * index
            for pname, port in ports.items():
                t = _LAYER_TYPES.get(str(port.type))
                if not pname.startswith(prefix) or t is None or (nid, pname) in wired \
                        or pname.endswith("_mask"):
                    continue
                settings: dict[str, Any] = {"group": title, "order": order + 1 + len(out),
                                            "tooltip": port.doc or ""}
                if port.range:
                    settings["ui_min"], settings["ui_max"] = port.range
                value = n.values.get(pname, port.default)
                out[pname] = ParameterInfo(pname, t, nid, n.kind, copy.deepcopy(value),
                                           settings, pname)
            if index > 0:
                out[f"{lid}_visible"] = ParameterInfo(
                    f"{lid}_visible", "switch", nid, n.kind, bool(e.get("visible", True)),
                    {"group": title, "order": order,
                     "tooltip": f"Show the {title} layer"}, f"{LAYER_VISIBLE}:{lid}")
    return out


def sorted_groups(params: dict[str, ParameterInfo]) -> list[tuple[str, list[ParameterInfo]]]:
    """Parameters by group (ungrouped first, then groups by their lowest order, then name),
    each group ordered by `order`, then name."""
    groups: dict[str, list[ParameterInfo]] = {}
    for p in params.values():
        groups.setdefault(p.group, []).append(p)
    for g in groups.values():
        g.sort(key=lambda p: (p.order, p.name))
    return sorted(groups.items(), key=lambda kv: (kv[0] != "", min(p.order for p in kv[1]),
                                                  kv[0].lower()))


def _num(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def value_problem(t: str, value: Any) -> str | None:
    """Why `value` cannot be a parameter of type `t` (None when it can)."""
    if t == "scalar":
        if not _num(value):
            return f"a scalar parameter takes a number, got {describe_number(value)}"
        return gpu_number_problem(value)  # the float32 rule every format shares
    if t in ("vector", "color"):
        n = 4 if t == "vector" else 3
        ok = isinstance(value, list) and len(value) == n and all(_num(x) for x in value)
        if not ok:
            return f"a {t} parameter takes a list of {n} numbers, got {describe_number(value)}"
        return gpu_numbers_problem(value, n)
    if t == "texture":
        ok = isinstance(value, str) and "\0" not in value and len(value) < 4096
        return None if ok else f"a texture parameter takes a file path, got {value!r}"
    if t == "switch":
        return None if isinstance(value, bool) else \
            f"a static switch takes true or false, got {value!r}"
    return f"unknown parameter type {t!r}"


# --- resolution -------------------------------------------------------------------------------

def _real(p: Path) -> Path:
    return Path(os.path.realpath(p))


def resolve(inst: InstanceDocument, root: MaterialDocument | None = None) -> ResolvedInstance:
    """Walk the parent chain and build the effective material. Raises InstanceError for a
    chain that cannot be followed (missing parent, cycle, a parent that is not a material or
    an instance, an unreadable parent); parameter problems are collected in `problems`.
    `root`: a material document standing for the file at its path (the editor's open, maybe
    unsaved, material), read instead of that file where the chain reaches it."""
    chain_docs: list[InstanceDocument] = [inst]
    chain: list[Path] = [_real(inst.path) if inst.path else Path("<unsaved instance>")]
    current = inst
    while True:
        here = str(current.path) if current.path else "<instance>"
        try:
            ppath = current.parent_path()
        except ValueError as exc:
            raise InstanceError(here, f"parent {current.parent}: {exc}") from None
        if len(chain) > MAX_CHAIN:
            raise InstanceError(here, f"the parent chain is more than {MAX_CHAIN} deep")
        real = _real(ppath)
        if real in chain:
            loop = [*chain[chain.index(real):], real]
            raise InstanceError(inst.path, "instance parents form a cycle: "
                                + " -> ".join(str(p) for p in loop), None)
        if root is not None and root.path is not None and _real(root.path) == real:
            if root.is_function:
                raise InstanceError(here, f"parent {current.parent} is a material function; "
                                    "an instance's parent is a material or another instance")
            chain.append(real)
            return _apply(inst, chain_docs, chain, root)
        try:
            text = read_document_text(ppath)
        except FormatError as exc:
            raise InstanceError(here, f"parent {current.parent}: {exc.reason}") from None
        chain.append(real)
        if is_instance_text(text):
            try:
                parent = loads(text, str(ppath), ppath)
            except FormatError as exc:
                raise InstanceError(here, f"parent {current.parent}: {exc}") from None
            chain_docs.append(parent)
            current = parent
            continue
        try:
            material = load(ppath)
        except FormatError as exc:
            raise InstanceError(here, f"parent {current.parent}: {exc}") from None
        if material.is_function:
            raise InstanceError(here, f"parent {current.parent} is a material function; an "
                                "instance's parent is a material or another instance")
        break
    return _apply(inst, chain_docs, chain, material)


def _apply(inst: InstanceDocument, chain_docs: list[InstanceDocument], chain: list[Path],
           material: MaterialDocument) -> ResolvedInstance:
    params = material_parameters(material, layers=True)
    values = {n: copy.deepcopy(p.default) for n, p in params.items()}
    problems: list[Problem] = []
    anchor = Path(inst.path) if inst.path else Path.cwd() / "instance.json"
    inherited: dict[str, Any] = dict(values)
    texture_dirs: dict[str, Path] = {}  # texture parameter -> folder its path is relative to
    preview = _preview_at(material.preview, material.path, anchor)
    for d in reversed(chain_docs):  # root-most instance first
        if d is inst:
            inherited = copy.deepcopy(values)
        f = str(d.path) if d.path else "<instance>"
        for name, value in d.parameters.items():
            p = params.get(name)
            if p is None:
                if name in d.parent_parameters:
                    problems.append(Problem(
                        "warning", f, "the parent no longer has this parameter (renamed or "
                        "removed); the override is kept in the file but has no effect", name))
                else:
                    problems.append(Problem(
                        "error", f, "the parent material has no parameter of this name", name))
                continue
            why = value_problem(p.type, value)
            if why is None and name in d.parent_parameters and \
                    d.parent_parameters[name] != p.type:
                why = (f"was a {d.parent_parameters[name]} parameter, the parent now makes it "
                       f"a {p.type} parameter")
            if why:
                problems.append(Problem("error", f, why, name))
                continue
            values[name] = copy.deepcopy(value)
            if p.type == "texture":
                texture_dirs[name] = Path(d.path).parent if d.path else Path.cwd()
        preview.update(_preview_at(d.preview, d.path, anchor))
    doc = copy.deepcopy(material)
    rebase_references(doc, anchor)
    doc.path = Path(inst.path) if inst.path else None
    tidied: list[Path] = []
    for name, p in params.items():
        n = doc.graph.nodes[p.node]
        v = values[name]
        if p.port.startswith(LAYER_VISIBLE):  # a layer shown or hidden
            lid = p.port.split(":", 1)[1]
            for e in n.settings.get("layers", []):
                if isinstance(e, dict) and e.get("id") == lid:
                    e["visible"] = bool(v)
            continue
        if p.port != "value":  # a layer's input, on its stack
            n.values[p.port] = copy.deepcopy(v)
            continue
        if p.type == "texture":
            if name not in texture_dirs:
                v = n.settings.get("path", "")  # the material's own, rebased above
            elif v and not Path(v).is_absolute():
                # the file a reader that tidies `..` away would open: guarded as an input too
                tidied.append(Path(os.path.abspath(texture_dirs[name] / v)))
                v = _relative(texture_dirs[name] / v, anchor.parent)
            n.settings["path"] = v
            values[name] = v
        elif p.type == "switch":
            n.settings["value"] = v
        else:
            n.values["value"] = copy.deepcopy(v)
    doc.preview = preview
    doc.name = inst.name or material.name
    doc.instance_chain = list(chain[1:])  # read by matedit.io.inputs.document_inputs
    doc.instance_textures = tidied  # so is this
    return ResolvedInstance(inst, chain, material, params, inherited, values, doc, problems)


def _preview_at(preview: dict, owner: Path | None, anchor: Path) -> dict:
    """`preview` with its file references made relative to `anchor`'s folder."""
    out = dict(preview or {})
    base = Path(owner).parent if owner else Path.cwd()
    for key in PREVIEW_FILES:
        v = out.get(key)
        if isinstance(v, str) and _is_file_ref(key, v) and not Path(v).is_absolute():
            out[key] = _preview_relative(base / v, anchor.parent, key)
    return out


def new_instance(parent: str | os.PathLike, path: str | os.PathLike,
                 name: str = "") -> InstanceDocument:
    """An instance of `parent` (a material or instance file) to be saved at `path`, with no
    overrides yet."""
    path = Path(path)
    rel = _relative(Path(parent), path.parent)
    return InstanceDocument(parent=rel, name=name or path.stem.replace("_", " "), path=path)


def load_effective(path: str | os.PathLike) -> tuple[MaterialDocument, list[Problem]]:
    """What the commands build from a file: a material (or function) as loaded, or an
    instance's effective material with its warnings. Raises FormatError, or InstanceError
    naming the file and parameter of the first error."""
    p = Path(path)
    text = read_document_text(p)
    if not is_instance_text(text):
        from matedit.io.document import loads as material_loads

        return material_loads(text, str(p), p), []
    r = resolve(loads(text, str(p), p))
    if r.errors:
        first = r.errors[0]
        raise InstanceError(first.file, first.message, first.parameter)
    return r.document, r.warnings
