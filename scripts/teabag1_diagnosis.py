"""Where names-and-shades loses on one MIT object: the figure and numbers of issue 48, round 6.

Usage: python -P scripts/teabag1_diagnosis.py MIT_DIR OUT.png [OBJECT] [--before] [--no-reads]
       [--variant=NAME]

One row per setting (the defaults; with ``--before``, the method before round 6,
``NamesAndShades(blurred_steps=False, fine_detail=False)``; with ``--no-reads``, the defaults
without sec. 3.4's reads across sharp steps, ``blurred_steps=False``, rounds 6 and 9), on the
object under a stress variant of :mod:`spectrinsic.decompose.evaluation.mit_variants`
(``--variant``, default ``original``): the photograph, the true reflectance and shading, the estimates, and two error
maps, ``log(R_est / R_true)`` per pixel (after one global scale, the median; red: too light,
blue: too dark) and the local shading error (each 20-pixel window's squared error after its
own least-squares scale, the MIT LMSE's term, spread over the window). Prints each row's MIT
LMSE per layer and, per region-size class, how far the region's reflectance is from the truth
(mean ``|log|`` of the region's best scale, pixel-weighted) and what the LMSE would be with
those scales corrected (an oracle: it says where the error sits, not a method).
OBJECT defaults to teabag1; only the development half may be given.
"""

from __future__ import annotations

import sys
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np

from spectrinsic.decompose.decomposition import finish
from spectrinsic.decompose.evaluation.mit import MitObject, load_mit_object, mit_measures
from spectrinsic.decompose.evaluation.mit_variants import VARIANTS, apply_variant
from spectrinsic.decompose.methods.baselines import ImageAsReflectance
from spectrinsic.decompose.methods.names_shades import NamesAndShades

#: Region sizes (pixels) of the error breakdown.
SIZE_CLASSES = ((1, 20), (20, 200), (200, 2000), (2000, 10**9))
WINDOW = 20


def _grey(a: np.ndarray) -> np.ndarray:
    return np.asarray(a, np.float64).mean(axis=2) if np.ndim(a) == 3 else np.asarray(a)


