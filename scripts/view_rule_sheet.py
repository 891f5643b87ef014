"""Contact sheet of N generated views as a preview build draws them (docs/figures/view-rule-50.png).

The rooms of ``dataset --generator rooms --count N --seed 11 --preset preview --resolution
64x64`` are generated as the pipeline does (the view rule with its probe render,
:mod:`spectrinsic.render.probe`), then each view is rendered at 64 x 64 (CIE XYZ through the
spectral pass, 16 spp; exposed so its 99th-percentile luminance is white, sRGB-encoded) and
tiled with :func:`spectrinsic.gt_export.dataset.contact_sheet.tile_sheet`. The probes' verdicts
go to ``OUT.json``. Run: ``python scripts/view_rule_sheet.py [N] [OUT] [SEED] [DATASET
OPTIONS...]`` (about 6 s a view on one core). The tiles are not the dataset's denoised previews
(a 64² preview sample takes 4-5 s of Mitsuba alone): the framing and the light are the same,
the noise is not.
"""

from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

import colour
import numpy as np
from PIL import Image

from spectrinsic.cli import build_parser
from spectrinsic.cli.dataset import config_from_args
from spectrinsic.data_dir import resolve_data_dir
from spectrinsic.gt_export.dataset.contact_sheet import tile_sheet
from spectrinsic.pipeline.sample_plan import plan_samples
from spectrinsic.render.probe import probe_luminance
from spectrinsic.render.settings import PassRequest
from spectrinsic.render.spectral import render_spectral
from spectrinsic.scenes.generators.view_rule import judge_frame, judge_view
from spectrinsic.spectra import get_sensors


def _tile(xyz: np.ndarray) -> Image.Image:
    """sRGB tile of an XYZ image exposed so its 99th-percentile luminance is 1."""
    y99 = max(float(np.percentile(xyz[..., 1], 99)), 1e-12)
    rgb = colour.XYZ_to_sRGB(np.clip(xyz / y99, 0, None))
    return Image.fromarray((np.clip(rgb, 0, 1) * 255 + 0.5).astype(np.uint8))


#: The set's options after ``--count N --seed S``: the CLI's own defaults (gloss, textures).
_PREVIEW_64 = ("--preset", "preview", "--resolution", "64x64")


def main(
    n: int = 50, out: str = "docs/figures/view-rule-50.png", seed: int = 11, *extra: str
) -> None:
    found = resolve_data_dir()  # $SPECTRINSIC_DATA, as the CLI finds it
    data = None if found is None else str(found)
    args = [*f"dataset --generator rooms --count {n} --seed {seed}".split(), *_PREVIEW_64, *extra]
    config = config_from_args(build_parser().parse_args([*args, "--out", "unused"]))
    stats: dict[str, dict[str, object]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        tiles = []
        for task in plan_samples(Path(tmp) / "plan", config, data_dir=data):
            probes: list[float] = []

            def probe(scene, probes=probes):  # the pipeline's probe, its verdicts recorded
                y = probe_luminance(scene, data_dir=data)
                probes.append(round(judge_frame(y).median_share, 4))
                return y

            scene = task.source.build(data, probe=probe)
            xyz = render_spectral(scene, get_sensors("cie1931"), PassRequest(16, 0), data_dir=data)
            path = Path(tmp) / f"{task.sample_id}.png"
            _tile(xyz.image).save(path)
            tiles.append((task.sample_id, path))
            j = judge_view(scene.meshes, scene.lights, scene.camera)
            stats[task.sample_id] = {
                "probes": probes,
                "view_rule": scene.metadata["view_rule"],
                "meshes": len(scene.meshes),
                "object_ids": len({m.object_id for m in scene.meshes}),
                "max_mesh_share": round(j.max_mesh_share, 3),
                "max_object_share": round(j.max_object_share, 3),
            }
            print(task.sample_id, stats[task.sample_id], flush=True)
        tile_sheet(tiles, out)
    with Image.open(out) as sheet:  # 256 colours keep the docs' figure under 300 kB
        small = sheet.convert("RGB").quantize(
            256, Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE
        )
    small.save(out, optimize=True)
    Path(out).with_suffix(".json").write_text(json.dumps(stats, indent=1) + "\n")


if __name__ == "__main__":
    main(*(int(a) if i in (0, 2) else a for i, a in enumerate(sys.argv[1:])))  # type: ignore[arg-type]
