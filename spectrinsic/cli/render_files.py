"""The files of ``spectrinsic render``: every mode's raw passes as EXR with named channels,
an sRGB PNG preview beside each, the AOVs, and ``meta.json``."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from ..file_writes import write_text_file
from ..gt_export.formats.exr import write_exr
from ..gt_export.formats.png import encode_srgb8, exposure, write_png
from ..render import RenderResult
from ..scenes.model import Scene, scene_to_dict
from ..spectra import get_sensors
from ..spectra.colorimetry import xyz_to_linear_srgb

__all__ = ["write_render"]


def write_render(
    out: Path, scene: Scene, result: RenderResult, *, data_dir: str | None = None
) -> dict[str, Path]:
    """Write a :class:`~spectrinsic.render.RenderResult` as EXR files, an sRGB PNG beside each
    mode's EXR (``<mode>.png``: its XYZ as linear sRGB, times :func:`~spectrinsic.gt_export.formats.png.
    exposure`, sRGB-encoded to 8 bits; the scale in ``meta.json["previews"]``) and
    ``meta.json`` into *out*."""
    out.mkdir(parents=True, exist_ok=True)
    paths: dict[str, Path] = {}
    previews: dict[str, dict[str, Any]] = {}
    for mode, raw in result.raw.items():
        labels = get_sensors(result.meta["sensors"][mode], data_dir=data_dir).channels
        layers = {"raw": raw, "xyz": result.images[mode]}
        names: dict[str, tuple[str, ...]] = {"raw": tuple(labels), "xyz": ("X", "Y", "Z")}
        if mode in result.direct:
            layers["direct"], names["direct"] = result.direct[mode], ("X", "Y", "Z")
        for i, light in enumerate(result.per_light):
            layers[f"light{i}"], names[f"light{i}"] = light[mode], ("X", "Y", "Z")
        paths[mode] = write_exr(
            out / f"{mode}.exr",
            layers,
            channel_names=names,
            attributes={"spectrinsic.mode": mode, "spectrinsic.units": result.meta["units"]},
        )
        rgb = xyz_to_linear_srgb(result.images[mode])
        scale = exposure(rgb)  # the package's one exposure and sRGB encoding (gt_export.png)
        paths[f"{mode}_png"] = write_png(out / f"{mode}.png", encode_srgb8(rgb, scale))
        previews[mode] = {"file": f"{mode}.png", "exposure": scale}
    if result.aovs:
        a = result.aovs
        paths["aovs"] = write_exr(
            out / "aovs.exr",
            {
                "coverage": a["coverage"],
                "material_id": a["material_id"],
                "object_id": a["object_id"],
                "depth": a["depth"],
                "normals": a["normals"],
                "mask": a["mask"].astype("float32"),
            },
            channel_names={
                "coverage": tuple(f"m{i:02d}" for i in range(a["coverage"].shape[-1])),
                "material_id": ("id",),
                "object_id": ("id",),
                "depth": ("Z",),
                "normals": ("X", "Y", "Z"),
                "mask": ("A",),
            },
        )
    meta = {
        **result.meta,
        "scene": scene_to_dict(scene),
        "files": {k: v.name for k, v in paths.items()},
        "previews": {
            "encoding": "sRGB (IEC 61966-2-1), 8-bit, linear sRGB x exposure, clipped",
            **previews,
        },
    }
    meta["scene"]["meshes"] = [
        {"name": m.name, "object_id": m.object_id, "faces": len(m.faces)} for m in scene.meshes
    ]
    paths["meta"] = out / "meta.json"
    write_text_file(paths["meta"], json.dumps(meta, indent=2, default=str, allow_nan=False) + "\n")
    return paths
