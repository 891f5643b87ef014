"""A Mitsuba XML scene parsed by Mitsuba's own parser, as a tree of plain records.

Mitsuba 3.6+ parses a scene without instantiating a plugin (``mitsuba.parser``):
``parse_string`` reads the XML (``$name`` parameters take their ``<default>``; ``<point x= y=
z=>``, every ``<transform>`` form and ``<rgb value="5"/>`` become vectors, matrices and
colours), ``transform_upgrade`` applies Mitsuba's own upgrade of 0.5/0.6 files (camelCase names
to snake_case) and ``transform_resolve`` resolves ``<ref>``. This module walks the parser's
nodes into :class:`XmlNode` records and makes the usual fixes Mitsuba's upgrade does not
(:func:`_fix`), each named in :attr:`ParsedXml.fixes` for a line on stderr.

The XML text comes from :func:`~spectrinsic.scenes.mitsuba_files.prepare_xml` (includes
inlined, files checked), so the parser reads no file.

Mitsuba is imported as found: a caller that renders in the same process sets it up first with
:func:`spectrinsic.render.base.variants.import_mitsuba` (the command line and the dataset
workers do), so that Dr.Jit loads the ``libLLVM`` spectrinsic chose.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any, Union

import numpy as np

from ..errors import SceneError
from ..mitsuba_import import import_mitsuba

__all__ = [
    "Spectrum",
    "Value",
    "XmlNode",
    "ParsedXml",
    "parse_xml",
    "named_ior",
    "mesh_file",
    "mesh_file_uv",
]


@dataclass(frozen=True)
class Spectrum:
    """Written-out spectral samples: *wavelengths* (nm) and *values*."""

    wavelengths: tuple[float, ...]
    values: tuple[float, ...]


Value = Union[bool, int, float, str, np.ndarray, Spectrum, "XmlNode"]


@dataclass(frozen=True, eq=False)
class XmlNode:
    """One element: its *kind* (``shape``, ``bsdf``, ``emitter``, ``texture`` ...), *plugin*
    (``obj``, ``diffuse`` ...), ``id``, named *props* (numbers, strings, 3-vectors and colours
    as arrays, transforms as 4 × 4 matrices, spectra, nested nodes) and unnamed *children*
    (nested or referenced elements, in document order)."""

    kind: str
    plugin: str
    id: str
    props: Mapping[str, Value]
    children: tuple[XmlNode, ...] = ()
    where: str = ""

    def label(self) -> str:
        """``<bsdf type='dielectric' id='glass'>``: how messages name the element."""
        ident = f" id={self.id!r}" if self.id and not self.id.startswith("_unnamed") else ""
        return f"<{self.kind} type={self.plugin!r}{ident}>"

    def number(self, key: str, default: float) -> float:
        """Parameter *key* as a number (*default* when absent); one line otherwise."""
        value = self.props.get(key, default)
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise SceneError(f"{key} {value!r} in {self.label()}; expected a number")
        return float(value)

    def integer(self, key: str, default: int) -> int:
        """Parameter *key* as a whole number (*default* when absent); one line otherwise."""
        value = self.props.get(key, default)
        if isinstance(value, bool) or not isinstance(value, int):
            raise SceneError(f"{key} {value!r} in {self.label()}; expected a whole number")
        return value


@dataclass(frozen=True)
class ParsedXml:
    """The scene's root node and the fixes made to old-version content (one phrase each)."""

    root: XmlNode
    fixes: tuple[str, ...] = field(default=())


#: Old-version names Mitsuba's upgrade leaves (snake_case of 0.5 names) and what they mean now.
_RENAMED = {"ext_eta": "ext_ior", "int_eta": "int_ior"}
#: 0.5 sun/sky parameters renamed in Mitsuba 3.
_SUNSKY = {"sun_radius_scale": "sun_scale"}