def _local_error(truth: np.ndarray, est: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """Per pixel, the mean over the 20-pixel windows (shift 10) holding it of the window's
    squared error after its own least-squares scale, over the window's true energy."""
    h, w = mask.shape
    acc, hits = np.zeros((h, w)), np.zeros((h, w))
    for y in range(0, h - WINDOW + 1, WINDOW // 2):
        for x in range(0, w - WINDOW + 1, WINDOW // 2):
            sl = (slice(y, y + WINDOW), slice(x, x + WINDOW))
            m = mask[sl]
            if not m.any():
                continue
            t, e = truth[sl][m], est[sl][m]
            den = float((e * e).sum())
            a = float((t * e).sum()) / den if den > 1e-5 else 0.0
            energy = float((t * t).sum())
            acc[sl] += ((t - a * e) ** 2).sum() / energy if energy > 0 else 0.0
            hits[sl] += 1
    return np.where(mask & (hits > 0), acc / np.maximum(hits, 1), np.nan)


def _breakdown(obj: MitObject, refl: np.ndarray, regions: np.ndarray) -> list[str]:
    """Per region-size class: pixels, mean |log scale error| and the LMSE with it corrected."""
    m = obj.mask
    truth, est = _grey(obj.reflectance), _grey(refl)
    n = int(regions.max()) + 1
    size = np.bincount(regions[m], minlength=n)
    log_err = np.log(np.maximum(truth, 1e-4)) - np.log(np.maximum(est, 1e-6))
    scale = np.bincount(regions[m], weights=log_err[m], minlength=n) / np.maximum(size, 1)
    scale -= scale[np.argmax(size[1:]) + 1]  # relative to the largest region
    lines = []
    for lo, hi in SIZE_CLASSES:
        chosen = (size >= lo) & (size < hi)
        chosen[0] = False
        pixels = int(size[chosen].sum())
        mean_err = float((np.abs(scale) * size)[chosen].sum() / max(pixels, 1))
        fixed = refl * np.exp(np.where(chosen, scale, 0.0))[regions][:, :, None]
        lmse = mit_measures(obj, finish(obj.image, fixed, m, {}))["lmse"]
        lines.append(
            f"  regions {lo}-{hi} px: {int(chosen.sum())} regions, {pixels} px, "
            f"mean |log scale error| {mean_err:.3f}, LMSE with them corrected {lmse:.4f}"
        )
    fixed = refl * np.exp(np.where(size > 0, scale, 0.0))[regions][:, :, None]
    lmse = mit_measures(obj, finish(obj.image, fixed, m, {}))["lmse"]
    lines.append(f"  every region's scale corrected: LMSE {lmse:.4f}")
    return lines


def main(folder: Path, out: Path, name: str, rows: tuple[str, ...], variant: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    obj = apply_variant(variant, load_mit_object(folder / f"{name}.npz"))
    m = obj.mask
    iar = mit_measures(obj, ImageAsReflectance()(obj.image, m))["lmse"]
    print(f"{name} ({variant}): image-as-reflectance LMSE {iar:.4f}")
    settings = {"defaults": NamesAndShades()}
    if "--no-reads" in rows:
        settings["no reads across steps"] = NamesAndShades(blurred_steps=False)
    if "--before" in rows:
        settings["before round 6"] = NamesAndShades(blurred_steps=False, fine_detail=False)
    ys, xs = np.nonzero(m)
    crop = (slice(ys.min(), ys.max() + 1), slice(xs.min(), xs.max() + 1))
    fig, axes = plt.subplots(len(settings), 7, figsize=(17, 2.9 * len(settings)), squeeze=False)
    exposure = float(np.percentile(obj.image[m], 99))
    for row, (label, method) in zip(axes, settings.items(), strict=True):
        stages = method.labelling(obj.image, m)
        result = method(obj.image, m)
        regions, _ = replace(method, collapse_guard=False)._regions(stages)
        v = mit_measures(obj, result)
        print(
            f"{label}: LMSE {v['lmse']:.4f} ({v['lmse'] / iar:.2f} x image-as-reflectance), "
            f"shading {v['lmse_shading']:.4f}, reflectance {v['lmse_reflectance']:.4f}, "
            f"{int(regions.max())} regions"
        )
        print("\n".join(_breakdown(obj, np.asarray(result.reflectance, np.float64), regions)))
        r_true, r_est = _grey(obj.reflectance), _grey(result.reflectance)
        log_ratio = np.where(m, np.log(np.maximum(r_est, 1e-6) / np.maximum(r_true, 1e-4)), np.nan)
        log_ratio -= np.nanmedian(log_ratio)
        s_est = _grey(result.shading)
        panels = [
            ("photograph", np.clip(obj.image / exposure, 0, 1) ** (1 / 2.2), {}),
            ("true reflectance", r_true, {"cmap": "gray"}),
            ("true shading", obj.shading, {"cmap": "gray"}),
            (f"{label}: reflectance", r_est, {"cmap": "gray"}),
            (f"shading (LMSE {v['lmse_shading']:.4f})", s_est, {"cmap": "gray"}),
            ("log(R_est/R_true)", log_ratio, {"cmap": "coolwarm", "vmin": -1.5, "vmax": 1.5}),
            (
                "local shading error",
                _local_error(obj.shading, s_est, m),
                {"cmap": "magma", "vmin": 0, "vmax": 0.3},
            ),
        ]
        for ax, (title, image, kw) in zip(row, panels, strict=True):
            shown = image[crop]
            if shown.ndim == 2 and "vmin" not in kw:
                shown = np.where(m[crop], shown / np.percentile(image[m], 99), np.nan)
                kw = {**kw, "vmin": 0, "vmax": 1}
            handle = ax.imshow(shown, **kw)
            ax.set_title(title, fontsize=9)
            ax.axis("off")
            if "cmap" in kw and kw["cmap"] != "gray":
                fig.colorbar(handle, ax=ax, fraction=0.046)
    fig.tight_layout()
    fig.savefig(out, dpi=70)


if __name__ == "__main__":
    warnings.filterwarnings("ignore", category=FutureWarning)  # gco's numpy aliases
    flags = tuple(a for a in sys.argv[1:] if a in ("--before", "--no-reads"))
    chosen = [a.split("=", 1)[1] for a in sys.argv[1:] if a.startswith("--variant=")]
    args = [a for a in sys.argv[1:] if a not in flags and not a.startswith("--variant=")]
    if len(args) not in (2, 3) or len(chosen) > 1 or (chosen and chosen[0] not in VARIANTS):
        sys.exit(__doc__)
    name = args[2] if len(args) == 3 else "teabag1"
    main(Path(args[0]), Path(args[1]), name, flags, chosen[0] if chosen else "original")
