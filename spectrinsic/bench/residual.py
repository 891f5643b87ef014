"""Benchmark of the residual share: how much of the image the intrinsic product leaves out.

Generated rooms (the ``rooms`` generator, matte) rendered with the 31-band cube: per room the
RGB layers' residual share ``Σ|residual| / Σ|image|`` over the mask in the default working
space (ACEScg, shading negatives kept) and in linear sRGB (shading clipped at 0, the layers of
before), the per-band layers' (``--spectral-layers``), and the share of lit pixels whose
shading leaves each space's gamut (clipped in sRGB); per light family (the room's most
saturated light) and over all rooms, median and p95, and the ratios default / sRGB. Goals
(issue 30): per band ≤ 0.5 % median and ≤ 2 % p95 under every family; the default at most
half sRGB's residual share (median and p95) with ≤ 1 % of pixels clipped;
``scripts/colour_space_study.py`` compares working spaces on 200 rooms
(docs/spectral-layers.md). Also the cost of ``spectral.exr`` per sample.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path
from typing import Any

from ..gt_export import export_sample
from ..gt_export.layers import LayerSettings, compute_ground_truth
from ..gt_export.layers.spectral_intrinsics import light_family, residual_summary
from ..render import RenderSettings, render_scene
from ..scenes.generators import generate
from ..scenes.generators.base import GeneratorOptions
from ..spectra.working_space import DEFAULT_WORKING_SPACE, working_space

ROOMS = 12
SIZE = 48
SPP = 16
SEED = 30


def _meta_of(scene: Any, gt: Any) -> dict[str, Any]:
    return {
        "lights": [{"spectrum": li.spectrum} for li in scene.lights],
        "residual_share": gt.residual_share,
        "shading_clipping": gt.clipping,
        "working_space": gt.working_space.record(),  # clipped_pixels or out_of_gamut_share
    }


def _export_cost(scene: Any, result: Any) -> dict[str, float]:
    """Seconds and bytes of one sample folder without and with the band layers."""
    out: dict[str, float] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for spectral in (False, True):
            start = time.perf_counter()
            folder = export_sample(
                tmp,
                scene,
                result,
                LayerSettings(cameras=(), spectral_layers=spectral),
                sample_id=f"s{int(spectral)}",
                config={"bench": "residual"},
                seed=SEED,
            )
            key = "with_bands" if spectral else "without_bands"
            out[f"export_seconds_{key}"] = time.perf_counter() - start
            out[f"folder_bytes_{key}"] = float(
                sum(f.stat().st_size for f in folder.rglob("*") if f.is_file())
            )
    return out


def run(out_dir: Path) -> dict[str, Any]:
    options = GeneratorOptions(width=SIZE, height=SIZE)
    settings = RenderSettings(spp=SPP, max_depth=5, modes=("rgb3", "bands31"), per_light=True)
    metas, srgb_metas, families, cost = [], [], [], {}
    for index in range(ROOMS):
        scene = generate("rooms", root_seed=SEED, index=index, view=0, options=options)
        result = render_scene(scene, settings, seed=SEED + index)
        gt = compute_ground_truth(scene, result, LayerSettings(spectral_layers=True))
        metas.append(_meta_of(scene, gt))
        srgb = compute_ground_truth(
            scene, result, LayerSettings(working_space=working_space("srgb"))
        )
        srgb_metas.append(_meta_of(scene, srgb))
        families.append(light_family(li.spectrum for li in scene.lights))
        if index == 0:
            cost = _export_cost(scene, result)
    summary = residual_summary(metas)
    overall = summary["all"]
    srgb = residual_summary(srgb_metas)["all"]
    return {
        "rooms": ROOMS,
        "size": f"{SIZE}x{SIZE}",
        "spp": SPP,
        "families": families,
        "by_family": summary,
        "working_space": DEFAULT_WORKING_SPACE,
        "rgb_residual_share": overall["rgb"],
        "band_residual_share": overall["spectral"],
        "shading_out_of_gamut_pixels": overall.get("out_of_gamut_share", {}),
        "srgb_residual_share": srgb["rgb"],
        "srgb_shading_clipped_pixels": srgb.get("clipped_pixels", {}),
        "default_over_srgb": {
            k: overall["rgb"][k] / max(srgb["rgb"][k], 1e-12) for k in ("median", "p95")
        },
        "band_over_rgb_median": overall["spectral"]["median"]
        / max(overall["rgb"]["median"], 1e-12),
        "spectral_exr_cost": cost,
        "goal": {
            "band_median": 0.005,
            "band_p95": 0.02,
            "default_over_srgb": 0.5,
            "default_out_of_gamut_share": 0.01,
        },
    }