def _value(mi: Any, props: Any, key: str, nodes: list[XmlNode | None]) -> Value:
    kind = props.type(key)
    t = mi.Properties.Type
    raw = props[key]
    if kind == t.ResolvedReference:
        node = nodes[raw.index()]
        if node is None:
            raise SceneError(f"property {key!r} refers to an element not read yet")
        return node
    if kind == t.Transform:
        return np.array(raw.matrix, dtype=np.float64)
    if kind in (t.Vector, t.Color):
        return np.array(raw, dtype=np.float64).reshape(-1)
    if kind == t.Spectrum:
        wl = tuple(float(w) for w in raw.wavelengths)
        values = tuple(float(v) for v in raw.values)
        return Spectrum(wl, values) if wl else float(values[0])
    if kind in (t.Bool, t.Integer, t.Float, t.String):
        return raw  # type: ignore[no-any-return]
    raise SceneError(f"property {key!r} of an unsupported type ({kind})")


def _renames(node: XmlNode, props: dict[str, Value]) -> list[str]:
    said = []
    for old, new in _RENAMED.items():
        if old in props and new not in props:
            props[new] = props.pop(old)
            said.append(f"{node.label()} {old} -> {new}")
    return said


def _bitmap(node: XmlNode, props: dict[str, Value]) -> list[str]:
    said = []
    if props.get("filter_type") == "trilinear":
        props["filter_type"] = "bilinear"
        said.append(f"{node.label()} filter_type trilinear -> bilinear")
    if "gamma" in props:
        gamma = props.pop("gamma")
        props["raw"] = gamma == 1.0
        said.append(f"{node.label()} gamma {gamma} -> raw={props['raw']}")
    return said


def _sunsky(node: XmlNode, props: dict[str, Value]) -> list[str]:
    said = []
    for old, new in _SUNSKY.items():
        if old in props:
            props[new] = props.pop(old)
            said.append(f"{node.label()} {old} -> {new}")
    for gone in ("resolution", "stretch"):
        if gone in props:
            props.pop(gone)
            said.append(f"{node.label()} {gone} dropped (not in Mitsuba 3)")
    return said


def _fix(node: XmlNode, version: str) -> tuple[XmlNode, list[str]]:
    """*node* with the usual old-version fixes, and the phrases naming them."""
    if version.startswith("3"):
        return node, []
    props = dict(node.props)
    said = _renames(node, props)
    said += _bitmap(node, props) if node.plugin == "bitmap" else []
    said += _sunsky(node, props) if node.plugin == "sunsky" else []
    children = list(node.children)
    if node.plugin == "bumpmap":  # a height map is data, not a colour: read without sRGB
        for i, c in enumerate(children):
            if c.plugin == "bitmap" and c.props.get("raw") is not True:
                children[i] = replace(c, props={**c.props, "raw": True})
                said.append(f"{node.label()} {c.label()} read raw")
    return replace(node, props=props, children=tuple(children)), said


def _mitsuba() -> Any:
    """Mitsuba, imported through spectrinsic's set-up step (so Dr.Jit loads a suitable
    ``libLLVM`` even when a scene is read before any render), with a variant set: the one
    already chosen (the renderer's), else ``scalar_rgb``, since reading a Transform or a mesh
    needs the scalar types of some variant."""
    mi = import_mitsuba()
    if mi.variant() is None:
        mi.set_variant("scalar_rgb")
    return mi


def named_ior(name: str) -> float | None:
    """The index of refraction Mitsuba's own table (``ior.h``, as its ``dielectric`` plugins
    read ``int_ior``/``ext_ior``) gives *name* (``"bk7"``, ``"water"``, ``"air"``...), or
    ``None`` where Mitsuba knows no such name."""
    mi = _mitsuba()
    try:  # the one public door to the table: a dielectric of that index against a vacuum
        bsdf = mi.load_dict({"type": "dielectric", "int_ior": name, "ext_ior": 1.0})
    except RuntimeError:
        return None
    return float(mi.traverse(bsdf)["eta"])


