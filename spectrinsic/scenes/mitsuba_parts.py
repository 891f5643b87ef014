"""Pieces of Mitsuba 3 XML scenes for :mod:`spectrinsic.scenes.mitsuba_xml`: ``to_world``
transforms, the built-in shapes as triangles, and spectra and colours as registry names.

Conventions follow Mitsuba 3's documentation: transform operations apply in document order
(each one left-multiplies); ``rectangle`` spans [-1, 1]² at z = 0 with normal +z, ``cube``
[-1, 1]³, ``disk`` the unit disk at z = 0, ``sphere`` a ``center`` and ``radius``; a
``lookat`` maps +z to the viewing direction.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np

from ..errors import SceneError
from ..spectra.illuminants import normalise_illuminant
from ..spectra.user_spectra import inline_name

__all__ = [
    "numbers",
    "transform",
    "rectangle",
    "cube",
    "disk",
    "sphere",
    "reflectance_name",
    "emission",
]

#: Segments of a tessellated disk and sphere (longitude; a sphere has half as many rings).
SEGMENTS = 32


def numbers(text: str | None, n: int | None, what: str) -> np.ndarray:
    """The numbers in *text* (comma or space separated); exactly *n* unless ``None``."""
    try:
        values = np.array([float(x) for x in (text or "").replace(",", " ").split()])
    except ValueError:
        raise SceneError(f"{what}: {text!r} is not a list of numbers") from None
    if (n is not None and values.size != n) or values.size == 0 or not np.isfinite(values).all():
        raise SceneError(f"{what}: {text!r}; expected {n or 'some'} finite numbers")
    return values


def _xyz(el: ET.Element, default: float, what: str) -> np.ndarray:
    if "value" in el.attrib:
        v = numbers(el.get("value"), None, what)
        return np.repeat(v, 3) if v.size == 1 else numbers(el.get("value"), 3, what)
    return np.array([float(el.get(k, default)) for k in "xyz"])


def _rotation(axis: np.ndarray, angle_deg: float) -> np.ndarray:
    a = axis / np.linalg.norm(axis)
    c, s = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    m = np.eye(4)
    m[:3, :3] = c * np.eye(3) + s * k + (1 - c) * np.outer(a, a)
    return m


def _lookat(el: ET.Element, what: str) -> np.ndarray:
    origin = numbers(el.get("origin"), 3, f"{what} origin")
    target = numbers(el.get("target"), 3, f"{what} target")
    up = numbers(el.get("up", "0 1 0"), 3, f"{what} up")
    d = target - origin
    left = np.cross(up, d)
    if not (np.linalg.norm(d) > 0 and np.linalg.norm(left) > 0):
        raise SceneError(f"{what}: lookat with a zero or vertical-to-up direction")
    d, left = d / np.linalg.norm(d), left / np.linalg.norm(left)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = left, np.cross(d, left), d, origin
    return m


def transform(el: ET.Element | None, what: str) -> np.ndarray:
    """The 4 × 4 matrix of a ``<transform>`` element (identity for ``None``)."""
    m = np.eye(4)
    for op in [] if el is None else list(el):
        step = np.eye(4)
        if op.tag == "translate":
            step[:3, 3] = _xyz(op, 0.0, f"{what} translate")
        elif op.tag == "scale":
            step[:3, :3] = np.diag(_xyz(op, 1.0, f"{what} scale"))
        elif op.tag == "rotate":
            axis = _xyz(op, 0.0, f"{what} rotate") if "value" in op.attrib else None
            axis = axis if axis is not None else np.array([float(op.get(k, 0)) for k in "xyz"])
            if not np.linalg.norm(axis) > 0:
                raise SceneError(f"{what}: rotate needs a non-zero axis")
            step = _rotation(axis, float(op.get("angle", 0)))
        elif op.tag == "matrix":
            step = numbers(op.get("value"), 16, f"{what} matrix").reshape(4, 4)
        elif op.tag == "lookat":
            step = _lookat(op, what)
        else:
            raise SceneError(f"{what}: unsupported transform element <{op.tag}>")
        m = step @ m
    return m


def apply(m: np.ndarray, vertices: np.ndarray) -> np.ndarray:
    """*vertices* ``(V, 3)`` mapped by the 4 × 4 matrix *m*."""
    return vertices @ m[:3, :3].T + m[:3, 3]


def rectangle() -> tuple[np.ndarray, np.ndarray]:
    """Vertices and faces of Mitsuba's ``rectangle``."""
    v = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], float)
    return v, np.array([[0, 1, 2], [0, 2, 3]])


def cube() -> tuple[np.ndarray, np.ndarray]:
    """Vertices and outward faces of Mitsuba's ``cube``, [-1, 1]³."""
    v = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    faces = [f for a, b, c, d in quads for f in ((a, b, c), (a, c, d))]
    return v, np.array(faces)


