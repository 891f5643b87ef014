"""Which working colour space makes the RGB intrinsic identity hold best (issue 30).

Usage: python -P scripts/colour_space_study.py OUT.json [--rooms N] [--size S] [--spp P]
       [--seed K] [--gloss F] [--library]

Renders N generated rooms (``rooms`` generator, matte unless ``--gloss``) as 31-band cubes,
computes their spectral layers (:mod:`spectrinsic.gt_export.layers.spectral_intrinsics`, raw,
not denoised) and, from those alone, the RGB layers in each candidate space S (a 3x3 matrix M
from CIE XYZ; X the cube's raw -> XYZ matrix, D_k the D65 band values, Y_D their luminance):

    image_S       = M X cube
    reflectance_S = M X (ρ_k D_k) / Y_D              (under D65, as the reflectance layer today)
    shading_S     = M X W / white_S,  white_S = M X D / Y_D   (clipped at 0, or not)
    residual_S    = image_S − reflectance_S ∘ shading_S

So a grey surface, or any surface under D65 without interreflection, has no residual in any
space. Per sample: the residual share Σ|residual| / Σ|image| over the mask and the share of lit
pixels with a negative shading channel. Spaces: linear sRGB (today's layers), linear Rec.2020,
ACEScg (colour-science matrices, D65 white normalised per channel as above), a spectrally
sharpened basis (Finlayson, Drew & Funt 1994) fitted here to the Munsell chips under a pool of
lights drawn from the generators' pools with a seed apart from the rooms', and the per-band
layers themselves (the bound). Writes OUT.json (per sample rows and the summary) and prints
the summary as a markdown table per light family.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import colour
import numpy as np
from scipy.optimize import minimize

from spectrinsic.gt_export.layers import LayerSettings, compute_ground_truth
from spectrinsic.gt_export.layers.spectral_intrinsics import (
    LIGHT_FAMILIES,
    bands_to_rgb,
    light_family,
)
from spectrinsic.render import RenderSettings, render_scene
from spectrinsic.scenes.generators import generate
from spectrinsic.scenes.generators.base import GeneratorOptions
from spectrinsic.scenes.generators.gloss import GlossDistribution
from spectrinsic.scenes.generators.lights import draw_illuminant
from spectrinsic.spectra import COLORIMETRIC_WAVELENGTHS as WL
from spectrinsic.spectra import (
    family_values,
    get_sensors,
    get_spectrum,
    responses,
)
from spectrinsic.spectra.colourspace import srgb_matrices

#: Lights of the sharpening fit: this many white and as many saturated draws.
FIT_LIGHTS = 40
FIT_SEED = 20260430


def _fit_data() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Munsell XYZ under D65 ``(N, 3)``, D65 ``(3,)``, under each fit light ``(L, N, 3)`` and
    each light's white ``(L, 3)``, every light at unit luminance."""
    rho = family_values("munsell", WL)
    cmf = get_sensors("cie1931").on(WL)
    rng = np.random.default_rng(FIT_SEED)
    names = [draw_illuminant(rng, saturated=i % 2 == 1) for i in range(2 * FIT_LIGHTS)]

    def under(spd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        white = responses(spd, cmf, WL)
        return responses(rho * spd, cmf, WL) / white[1], white / white[1]

    pc, wc = under(get_spectrum("cie:D65").on(WL))
    pairs = [under(get_spectrum(n).on(WL)) for n in names]
    return pc, wc, np.stack([p for p, _ in pairs]), np.stack([w for _, w in pairs])


def _fdf_basis(pc: np.ndarray, pe: np.ndarray) -> np.ndarray:
    """Data-based sharpening (Finlayson, Drew & Funt 1994): the eigenvectors of the mean
    least-squares map ``p_c -> p_e`` over the lights, as rows of an XYZ -> RGB matrix."""
    maps = [np.linalg.lstsq(pc, p, rcond=None)[0].T for p in pe]
    values, vectors = np.linalg.eig(np.mean(maps, axis=0))
    t = np.real(np.linalg.inv(vectors))[np.argsort(-np.real(values))]
    return t / np.linalg.norm(t, axis=1, keepdims=True)


def fit_sharpened() -> np.ndarray:
    """``(3, 3)`` XYZ -> sharpened RGB: :func:`_fdf_basis`, refined to minimise the diagonal
    model's relative error ``‖T p_e − (T p_c / T w_c) ∘ T w_e‖² / ‖T p_e‖²`` over chips and
    lights (rows unit norm; a penalty keeps the rows apart, |det| ≥ 0.2)."""
    pc, wc, pe, we = _fit_data()
    pc, pe = pc[::3], pe[:, ::3]

    def loss(flat: np.ndarray, penalty: bool = True) -> float:
        t = flat.reshape(3, 3)
        t = t / np.linalg.norm(t, axis=1, keepdims=True)
        a = (pc @ t.T) / (t @ wc)
        pred = a[None] * (we @ t.T)[:, None, :]
        b = pe @ t.T
        value = float(((b - pred) ** 2).sum() / (b**2).sum())
        return value + (100 * max(0.0, 0.2 - abs(np.linalg.det(t))) ** 2 if penalty else 0)

    srgb, fdf = srgb_matrices()[0], _fdf_basis(pc, pe)
    best = minimize(loss, fdf.ravel(), method="Nelder-Mead", options={"maxiter": 1500})
    t = best.x.reshape(3, 3)
    t = t / np.linalg.norm(t, axis=1, keepdims=True)
    print(
        f"diagonal-model error: sRGB {loss(srgb.ravel(), False):.4g}, FDF "
        f"{loss(fdf.ravel(), False):.4g}, refined {loss(t.ravel(), False):.4g} "
        f"(|det| {abs(np.linalg.det(t)):.3f})",
        flush=True,
    )
    return t


def spaces(sharpened: np.ndarray) -> dict[str, np.ndarray]:
    """XYZ -> RGB matrices of the candidate spaces."""
    return {
        "srgb": srgb_matrices()[0],
        "rec2020": colour.RGB_COLOURSPACES["ITU-R BT.2020"].matrix_XYZ_to_RGB,
        "acescg": colour.RGB_COLOURSPACES["ACEScg"].matrix_XYZ_to_RGB,
        "sharpened": sharpened,
    }


def _share(image: np.ndarray, residual: np.ndarray, mask: np.ndarray) -> float:
    den = float(np.abs(image[mask]).sum())
    return float(np.abs(residual[mask]).sum()) / den if den > 0 else 0.0


def space_figures(gt: object, to_xyz: np.ndarray, m: np.ndarray) -> dict[str, float]:
    """Residual share (clipped and unclipped shading) and clipped-pixel share in one space,
    from the band layers (:func:`~spectrinsic.gt_export.layers.spectral_intrinsics.bands_to_rgb`)."""
    layers = {k: v.data for k, v in gt.layers.items()}  # type: ignore[attr-defined]
    rgb = bands_to_rgb(layers, to_xyz, m)
    mask = layers["mask"] > 0
    image, shading = rgb["image"], rgb["shading"]
    clipped = rgb["residual"] + rgb["reflectance"] * (shading - np.clip(shading, 0, None))
    lit = mask & (np.abs(layers["shading_bands"]).sum(-1) > 0)
    return {
        "share_unclipped": _share(image, rgb["residual"], mask),
        "share_clipped": _share(image, clipped, mask),
        "clipped_pixels": float((shading[lit] < 0).any(-1).mean()) if lit.any() else 0.0,
    }


def _scenes(args: argparse.Namespace) -> list[object]:
    """The benchmark's scenes: the library's default samples, or N generated rooms."""
    if args.library:
        from spectrinsic.scenes import library  # noqa: PLC0415

        return [
            library.build(
                s.scene,
                view=s.view,
                condition=s.condition,
                seed=args.seed,
                width=args.size,
                height=args.size,
            )
            for s in library.default_samples()
        ]
    options = GeneratorOptions(
        width=args.size,
        height=args.size,
        gloss=GlossDistribution(glossy_fraction=args.gloss) if args.gloss else GlossDistribution(),
    )
    return [
        generate("rooms", root_seed=args.seed, index=i, view=0, options=options)
        for i in range(args.rooms)
    ]


def room_rows(args: argparse.Namespace, matrices: dict[str, np.ndarray]) -> list[dict]:
    settings = RenderSettings(
        spp=args.spp, max_depth=args.depth, modes=("rgb3", "bands31"), per_light=True
    )
    scenes = _scenes(args)
    rows = []
    for index, scene in enumerate(scenes):
        t0 = time.perf_counter()
        result = render_scene(scene, settings, seed=args.seed + index)
        gt = compute_ground_truth(scene, result, LayerSettings(spectral_layers=True))
        to_xyz = np.asarray(result.meta["to_xyz"]["bands31"], np.float64)
        row = {
            "scene": scene.name,
            "lights": [li.spectrum for li in scene.lights],
            "family": light_family(li.spectrum for li in scene.lights),
            "glossy": any(m.kind != "diffuse" for m in scene.materials),
            "layers_rgb_share": gt.residual_share["image"],
            "layers_clipped_pixels": gt.clipping.get("pixels", 0.0),
            "bands31_share": gt.residual_share["image_bands"],
            "spaces": {k: space_figures(gt, to_xyz, m) for k, m in matrices.items()},
        }
        rows.append(row)
        print(
            f"{index + 1}/{len(scenes)} {scene.name} {row['family']}: sRGB "
            f"{100 * row['spaces']['srgb']['share_clipped']:.2f} %, bands "
            f"{100 * row['bands31_share']:.4f} % ({time.perf_counter() - t0:.1f} s)",
            flush=True,
        )
    return rows


def _stats(values: list[float]) -> dict[str, float]:
    v = np.asarray(values, float)
    return {"median": float(np.median(v)), "p95": float(np.percentile(v, 95))}


def summary(rows: list[dict]) -> dict[str, dict]:
    """Per family and ``all``: median / p95 of every space's figures over the samples."""
    out: dict[str, dict] = {}
    for family in [*LIGHT_FAMILIES, "all"]:
        chosen = [r for r in rows if family in (r["family"], "all")]
        if not chosen:
            continue
        entry: dict[str, dict] = {"samples": {"n": len(chosen)}}
        for space in chosen[0]["spaces"]:
            for key in ("share_clipped", "share_unclipped", "clipped_pixels"):
                entry[f"{space}:{key}"] = _stats([r["spaces"][space][key] for r in chosen])
        entry["bands31:share"] = _stats([r["bands31_share"] for r in chosen])
        out[family] = entry
    return out


def markdown(table: dict[str, dict]) -> str:
    """Residual share median / p95 (%) per space and family; clipped pixels (%) in brackets."""
    cols = [
        ("sRGB clipped (today)", "srgb:share_clipped", "srgb:clipped_pixels"),
        ("sRGB unclipped", "srgb:share_unclipped", None),
        ("Rec.2020 clipped", "rec2020:share_clipped", "rec2020:clipped_pixels"),
        ("Rec.2020 unclipped", "rec2020:share_unclipped", None),
        ("ACEScg clipped", "acescg:share_clipped", "acescg:clipped_pixels"),
        ("ACEScg unclipped", "acescg:share_unclipped", None),
        ("sharpened clipped", "sharpened:share_clipped", "sharpened:clipped_pixels"),
        ("sharpened unclipped", "sharpened:share_unclipped", None),
        ("31 bands (bound)", "bands31:share", None),
    ]
    lines = [
        "| light family | n | " + " | ".join(c[0] for c in cols) + " |",
        "|---|---|" + "---|" * len(cols),
    ]
    for family, entry in table.items():
        cells = []
        for _, key, clip in cols:
            s = entry[key]
            cell = f"{100 * s['median']:.2f} / {100 * s['p95']:.2f}"
            if clip:
                cell += f" [{100 * entry[clip]['median']:.0f} / {100 * entry[clip]['p95']:.0f}]"
            cells.append(cell)
        lines.append(f"| {family} | {entry['samples']['n']} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out", type=Path)
    p.add_argument("--rooms", type=int, default=200)
    p.add_argument("--size", type=int, default=32)
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--depth", type=int, default=5)
    p.add_argument("--seed", type=int, default=30)
    p.add_argument("--gloss", type=float, default=0.0, help="fraction of glossy materials")
    p.add_argument("--library", action="store_true", help="the library's 68 samples instead")
    args = p.parse_args(argv)
    sharpened = fit_sharpened()
    rows = room_rows(args, spaces(sharpened))
    table = summary(rows)
    record = {
        "settings": vars(args) | {"out": str(args.out)},
        "sharpened_xyz_to_rgb": sharpened.tolist(),
        "summary": table,
        "rows": rows,
    }
    args.out.write_text(json.dumps(record, indent=1, sort_keys=True) + "\n", encoding="utf-8")
    print(markdown(table))
    return 0


if __name__ == "__main__":
    sys.exit(main())
