"""The files of a Mitsuba XML scene, checked before anything is loaded.

A scene file is untrusted. Before Mitsuba's parser sees it (:mod:`~spectrinsic.scenes.mitsuba_tree`),
:func:`prepare_xml` reads it with :mod:`xml.etree.ElementTree` and

- refuses a scene file that is not a regular file (a FIFO would hang the read), one over
  :data:`MAX_XML_BYTES`, and DOCTYPE or ENTITY declarations (entity bombs);
- inlines every ``<include filename=...>`` itself (at most :data:`MAX_INCLUDES` files, nested at
  most :data:`MAX_INCLUDE_DEPTH` deep, :data:`MAX_TOTAL_XML_BYTES` in all), so the parser
  reads no file;
- reads every ``<spectrum filename=...>`` (a Mitsuba ``.spd`` file) into written-out samples;
- checks every other file the scene names (``<string name="filename">``: meshes, bitmaps,
  ``csv:`` spectra) without reading it.

Every path is relative to the scene file's folder, resolved inside it (``..`` and symbolic links
that lead out are refused) and a regular file. :class:`SceneFile` records each one with its
SHA-256 (provenance, ``scene.metadata["files"]``). ``$name`` references in file names take the
``<default>`` values of the top file.
"""

from __future__ import annotations

import hashlib
import re
import stat
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from ..errors import SceneError
from ..spectra.io import read_spd
from ..spectra.user_spectra import split_csv_key

__all__ = [
    "MAX_XML_BYTES",
    "MAX_TOTAL_XML_BYTES",
    "MAX_INCLUDES",
    "MAX_INCLUDE_DEPTH",
    "SceneFile",
    "PreparedXml",
    "prepare_xml",
    "regular_file",
    "confined_file",
    "file_sha256",
]

#: Largest scene (or included) XML file read, in bytes.
MAX_XML_BYTES = 4 * 1024 * 1024
#: Most bytes of XML in one scene, its includes counted.
MAX_TOTAL_XML_BYTES = 4 * MAX_XML_BYTES
#: Most ``<include>`` files in one scene, and their deepest nesting.
MAX_INCLUDES = 256
MAX_INCLUDE_DEPTH = 8


@dataclass(frozen=True)
class SceneFile:
    """A file a scene reads: *path* relative to the scene's folder, its role (``include``,
    ``spd``, ``csv`` or ``file``: a mesh or bitmap) and SHA-256."""

    path: str
    role: str
    sha256: str


@dataclass(frozen=True)
class PreparedXml:
    """The scene's XML with includes inlined and ``.spd`` spectra written out, its format
    version (``"3.0.0"``, ``"0.5.0"``) and the files it names."""

    text: str
    version: str
    files: tuple[SceneFile, ...]


def regular_file(path: Path, what: str) -> None:
    """Refuse *path* unless it is an existing regular file (a FIFO or device would block)."""
    try:
        mode = path.stat().st_mode
    except OSError:
        raise SceneError(f"{what}: {str(path)!r} not found") from None
    if not stat.S_ISREG(mode):
        raise SceneError(f"{what}: {str(path)!r} is not a regular file")


def confined_file(rel: str, base: Path, what: str) -> Path:
    """*rel* resolved inside folder *base*, an existing regular file; one line otherwise."""
    root = base.resolve()
    if not rel or Path(rel).is_absolute() or re.match(r"^[A-Za-z]:[\\/]", rel):
        raise SceneError(f"{what}: filename {rel!r}; expected a path inside the scene's folder")
    path = (root / rel).resolve()
    if not path.is_relative_to(root):
        raise SceneError(f"{what}: filename {rel!r}; expected a path inside the scene's folder")
    regular_file(path, what)
    return path


