"""An interactive static gallery of a dataset, and contact sheets of its images.

:func:`build_gallery` writes, into the dataset folder,

* ``index.html``, ``gallery.js`` and ``gallery.css``: a page that opens from the file system (no
  server, no network) and renders only the current page of samples, with lazy thumbnails;
* ``gallery.json``: the index (per sample its scene, generator, condition, kind, split, noise figure,
  lights with their SPDs, chromaticities and shares, every layer's preview with its encoding,
  ``image_denoised`` first where it exists, and the previous and next sample's ids), and
  ``gallery-index.js``, the same index assigned to ``window.SPECTRINSIC_GALLERY`` (a page opened
  from ``file://`` may not ``fetch()`` a local JSON file, but it may load a script);
* ``contact_sheet.png`` (every sample) and ``contact_sheets/<condition>.png`` (one per condition);
* ``gallery-pixels/<id>.js``: a sample's previews as ``data:`` URLs, loaded when the sample is
  opened, for the pixel readout of a page opened from ``file://`` (see :func:`build_gallery`).

The page decodes a pixel of a preview back to the linear value it stands for from the layer's
``preview_encoding`` (``meta.json["layers"][name]``): ``srgb`` previews are sRGB-encoded
``clip(value × scale)``, ``colormap`` previews map ``[vmin, vmax]`` through a matplotlib colormap
(whose 256 colours the index carries), ``categorical`` ones have no scalar value.
"""

from __future__ import annotations

import base64
import html
import json
import os
import string
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import DatasetError
from ...file_writes import guarded_write, refuse_link, write_text_file
from ...scenes.lighting import describe_lighting
from ...spectra import get_sensors, xyz_to_xy
from ..formats.names import slug
from ..layers.spectral_intrinsics import rgb_residual_share
from ..sample import META_NAME, SCENE_NAME, plain_data, sample_dirs
from ..sample.meta import SampleMeta, read_meta
from .card import read_template
from .contact_sheet import contact_sheet
from .manifest import read_manifest

__all__ = [
    "build_gallery",
    "contact_sheet",
    "gallery_index",
    "scene_kind",
    "sensor_panel",
    "SENSOR_PANEL",
    "GALLERY_DIRS",
    "GALLERY_LAYERS",
    "INDEX_VARIABLE",
]

#: Layer order in the per-sample switcher (others follow in name order; camera views last).
#: ``image_denoised`` (``reflectance * shading + residual``, what a method should decompose)
#: comes first where a sample has it, so the page opens on it rather than the noisy render.
GALLERY_LAYERS: tuple[str, ...] = (
    "image_denoised",
    "image",
    "image_rgb3",
    "image_rgb6",
    "image_spectral",
    "reflectance",
    "shading",
    "shading_raw",
    "shading_grey",
    "shading_ratio",
    "residual",
    "residual_raw",
    "specular",
    "illuminant",
    "error_rgb3",
    "error_rgb6",
    "error_spectral",
    "noise_image",
    "noise_shading_raw",
    "depth",
    "normals",
    "material_id",
    "object_id",
    "semantic",
    "mask",
    "non_diffuse",
    "metallic",
    "transmissive",
    "roughness",
)
#: The JavaScript variable ``gallery-index.js`` assigns the index to.
INDEX_VARIABLE = "SPECTRINSIC_GALLERY"
#: Static files copied from ``gt_export/templates`` next to ``index.html``.
_STATIC = ("gallery.js", "gallery.css")
#: Significant digits of the lights' SPDs in the index (for plotting; every other number is
#: copied from ``meta.json`` unrounded, so preview encodings decode exactly).
_SPD_DIGITS = 5
#: Folder of the per-condition contact sheets and file-name pattern of summary plots.
_SHEETS_DIR = "contact_sheets"
_PIXELS_DIR = "gallery-pixels"
#: The folders the gallery writes into the dataset folder beside the sample folders.
GALLERY_DIRS: tuple[str, ...] = (_SHEETS_DIR, _PIXELS_DIR)
_SUMMARY_GLOBS = ("*.png", "plots/*.png", "summary/*.png", "figures/*.png")


def _spectral_locus() -> list[list[float]]:
    """xy of the CIE 1931 2° spectral locus, 380–700 nm at 1 nm (colour-science's CMFs)."""
    cmf = get_sensors("cie1931")
    keep = (cmf.wavelengths >= 380) & (cmf.wavelengths <= 700)
    return np.round(xyz_to_xy(cmf.curves[:, keep].T), 5).tolist()


