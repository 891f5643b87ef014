"""The writer's side of :mod:`~spectrinsic.gt_export.sample.layer_storage` (issue 45): which
layers of a sample it stores as their factors (those whose factors rebuild them bit for bit,
tried on every sample) and which estimates it stores as float16.
"""

from __future__ import annotations

import fnmatch
import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..formats.exr import DEFAULT_COMPRESSION
from ..layers.records import GroundTruth
from .layer_storage import (
    BAND_FACTORS,
    BAND_FORMS,
    COVERAGE_LAYER,
    TABLE_ATTRIBUTE,
    layer_sha256,
    rebuild,
)
from .transport_cube import MEANS_ATTRIBUTE, CubeFactors

__all__ = ["HALF_PREFIXES", "PIZ_FILES", "StoredLayers", "compression_of", "stored_layers"]

#: Layers outside every identity, estimates rather than ground truth, stored as float16: the
#: noise maps (relative standard error of the batches; their float16 rounding, 4.9e-4 of the
#: value, is far below their own sampling error, and they come from the transport's float16
#: deviations in relit samples anyway). The error maps of the 3- and 6-sensor images stay
#: float32: relit ones must equal a direct render's within 1e-5 like every other layer.
HALF_PREFIXES = ("noise_",)
_HALF_MAX = float(np.finfo(np.float16).max)
#: Files written with PIZ instead of ZIP (lossless both), chosen by measurement on the default
#: 256² two-light room (``make bench``, storage): Monte Carlo noise in float32 images packs
#: tighter with PIZ (``spectral.exr`` 15.7 -> 13.5 MB, ``image.exr`` 4.27 -> 3.94 MB, each camera
#: file 2.33 -> 2.25 MB; read back as fast), piecewise-constant layers (reflectance, ids,
#: coverage, the intrinsics' grey shading) with ZIP.
PIZ_FILES = ("spectral.exr", "image.exr", "camera-*.exr")


def compression_of(file: str) -> str:
    """The EXR compression of a sample's layer file *file* (:data:`PIZ_FILES`, else ZIP)."""
    return "piz" if any(fnmatch.fnmatchcase(file, p) for p in PIZ_FILES) else DEFAULT_COMPRESSION


@dataclass(frozen=True)
class StoredLayers:
    """What :func:`stored_layers` decided: per file the EXR layers to write, their channel names
    and header attributes, and the form of every layer not stored in full."""

    arrays: dict[str, dict[str, np.ndarray]]
    channels: dict[str, dict[str, tuple[str, ...]]]
    attributes: dict[str, dict[str, str]]
    forms: dict[str, str] = field(default_factory=dict)
    #: :func:`layer_sha256` of every layer in *forms*, as the writer computed it.
    hashes: dict[str, str] = field(default_factory=dict)
    #: The layers every layer in *forms* is rebuilt from, in the form's order.
    terms: dict[str, list[str]] = field(default_factory=dict)
    #: Layers stored as float16 (:func:`_half_layers`).
    half: list[str] = field(default_factory=list)

    def record(self) -> dict[str, Any]:
        """``meta.json["storage"]``."""
        return {
            "layers": dict(sorted(self.forms.items())),
            "terms": dict(sorted(self.terms.items())),
            "sha256": dict(sorted(self.hashes.items())),
            "half": list(self.half),
        }


def _file(group: str) -> str:
    return f"{group}.exr"


def _identity_terms(identities: Sequence[Mapping[str, Any]], key: str) -> list[str]:
    """``[image, reflectance, shading(, specular)]`` of the identity whose residual is *key*."""
    for ident in identities:
        if isinstance(ident, Mapping) and ident.get("residual") == key:
            terms = [ident.get(k) for k in ("image", "reflectance", "shading", "specular")]
            return [str(t) for t in terms if t is not None]
    return []


@dataclass(frozen=True)
class Candidate:
    """A layer the writer may store as *form* of the layers *terms*."""

    key: str
    form: str
    terms: tuple[str, ...]


def _candidates(gt: GroundTruth, identities: Sequence[Mapping[str, Any]]) -> list[Candidate]:
    """Every ``(layer, form, terms)`` the writer tries, in an order where a layer's terms come
    first; an identity's residual last, so its terms may be rebuilt ones."""
    have = gt.layers
    spec = ["specular_bands"] if "specular_bands" in have else []
    out = [
        Candidate("image_bands_raw", "transport_sum", ()),
        Candidate("image_bands", "transport_sum", ()),  # the cube itself where not denoised
        Candidate("cube", "transport_sum", ()),
        Candidate("reflectance_bands", "coverage_table", ()),
        Candidate("image_bands", "band_image", (*BAND_FACTORS, *spec)),
        Candidate("shading_ratio", "ratio", ("image", "reflectance")),
    ]
    for key in have:  # illuminant, illuminant_camera/<name>: shading / shading_grey
        if key.split("/", 1)[0] in ("illuminant", "illuminant_camera"):
            shading = key.replace("illuminant", "shading", 1)
            out.append(Candidate(key, "unit_luminance", (shading, "shading_grey")))
    out += [
        Candidate(
            str(i["residual"]),
            "identity_residual",
            tuple(_identity_terms(identities, str(i["residual"]))),
        )
        for i in identities
    ]
    return out