def disk() -> tuple[np.ndarray, np.ndarray]:
    """The unit disk at z = 0 (normal +z) as a fan of :data:`SEGMENTS` triangles."""
    t = np.linspace(0, 2 * np.pi, SEGMENTS, endpoint=False)
    v = np.vstack([[0, 0, 0], np.stack([np.cos(t), np.sin(t), np.zeros_like(t)], 1)])
    i = np.arange(SEGMENTS)
    return v, np.stack([np.zeros_like(i), 1 + i, 1 + (i + 1) % SEGMENTS], 1)


def sphere(center: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """A UV sphere of :data:`SEGMENTS` longitudes, outward faces."""
    rings, seg = SEGMENTS // 2, SEGMENTS
    theta = np.linspace(0, np.pi, rings + 1)[1:-1]
    phi = np.linspace(0, 2 * np.pi, seg, endpoint=False)
    st, ct = np.sin(theta)[:, None], np.cos(theta)[:, None]
    ring = np.stack([st * np.cos(phi), st * np.sin(phi), np.broadcast_to(ct, (rings - 1, seg))], -1)
    v = np.vstack([[0, 0, 1], ring.reshape(-1, 3), [0, 0, -1]])
    faces = []
    south = len(v) - 1
    for j in range(seg):
        k = (j + 1) % seg
        faces.append((0, 1 + j, 1 + k))
        for r in range(rings - 2):
            a, b = 1 + r * seg + j, 1 + r * seg + k
            faces += [(a, a + seg, b + seg), (a, b + seg, b)]
        last = 1 + (rings - 2) * seg
        faces.append((last + j, south, last + k))
    return center + radius * v, np.array(faces)


def _samples(text: str, what: str) -> tuple[np.ndarray, np.ndarray]:
    """``"400:0.1, 500:0.2"`` as wavelengths and values."""
    try:
        pairs = [tuple(float(x) for x in p.split(":")) for p in text.split(",") if p.strip()]
        wl, values = np.array(pairs).reshape(-1, 2).T
    except ValueError:
        raise SceneError(f"{what}: {text!r}; expected 'WL:VALUE, ...' or one number") from None
    return wl, values


def reflectance_name(el: ET.Element | None, what: str) -> str:
    """The reflectance spectrum name of an ``rgb``, ``spectrum`` or ``float`` element
    (Mitsuba's default 0.5 for ``None``): ``rgb:`` (linear, :mod:`~spectrinsic.spectra.user_spectra`),
    ``inline:`` or ``flat:``."""
    if el is None:
        return "flat:0.5"
    value = el.get("value", "")
    if el.tag == "rgb":
        return "rgb:" + ",".join(f"{c:.9g}" for c in numbers(value, 3, what))
    if el.tag == "float" or (el.tag == "spectrum" and ":" not in value):
        return f"flat:{numbers(value, 1, what)[0]:.9g}"
    if el.tag == "spectrum" and "filename" not in el.attrib:
        return inline_name(*_samples(value, what), "reflectance")
    raise SceneError(f"{what}: unsupported <{el.tag}> {dict(el.attrib)}; expected rgb or spectrum")


def emission(el: ET.Element | None, what: str) -> tuple[str, float]:
    """``(illuminant name, power)`` of an emitter's ``rgb`` or ``spectrum`` element.

    A spectrum keeps its absolute scale in the power (the registry normalises every illuminant
    to unit luminance-weighted mean); one number is equal energy (``cie:E``); a grey ``rgb`` is
    D65, as Mitsuba's spectral variants emit it; a coloured ``rgb`` is refused."""
    if el is None:
        raise SceneError(f"{what}: the emitter gives no radiance, intensity or irradiance")
    value = el.get("value", "")
    if el.tag == "rgb":
        rgb = numbers(value, 3, what)
        if not (np.ptp(rgb) == 0 and rgb[0] > 0):
            raise SceneError(f"{what}: coloured rgb emission {value!r}; give a spectrum")
        return "cie:D65", float(rgb[0])
    if el.tag in ("spectrum", "float") and ":" not in value and "filename" not in el.attrib:
        return "cie:E", float(numbers(value, 1, what)[0])
    if el.tag == "spectrum" and "filename" not in el.attrib:
        wl, values = _samples(value, what)
        if not (np.diff(wl) > 0).all() or not (values >= 0).all():
            raise SceneError(f"{what}: expected increasing wavelengths and values >= 0")
        power = float(values.sum() / normalise_illuminant(wl, values).sum())
        return inline_name(wl, values, "illuminant"), power
    raise SceneError(f"{what}: unsupported <{el.tag}> {dict(el.attrib)}; expected rgb or spectrum")