def _srgb_primaries() -> dict[str, list[float]]:
    """xy of the sRGB primaries and of its white (D65), from colour-science."""
    import colour

    space = colour.RGB_COLOURSPACES["sRGB"]
    return {
        "primaries": np.asarray(space.primaries, float).round(5).tolist(),
        "white": np.asarray(space.whitepoint, float).round(5).tolist(),
    }


def _colormap_luts(names: Iterable[str]) -> dict[str, list[list[int]]]:
    """The 256 8-bit RGB colours of each named matplotlib colormap (as ``png.false_colour``
    quantises them), so the page can draw true colour bars and invert a colour to its value."""
    import matplotlib

    out = {}
    for name in sorted(set(names)):
        rgba = matplotlib.colormaps[name](np.linspace(0.0, 1.0, 256))
        out[name] = np.round(rgba[:, :3] * 255.0).astype(int).tolist()
    return out


def _split_of(splits: Mapping[str, Sequence[str]]) -> dict[str, str]:
    """Sample id -> split name from the manifest's ``{split: [ids]}``."""
    return {sid: split for split, ids in splits.items() for sid in ids}


def _noise_figure(meta: SampleMeta) -> float | None:
    """The median relative standard error of ``shading_raw`` (None when not measured)."""
    fig = meta.noise.get("shading_raw")
    return fig.median if fig is not None else None


def _layer_order(names: Iterable[str]) -> list[str]:
    """*names* in :data:`GALLERY_LAYERS` order, then the rest by name, camera views last."""
    rank = {name: i for i, name in enumerate(GALLERY_LAYERS)}
    return sorted(names, key=lambda n: ("/" in n, rank.get(n, len(rank)), n))


#: The camera chain's layers in the order light goes through it, with what each one shows.
SENSOR_PANEL: tuple[tuple[str, str], ...] = (
    ("raw_sensor", "1. raw Bayer mosaic (DN)"),
    ("image_sensor_noisy", "2. processed linear image, noise included"),
    ("processed_sensor", "3. tone-mapped output (display only)"),
    ("image_sensor", "ground truth: noise-free processed image"),
    ("reflectance_sensor", "ground truth: reflectance, carried through the chain"),
    ("shading_sensor", "ground truth: shading, carried through the chain"),
    ("residual_sensor", "ground truth: residual"),
)


def sensor_panel(layers: Iterable[str], sensor: Mapping[str, Any] | None) -> dict[str, Any] | None:
    """The gallery's camera-chain panel of a sample: its camera, the metered exposure
    (electrons per unit of the camera image) and its sensor layers in :data:`SENSOR_PANEL`
    order with their captions; ``None`` for a sample built without ``--camera``.

    >>> panel = sensor_panel(["image", "raw_sensor/Nikon D3", "shading_sensor/Nikon D3"],
    ...                      {"camera": "nikon-d3", "stages": {"exposure": {"electrons_per_unit": 9.5}}})
    >>> panel["camera"], [name for name, _ in panel["layers"]]
    ('nikon-d3', ['raw_sensor/Nikon D3', 'shading_sensor/Nikon D3'])
    """
    if not sensor:
        return None
    names = list(layers)
    ordered = [
        [name, caption]
        for base, caption in SENSOR_PANEL
        for name in names
        if name.split("/", 1)[0] == base
    ]
    exposure = (sensor.get("stages") or {}).get("exposure") or {}
    return {
        "camera": sensor.get("camera"),
        "electrons_per_unit": exposure.get("electrons_per_unit"),
        "layers": ordered,
    }


def _sample_entry(sample: Path, meta: SampleMeta, split: str | None) -> dict[str, Any]:
    """One sample's record in the index (paths relative to the dataset folder)."""
    smeta = meta.scene_metadata
    records = meta.layers
    layers = {
        name: [f"{sample.name}/{records[name].preview}", records[name].preview_encoding]
        for name in _layer_order(records)
        if records[name].preview
    }
    lights = [
        {
            "name": light.name,
            "spectrum": light.spectrum,
            "kind": light.kind,
            "xy": list(light.xy),
            "srgb": list(light.srgb),
            "share": light.share,
            "spd": [float(f"{v:.{_SPD_DIGITS}g}") for v in light.spd],
        }
        for light in meta.lights
    ]
    return {
        "id": sample.name,
        "scene": meta.scene,
        # a scene file's or a relit sample's lights say what its condition is
        "condition": ("relit_from" not in smeta and smeta.get("condition"))
        or describe_lighting(lights).family,
        # generated scenes name their generator; the built-in library and user scenes do not
        "generator": smeta.get("generator") or ("library" if "library" in smeta else "own scene"),
        "kind": scene_kind(meta),
        "split": split,
        "noise": _noise_figure(meta),
        # Σ|residual| / Σ|image| of the RGB layers (None for samples written before it)
        "residual_share": rgb_residual_share(meta.raw),
        "first_layer": next(iter(layers), None),
        "light_shares": [light["share"] for light in lights],
        "size": list(meta.size),
        "reference_mode": meta.reference_mode,
        "layers": layers,
        "sensor": sensor_panel(layers, meta.raw.get("sensor")),
        "lights": lights,
        "files": sorted(
            {f"{sample.name}/{r.file}" for r in records.values()}
            | {f"{sample.name}/{META_NAME}", f"{sample.name}/{SCENE_NAME}"}
        ),
    }