def file_sha256(path: Path) -> str:
    """SHA-256 (hex) of the file *path*, read in 1 MiB blocks."""
    digest = hashlib.sha256()
    with path.open("rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def _read_root(path: Path, what: str) -> ET.Element:
    regular_file(path, what)
    size = path.stat().st_size
    if size > MAX_XML_BYTES:
        raise SceneError(f"{what}: {size} bytes; expected a scene file of at most {MAX_XML_BYTES}")
    text = path.read_text(encoding="utf-8", errors="replace")
    if re.search(r"<!(DOCTYPE|ENTITY)", text):
        raise SceneError(f"{what}: DOCTYPE and ENTITY declarations are not allowed")
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise SceneError(f"{what}: malformed XML ({exc})") from None
    if root.tag != "scene":
        raise SceneError(f"{what}: root element <{root.tag}>; expected <scene>")
    return root


class _Reader:
    """One pass over the scene file and its includes (module docstring)."""

    def __init__(self, base: Path, defaults: dict[str, str]) -> None:
        self.base = base
        self.defaults = defaults
        self.files: dict[str, SceneFile] = {}
        self.includes = 0
        self.xml_bytes = 0

    def substitute(self, value: str, what: str) -> str:
        out = re.sub(r"\$(\w+)", lambda m: self.defaults.get(m.group(1), m.group(0)), value)
        if "$" in out:
            raise SceneError(f"{what}: {value!r} names a parameter with no <default>")
        return out

    def record(self, rel: str, role: str, what: str) -> Path:
        path = confined_file(rel, self.base, what)
        key = path.relative_to(self.base.resolve()).as_posix()
        if key not in self.files:
            self.files[key] = SceneFile(key, role, file_sha256(path))
        return path

    def expand(self, root: ET.Element, version: str, depth: int) -> None:
        """Check and rewrite *root*'s subtree in place (module docstring)."""
        for parent in list(root.iter()):
            for i, el in enumerate(list(parent)):
                if el.tag == "include":
                    self.include(parent, i, el, version, depth)
                else:
                    self.check(el)

    def include(self, parent: ET.Element, i: int, el: ET.Element, version: str, depth: int) -> None:
        rel = self.substitute(el.get("filename", ""), "<include>")
        self.includes += 1
        if self.includes > MAX_INCLUDES or depth >= MAX_INCLUDE_DEPTH:
            raise SceneError(
                f"<include filename={rel!r}>: more than {MAX_INCLUDES} includes or nested deeper "
                f"than {MAX_INCLUDE_DEPTH}"
            )
        path = self.record(rel, "include", "<include>")
        self.xml_bytes += path.stat().st_size
        if self.xml_bytes > MAX_TOTAL_XML_BYTES:
            raise SceneError(
                f"<include filename={rel!r}>: the scene's XML passes {MAX_TOTAL_XML_BYTES} bytes "
                "with its includes"
            )
        inner = _read_root(path, rel)
        if inner.get("version", version) != version:
            raise SceneError(
                f"<include filename={rel!r}>: version {inner.get('version')!r} differs from the "
                f"scene's {version!r}; upgrade one file to the other's version"
            )
        self.expand(inner, version, depth + 1)
        index = list(parent).index(el)
        parent.remove(el)
        for k, child in enumerate(list(inner)):
            parent.insert(index + k, child)

    def check(self, el: ET.Element) -> None:
        if el.tag == "spectrum" and "filename" in el.attrib:
            rel = self.substitute(el.attrib.pop("filename"), "<spectrum filename>")
            path = self.record(rel, "spd", "<spectrum>")
            wl, values = read_spd(path)
            samples = zip(wl.tolist(), values.tolist())
            el.set("value", ", ".join(f"{w!r}:{v!r}" for w, v in samples))
        value = el.get("value", "")
        if el.tag == "string" and el.get("name") == "filename":
            rel = self.substitute(value, f"<string name='filename' value={value!r}>")
            self.record(rel, "file", "<string name='filename'>")
        elif el.tag == "string" and value.strip().lower().startswith("csv:"):
            rel, _ = split_csv_key(value.strip()[4:])
            self.record(rel, "csv", f"<string value={value!r}>")


def prepare_xml(path: Path) -> PreparedXml:
    """The scene file *path* checked and made self-standing (module docstring).

    Raises
    ------
    SceneError
        One phrase naming the element or file (the caller prefixes the scene file).
    """
    root = _read_root(path, "scene file")
    version = root.get("version", "")
    if not version:
        raise SceneError("<scene> has no version attribute; expected e.g. version='3.0.0'")
    defaults = {d.get("name", ""): d.get("value", "") for d in root.iter("default")}
    reader = _Reader(path.parent, defaults)
    reader.xml_bytes = path.stat().st_size
    reader.expand(root, version, 0)
    text = ET.tostring(root, encoding="unicode")
    return PreparedXml(text, version, tuple(reader.files.values()))
