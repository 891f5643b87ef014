"""Benchmark of a relightable sample's bytes on disk (issue 45): the compact transport against
the per-batch layout written before it, in one run.

One two-light room of the default set (``room-living``, view 0, ``two-colour-a``) at the
``default`` preset (256², 2 batches), stored with ``--store-transport`` and its spectral
layers (what issue 45 measured at 235 MB for a five-light generated room). Reported:

* the bytes of every file of the sample folder, and of the sample;
* the transport in the layout before issue 45 (every batch in full, float32, uncompressed),
  written by this module from the same in-memory transport, against the compact file (the
  batches' float32 mean, float16 deviations, ZIP): bytes, and the seconds to read each back
  (:func:`~spectrinsic.gt_export.sample.transport_exr.read_transport`, the decoding a
  ``RandomRelight`` pays per sample), median of :data:`REPEATS`;
* exactness on the compact form: the relit images and raw channels composed from the
  transport read back against those composed from the in-memory transport (largest difference
  relative to each array's largest magnitude; goal ≤ 1e-5), and the noise estimate's (goal
  ≤ 1e-3, its float16 deviations);
* the same bytes scaled to 10,000 samples;
* the layers (issue 45, :mod:`~spectrinsic.gt_export.sample.layer_storage`): every layer's bytes
  alone (ZIP) in full and as stored (its coverage for a per-material table, nothing for one
  rebuilt from the others), every EXR file in full (the layout before it, written by this
  module from the layers the loader rebuilds) against as written, the seconds to read every
  layer back (rebuilt ones included) against reading the full files, ``check`` on the compact
  form; for this sample and for the same render written as a default sample (no transport,
  no spectral layers), whose issue-45 goal is 12 MB;
* the cube the sample defines from its stored transport
  (:mod:`~spectrinsic.gt_export.sample.transport_cube`, rebuilt by the loader) against the
  renderer's own (the batches' mean of each batch's sum): float32 rounding.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from ..gt_export import check_sample, export_sample, load_sample
from ..gt_export.formats.exr import read_exr, write_exr
from ..gt_export.layers import LayerSettings
from ..gt_export.relight import relit_scene
from ..gt_export.sample.layer_storage import read_layers
from ..gt_export.sample.meta import read_meta
from ..gt_export.sample.transport_exr import (
    COVERAGE_LAYER,
    TRANSPORT_NAME,
    read_transport,
    transport_layer,
)
from ..pipeline.presets import get_preset
from ..render.algebra.batch_means import relative_standard_error
from ..render.algebra.light_transport import LightTransport, relit_result
from ..render.result import PARTS
from ..render.transport_render import render_transport_batches
from ..scenes.library import build
from ..spectra import get_sensors

SCENE, VIEW, CONDITION = "room-living", 0, "two-colour-a"
NEW_LIGHTS = {0: "cie:LED-RGB1", 1: "planck:3000K"}
SEED = 3
REPEATS = 3
EXACT_GOAL = 1e-5
NOISE_GOAL = 1e-3
#: Issue 45's target for a relightable 256² default sample with spectral layers.
TARGET_SAMPLE_BYTES = 50e6
#: Issue 45's target for a default sample without transport (and without spectral layers).
TARGET_PLAIN_BYTES = 12e6


def _per_batch_file(path: Path, transport: LightTransport, coverage: np.ndarray) -> int:
    """Write *transport* in the layout before issue 45 (every batch of every part, float32,
    uncompressed) to *path*; its bytes."""
    layers: dict[str, np.ndarray] = {COVERAGE_LAYER: coverage}
    names = {COVERAGE_LAYER: tuple(f"m{m}" for m in range(coverage.shape[-1]))}
    held = {"transport": transport.batches} | {
        p: transport.parts[p] for p in PARTS if transport.parts.get(p)
    }
    for part, batches in held.items():
        for b, batch in enumerate(batches):
            for mode in transport.modes:
                for j in range(transport.n_lights):
                    layers[transport_layer(j, b, mode, part)] = batch[mode][j]
                    names[transport_layer(j, b, mode, part)] = get_sensors(
                        transport.sensors[mode]
                    ).channels
    write_exr(path, layers, channel_names=names, compression="none")
    return path.stat().st_size


def _median_seconds(fn: Any, *args: Any) -> float:
    runs = []
    for _ in range(REPEATS):
        start = time.perf_counter()
        fn(*args)
        runs.append(time.perf_counter() - start)
    return float(np.median(runs))


def _relative(a: np.ndarray, b: np.ndarray) -> float:
    scale = float(np.abs(b).max())
    return float(np.abs(np.asarray(a, np.float64) - b).max()) / scale if scale > 0 else 0.0


def _exactness(read: LightTransport, memory: LightTransport, scene: Any) -> dict[str, Any]:
    """Relit images, raw channels and noise estimate: from the file against from memory."""
    new_scene = relit_scene(scene, NEW_LIGHTS)
    a, b = relit_result(read, new_scene), relit_result(memory, new_scene)
    layers = {f"images/{m}": _relative(a.images[m], b.images[m]) for m in a.images}
    layers |= {f"raw/{m}": _relative(a.raw[m], b.raw[m]) for m in a.raw}
    mode = next(iter(a.raw))
    valid = np.ones(a.raw[mode].shape[:2], bool)
    noise = _relative(
        relative_standard_error([r[mode] for r in a.batch_raw], valid),
        relative_standard_error([r[mode] for r in b.batch_raw], valid),
    )
    worst = max(layers.values())
    return {
        "worst_relative": worst,
        "goal": EXACT_GOAL,
        "met": worst <= EXACT_GOAL,
        "noise_estimate_relative": noise,
        "noise_goal": NOISE_GOAL,
        "noise_met": noise <= NOISE_GOAL,
        "arrays": layers,
    }


def _files(sample: Path) -> dict[str, int]:
    """Bytes of every file of a sample folder, previews included (by relative path)."""
    return {
        p.relative_to(sample).as_posix(): p.stat().st_size
        for p in sorted(sample.rglob("*"))
        if p.is_file()
    }


def _layer_storage(sample: Path, work: Path) -> dict[str, Any]:
    """Bytes per layer and per EXR file of *sample* in full against as written, the seconds to
    read every layer back, and ``check`` on it (module notes)."""
    meta = read_meta(sample)
    records = meta.layers
    forms = (meta.raw.get("storage") or {}).get("layers", {})
    values = read_layers(meta.raw, records, list(records), lambda f: sample / f)
    one = work / "one.exr"

    half = set((meta.raw.get("storage") or {}).get("half") or ())

    def alone(name: str, array: np.ndarray, channels: Any, *, as_half: bool = False) -> int:
        data = array.astype(np.float16) if as_half else array
        write_exr(one, {name: data}, channel_names={name: channels}, half=[name] if as_half else [])
        return one.stat().st_size

    layers: dict[str, Any] = {}
    groups: dict[str, dict[str, Any]] = {}
    for key, rec in records.items():
        full = alone(rec.exr_layer, values[key], rec.channels)
        stored = 0 if key in forms else full
        if key in half:  # its float32 values read back from float16: "full" is a lower bound
            stored = alone(rec.exr_layer, values[key], rec.channels, as_half=True)
        if forms.get(key) == "coverage_table":
            coverage = read_exr(sample / rec.file, layers=[COVERAGE_LAYER])[COVERAGE_LAYER]
            stored = alone(COVERAGE_LAYER, coverage, [f"m{m}" for m in range(coverage.shape[-1])])
        form = forms.get(key, "float16" if key in half else "full")
        layers[key] = {"full": full, "stored": stored, "form": form}
        groups.setdefault(rec.file, {})[rec.exr_layer] = (values[key], rec.channels)
    full_dir = work / "full"
    full_dir.mkdir()
    for file, members in groups.items():
        write_exr(
            full_dir / file,
            {k: v for k, (v, _) in members.items()},
            channel_names={k: c for k, (_, c) in members.items()},
        )
    files = {
        f: {"full": (full_dir / f).stat().st_size, "stored": (sample / f).stat().st_size}
        for f in groups
    }
    read_full = _median_seconds(lambda: [read_exr(full_dir / f) for f in groups])
    read_stored = _median_seconds(
        lambda: read_layers(meta.raw, records, list(records), lambda f: sample / f)
    )
    return {
        "layers": layers,
        "exr_files": files,
        "exr_bytes": {k: sum(v[k] for v in files.values()) for k in ("full", "stored")},
        "read_all_layers_seconds": {"full": read_full, "stored": read_stored},
        "read_slowdown_stored_over_full": read_stored / read_full,
        "check_problems": check_sample(sample),
    }


def _plain_sample(root: Path, scene: Any, result: Any, cfg: Any) -> dict[str, Any]:
    """The same render written as a default sample (no transport, no spectral layers)."""
    sample = export_sample(
        root,
        scene,
        result,
        LayerSettings(cameras=cfg.resolved_cameras(), denoise=cfg.denoise),
        sample_id="storage__v0__plain",
        config=cfg.to_dict(),
        seed=SEED,
    )
    files = _files(sample)
    work = root / "plain_work"
    work.mkdir()
    layer_storage = _layer_storage(sample, work)
    top = sum(v for k, v in files.items() if "/" not in k)
    saved = layer_storage["exr_bytes"]["full"] - layer_storage["exr_bytes"]["stored"]
    return {
        "file_bytes": files,
        "sample_bytes": {"full_layers": top + saved, "compact": top},
        "previews_bytes": sum(v for k, v in files.items() if "/" in k),
        "target_bytes": TARGET_PLAIN_BYTES,
        "target_met": top <= TARGET_PLAIN_BYTES,
        "per_10000_samples_gb": {
            "full_layers": (top + saved) * 1e4 / 1e9,
            "compact": top * 1e4 / 1e9,
        },
        "layer_storage": layer_storage,
    }


def run(out_dir: Path) -> dict[str, Any]:
    cfg = get_preset("default")
    scene = build(SCENE, view=VIEW, condition=CONDITION, seed=0, width=cfg.width, height=cfg.height)
    transport, result = render_transport_batches(scene, cfg.render, seed=SEED)
    with tempfile.TemporaryDirectory(dir=out_dir) as tmp:
        root = Path(tmp)
        sample = export_sample(
            root,
            scene,
            result,
            LayerSettings(
                cameras=cfg.resolved_cameras(), denoise=cfg.denoise, spectral_layers=True
            ),
            sample_id="storage__v0__x",
            config=cfg.to_dict(),
            seed=SEED,
            transport=transport,
        )
        files = {p.name: p.stat().st_size for p in sorted(sample.iterdir()) if p.is_file()}
        record = read_meta(sample).raw["transport"]
        read, coverage = read_transport(sample, record)
        old_dir = root / "per_batch"
        old_dir.mkdir()
        old_bytes = _per_batch_file(old_dir / TRANSPORT_NAME, transport, coverage)
        old_record = {k: v for k, v in record.items() if k not in ("layout", "deviation_exponents")}
        read_old_s = _median_seconds(read_transport, old_dir, old_record)
        read_new_s = _median_seconds(read_transport, sample, record)
        exactness = _exactness(read, transport, scene)
        cube = load_sample(sample, layers=["image_bands_raw"])["image_bands_raw"]
        cube_gap = _relative(cube, np.asarray(result.raw["bands31"], np.float64))
        (root / "work").mkdir()
        layer_storage = _layer_storage(sample, root / "work")
        previews = sum(v for k, v in _files(sample).items() if "/" in k)
        plain = _plain_sample(root, scene, result, cfg)
    return {
        "scene": f"{SCENE}__v{VIEW}__{CONDITION}",
        "size": [scene.camera.width, scene.camera.height],
        "lights": len(scene.lights),
        "batches": len(transport.batches),
        "modes": list(transport.modes),
        "parts": record["parts"],
        "file_bytes": files,
        "previews_bytes": previews,
        **_sizes(files, old_bytes, layer_storage),
        "read_transport_seconds": {"per_batch_layout": read_old_s, "compact": read_new_s},
        "read_slowdown_new_over_old": read_new_s / read_old_s,
        "read_slowdown_goal": 1.5,
        "exactness_compact_vs_memory": exactness,
        "cube_from_transport_vs_render_relative": cube_gap,
        "layer_storage": layer_storage,
        "default_sample_without_transport": plain,
    }


def _sizes(files: dict[str, int], old_transport: int, layers: dict[str, Any]) -> dict[str, Any]:
    """The sample's bytes (its files, previews aside) in three layouts: before issue 45 (the
    per-batch transport, every layer in full), with the compact transport alone (every layer
    in full), and as written (compact transport, layers as stored)."""
    transport, now = files[TRANSPORT_NAME], sum(files.values())
    full_layers = now + layers["exr_bytes"]["full"] - layers["exr_bytes"]["stored"]
    sizes = {
        "before_issue_45": full_layers - transport + old_transport,
        "compact_transport_full_layers": full_layers,
        "compact": now,
    }
    return {
        "transport_bytes": {"per_batch_layout": old_transport, "compact": transport},
        "transport_ratio_old_to_new": old_transport / transport,
        "sample_bytes": sizes,
        "sample_ratio_before_to_now": sizes["before_issue_45"] / now,
        "sample_ratio_full_layers_to_now": full_layers / now,
        "sample_target_bytes": TARGET_SAMPLE_BYTES,
        "sample_target_met": now <= TARGET_SAMPLE_BYTES,
        "per_10000_samples_gb": {k: v * 1e4 / 1e9 for k, v in sizes.items()},
    }