#: Scene kind of a generator's scenes, for samples whose metadata does not name it.
_GENERATOR_KINDS = {"objects-on-ground": "object", "rooms": "complex"}


def scene_kind(meta: SampleMeta) -> str:
    """``"object"`` or ``"complex"``: the scene's ``kind`` metadata, else its generator's, else
    by name (library object scenes start with ``obj-``, as :func:`spectrinsic.decompose.
    sample_fields.sample_kind` reads them); never empty, so the gallery's kind filter sees every
    sample."""
    smeta = meta.scene_metadata
    kind = smeta.get("kind") or _GENERATOR_KINDS.get(str(smeta.get("generator")))
    return str(kind) if kind else ("object" if meta.scene.startswith("obj") else "complex")


def _link_neighbours(entries: list[dict[str, Any]]) -> None:
    """``prev``/``next``: the neighbouring sample ids in index order (``None`` at the ends)."""
    for i, entry in enumerate(entries):
        entry["prev"] = entries[i - 1]["id"] if i > 0 else None
        entry["next"] = entries[i + 1]["id"] if i + 1 < len(entries) else None


def _layer_info(metas: Sequence[SampleMeta]) -> dict[str, dict[str, Any]]:
    """Per layer name (first sample holding it): file, EXR layer, channels and units."""
    info: dict[str, dict[str, Any]] = {}
    for meta in metas:
        for name, rec in meta.layers.items():
            info.setdefault(
                name,
                {
                    "file": rec.file,
                    "exr_layer": rec.exr_layer,
                    "channels": list(rec.channels),
                    "units": rec.units,
                },
            )
    return info


def gallery_index(dataset_dir: str | os.PathLike[str]) -> dict[str, Any]:
    """The gallery's index of *dataset_dir* as plain data (what ``gallery.json`` holds).

    Keys: ``samples`` (one record per sample, see the module docstring), ``layer_info``,
    ``colormaps`` (name -> 256 RGB triples), ``locus`` (CIE 1931 xy, 380–700 nm), ``srgb``
    (primaries and white), ``spd_grid`` (the lights' SPD grid in nm), ``splits`` (names, possibly
    empty), ``contact_sheets`` and ``summary_plots`` (paths relative to the dataset folder).
    """
    root = Path(dataset_dir)
    samples = sample_dirs(root)
    if not samples:
        raise DatasetError(f"dataset folder {str(root)!r} has no complete samples for a gallery")
    manifest = read_manifest(root)
    split_of = _split_of(manifest.splits) if manifest is not None else {}
    metas = [read_meta(s) for s in samples]
    entries = [
        _sample_entry(s, m, split_of.get(s.name)) for s, m in zip(samples, metas, strict=True)
    ]
    _link_neighbours(entries)
    cmaps = {
        enc["cmap"]
        for e in entries
        for _, enc in e["layers"].values()
        if isinstance(enc, Mapping) and enc.get("kind") == "colormap"
    }
    grid = metas[0].raw["spectral_grid"].get("lights_spd") or {}
    return {
        "title": f"spectrinsic dataset: {root.resolve().name}",
        "samples": entries,
        "layer_info": _layer_info(metas),
        "colormaps": _colormap_luts(cmaps),
        "locus": _spectral_locus(),
        "srgb": _srgb_primaries(),
        "spd_grid": {"start_nm": grid.get("start_nm", 380.0), "step_nm": grid.get("step_nm", 5.0)},
        "splits": sorted(set(split_of.values())),
        "contact_sheets": {},
        "summary_plots": _summary_plots(root),
    }