def stored_layers(
    gt: GroundTruth,
    coverage: np.ndarray | None,
    identities: Sequence[Mapping[str, Any]],
    cube: CubeFactors | None = None,
) -> StoredLayers:
    """The EXR content of *gt*: every layer in full, except those whose factors rebuild them
    bit for bit (module notes). *coverage* is the render's ``(H, W, M)`` AOV, *cube* the
    factors of the cube of a sample stored with its transport."""
    values = {k: layer.data for k, layer in gt.layers.items()}
    factors = None
    if coverage is not None and gt.band_albedos is not None and "reflectance_bands" in values:
        factors = (np.asarray(coverage, np.float32), np.asarray(gt.band_albedos, np.float64))
    forms: dict[str, str] = {}
    terms: dict[str, list[str]] = {}
    for c in _candidates(gt, identities):
        if c.key not in forms and _rebuilds(c, values, factors, cube):
            forms[c.key], terms[c.key] = c.form, list(c.terms)
    # a header needs a file: the cube's ē is kept by a file that stores some layer in full
    kept = {_file(layer.group) for k, layer in gt.layers.items() if k not in forms}
    for key in [k for k, f in forms.items() if f == "transport_sum"]:
        if _file(gt.layers[key].group) not in kept:
            del forms[key], terms[key]
    arrays: dict[str, dict[str, np.ndarray]] = {}
    channels: dict[str, dict[str, tuple[str, ...]]] = {}
    attributes: dict[str, dict[str, str]] = {}
    for key, layer in gt.layers.items():
        file = _file(layer.group)
        arrays.setdefault(file, {})
        channels.setdefault(file, {})
        if key not in forms:
            name = key.split("/", 1)[0]
            arrays[file][name] = layer.data
            channels[file][name] = layer.channels
        elif forms[key] == "transport_sum" and cube is not None:
            attributes.setdefault(file, {})[MEANS_ATTRIBUTE.format(layer=key)] = cube.attribute()
        elif forms[key] == "coverage_table" and factors is not None:
            arrays[file][COVERAGE_LAYER] = factors[0]
            channels[file][COVERAGE_LAYER] = tuple(f"m{m}" for m in range(factors[0].shape[-1]))
            attributes.setdefault(file, {})[TABLE_ATTRIBUTE.format(layer=key)] = json.dumps(
                factors[1].tolist(), separators=(",", ":"), allow_nan=False
            )
    half = _half_layers(gt, forms, terms, identities)
    for key in half:
        arrays[_file(gt.layers[key].group)][key] = gt.layers[key].data.astype(np.float16)
    hashes = {k: layer_sha256(values[k]) for k in forms}
    return StoredLayers(arrays, channels, attributes, forms, hashes, terms, half)


def _rebuilds(
    c: Candidate,
    values: Mapping[str, np.ndarray],
    factors: tuple[np.ndarray, np.ndarray] | None,
    cube: CubeFactors | None,
) -> bool:
    """Whether *c*'s form and terms give its layer back bit for bit; *factors* are the band
    forms' ``(coverage, table)``, *cube* the ``transport_sum`` form's."""
    if c.key not in values or c.key in c.terms or any(t not in values for t in c.terms):
        return False
    if c.form == "transport_sum":
        factors = None if cube is None else (cube.means, cube.light_means)
    elif c.form not in BAND_FORMS:
        factors = None
    needs = c.form in BAND_FORMS or c.form == "transport_sum"
    if (needs and factors is None) or (c.form == "identity_residual" and not c.terms):
        return False
    return bool(np.array_equal(rebuild(c.key, c.form, c.terms, values, factors), values[c.key]))


def _half_layers(
    gt: GroundTruth,
    forms: Mapping[str, str],
    terms: Mapping[str, Sequence[str]],
    identities: Sequence[Mapping[str, Any]],
) -> list[str]:
    """The estimates (:data:`HALF_PREFIXES`) that no identity and no rebuilt layer uses, whose
    values float16 holds (finite, at most 65504)."""
    used = {str(v) for i in identities for v in i.values()}
    used |= {t for ts in terms.values() for t in ts}
    out = []
    for key, layer in gt.layers.items():
        if not key.startswith(HALF_PREFIXES) or key in forms or key in used or "/" in key:
            continue
        data = np.asarray(layer.data)
        if data.dtype == np.float32 and np.isfinite(data).all() and np.abs(data).max() <= _HALF_MAX:
            out.append(key)
    return sorted(out)