def parse_xml(text: str, version: str) -> ParsedXml:
    """*text* (a prepared scene) parsed by Mitsuba's parser into :class:`XmlNode` records.

    Raises
    ------
    SceneError
        The parser's message, in one line.
    """
    mi = _mitsuba()
    variant = mi.variant()
    p = mi.parser
    config = p.ParserConfig(variant)
    try:
        state = p.parse_string(config, text)
        p.transform_upgrade(config, state)
        p.transform_resolve(config, state)
    except RuntimeError as exc:
        message = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise SceneError(message.split("] ", 1)[-1]) from None
    nodes: list[XmlNode | None] = [None] * len(state.nodes)
    fixes: list[str] = []
    # a node's references point to later nodes (children) or earlier ones (<ref>): read
    # children first by walking the list backwards, then references resolve either way
    for index in _order(mi, state):
        n = state.nodes[index]
        props, children = {}, []
        for key in n.props.keys():
            value = _value(mi, n.props, key, nodes)
            if key.startswith("_arg_") and isinstance(value, XmlNode):
                children.append(value)
            else:
                props[key] = value
        kind = str(n.type).rsplit(".", 1)[-1].lower()
        node = XmlNode(kind, n.props.plugin_name(), n.props.id(), props, tuple(children))
        _check_finite(node)
        nodes[index], said = _fix(node, version)
        fixes += said
    root = nodes[0]
    assert root is not None
    return ParsedXml(root, tuple(fixes))


def _check_finite(node: XmlNode) -> None:
    """Refuse a number, point, colour, spectrum or transform of *node* holding infinity or
    NaN (``inf``, ``nan``, or a value beyond float range such as ``1e400``, which the parser
    reads as infinity) before any arithmetic with it: one line instead of a RuntimeWarning and
    a NaN spreading into derived values."""
    for key, value in node.props.items():
        if isinstance(value, bool | str | XmlNode):
            continue
        if isinstance(value, Spectrum):
            numbers = np.asarray(value.wavelengths + value.values, float)
        else:
            numbers = np.asarray(value, float)
        if not np.isfinite(numbers).all():
            what = "transform" if numbers.shape == (4, 4) else "value"
            raise SceneError(
                f"{node.label()}: its {key} {what} holds a non-finite number (inf, nan, or a "
                "value beyond float range such as 1e400); expected finite numbers"
            )


def _order(mi: Any, state: Any) -> list[int]:
    """Node indices with every referenced node before its referrer (a DFS post-order)."""
    out: list[int] = []
    seen: set[int] = set()
    kinds = mi.Properties.Type

    def visit(i: int, stack: frozenset[int]) -> None:
        if i in seen:
            return
        if i in stack:
            raise SceneError("a <ref> cycle")
        props = state.nodes[i].props
        for key in props.keys():
            if props.type(key) == kinds.ResolvedReference:
                visit(props[key].index(), stack | {i})
        seen.add(i)
        out.append(i)

    for i in range(len(state.nodes)):
        visit(i, frozenset())
    return out


def _load_mesh(plugin: str, path: str, index: int) -> Any:
    mi = _mitsuba()
    spec: dict[str, Any] = {"type": plugin, "filename": path}
    if plugin == "serialized":
        spec["shape_index"] = index
    try:
        return mi.traverse(mi.load_dict(spec))
    except RuntimeError as exc:
        message = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise SceneError(f"cannot read it ({message.rsplit('] ', 1)[-1]})") from None


def mesh_file(plugin: str, path: str, index: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Vertices ``(V, 3)`` and faces ``(F, 3)`` of a mesh file (a ``serialized`` file's mesh
    *index*), read by Mitsuba's own loader of that one built-in shape (the caller checked the
    file and its declared size). Positions come back as Mitsuba stores them, float32."""
    params = _load_mesh(plugin, path, index)
    v = np.array(params["vertex_positions"], dtype=np.float64).reshape(-1, 3)
    return v, np.array(params["faces"], dtype=np.int64).reshape(-1, 3)


def mesh_file_uv(
    plugin: str, path: str, index: int = 0
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`mesh_file` and the texture coordinates ``(V, 2)`` Mitsuba's loader gives each
    vertex, in Mitsuba's convention (its OBJ loader stores ``1 - vt``: v = 0 is the image's
    top row); ``(V, 0)`` where the file has none."""
    params = _load_mesh(plugin, path, index)
    v = np.array(params["vertex_positions"], dtype=np.float64).reshape(-1, 3)
    f = np.array(params["faces"], dtype=np.int64).reshape(-1, 3)
    has_uv = "vertex_texcoords" in params.keys()
    uv = np.array(params["vertex_texcoords"], dtype=np.float64) if has_uv else np.zeros(0)
    return v, f, uv.reshape(len(v), -1) if uv.size else np.zeros((len(v), 0))