def _summary_plots(root: Path) -> list[str]:
    """Summary plots in the dataset folder (PNG files other than the contact sheets)."""
    found = {
        p.relative_to(root).as_posix() for pattern in _SUMMARY_GLOBS for p in root.glob(pattern)
    }
    return sorted(f for f in found if not f.startswith("contact_sheet"))


def _condition_sheets(root: Path, index: Mapping[str, Any]) -> dict[str, str]:
    """Write one contact sheet per condition; return condition -> path (relative to *root*)."""
    by_condition: dict[str, list[Path]] = {}
    for entry in index["samples"]:
        by_condition.setdefault(str(entry["condition"]), []).append(root / entry["id"])
    out = {}
    for condition, members in sorted(by_condition.items()):
        rel = f"{_SHEETS_DIR}/{slug(condition, fallback='none')}.png"
        contact_sheet(root, out=root / rel, samples=members)
        out[condition] = rel
    return out


#: How every ``gallery-pixels/<id>.js`` starts: the mark of a file the gallery wrote.
_PIXELS_HEAD = "(window.SPECTRINSIC_PIXELS = window.SPECTRINSIC_PIXELS || {})["


def _written_by_us(path: Path) -> bool:
    """Whether *path* is a pixel script the gallery wrote (a plain file starting with
    :data:`_PIXELS_HEAD`); anything else in ``gallery-pixels/`` is the user's and stays."""
    if path.is_symlink() or not path.is_file():
        return False
    try:
        with path.open(encoding="utf-8") as fh:
            return fh.read(len(_PIXELS_HEAD)) == _PIXELS_HEAD
    except (OSError, UnicodeDecodeError):
        return False


def _write_pixel_scripts(root: Path, index: Mapping[str, Any]) -> None:
    """Write ``gallery-pixels/<id>.js`` per sample: its value-bearing previews (``srgb`` and
    ``colormap`` encodings) as ``data:`` URLs, which a page opened from ``file://`` may read
    into a canvas (Chromium forbids reading the files themselves); set each entry's ``pixels``.
    Earlier scripts of ours are replaced; no other file in the folder is touched."""
    folder = root / _PIXELS_DIR
    refuse_link(folder / "index.js")  # the folder itself: never a link planted since the start
    with guarded_write(folder):
        folder.mkdir(exist_ok=True)
    for old in sorted(folder.glob("*.js")):
        if _written_by_us(old):
            old.unlink()
    for entry in index["samples"]:
        urls = {
            name: "data:image/png;base64,"
            + base64.b64encode((root / src).read_bytes()).decode("ascii")
            for name, (src, enc) in entry["layers"].items()
            if isinstance(enc, Mapping) and enc.get("kind") in ("srgb", "colormap")
        }
        rel = f"{_PIXELS_DIR}/{entry['id']}.js"
        target = root / rel
        if target.exists() and not _written_by_us(target):
            raise DatasetError(
                f"{target}: not a gallery file spectrinsic wrote; move it away to "
                "rebuild the gallery"
            )
        write_text_file(
            target,
            f"{_PIXELS_HEAD}{json.dumps(entry['id'], allow_nan=False)}] = {json.dumps(urls, allow_nan=False)};\n",
        )
        entry["pixels"] = rel


def build_gallery(
    dataset_dir: str | os.PathLike[str], *, title: str | None = None, pixel_scripts: bool = True
) -> Path:
    """Write the gallery (see the module docstring) into *dataset_dir*; return ``index.html``.

    *pixel_scripts* also writes ``gallery-pixels/<id>.js`` (about 1.35 × the size of the
    previews), so the pixel readout works from ``file://`` in Chromium too; without them it needs
    the folder served (``python -m http.server``) or a browser that lets such a page read its files.
    """
    root = Path(dataset_dir)
    index = gallery_index(root)
    if title:
        index["title"] = title
    if pixel_scripts:
        _write_pixel_scripts(root, index)
    contact_sheet(root)
    index["contact_sheets"] = {"all": "contact_sheet.png", **_condition_sheets(root, index)}
    data = json.dumps(plain_data(index), ensure_ascii=False, separators=(",", ":"), allow_nan=False)
    write_text_file(root / "gallery.json", data + "\n")
    write_text_file(root / "gallery-index.js", f"window.{INDEX_VARIABLE} = {data};\n")
    for name in _STATIC:
        write_text_file(root / name, read_template(name))
    page = string.Template(read_template("gallery.html")).substitute(
        title=_escape(index["title"]), n_samples=len(index["samples"])
    )
    path = root / "index.html"
    write_text_file(path, page)
    return path


def _escape(text: str) -> str:
    return html.escape(text)
