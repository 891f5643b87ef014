"""One figure per stage of names-and-shades (thesis ch. 3) on one MIT development object.

Usage: python -P scripts/names_shades_stages.py MIT_DIR OBJECT OUT_DIR [--default-only] [PARAM=VALUE ...]

Writes OUT_DIR/nas-<object>-<stage>.png for the stages of Fig. 3.4: ``names`` (observed
Appendix A labels, each pixel painted with its label's centre of mass, as Fig. 3.2(b)),
``ridges`` (the log colour distribution and its ridges, as Fig. 3.3(b, c), and each pixel's
ridge), ``weights`` (the Case A/B/C weight of each pixel's edges, Fig. 3.6), ``labels`` (MRF
output, as Fig. 3.7(c) before coherence), ``regions``, and ``result`` (reflectance and shading
beside the ground truth, as Table 3.3), for the thesis' settings and, when PARAM=VALUE pairs are
given, for those too (e.g. ``gamma=10``); ``--default-only``: the defaults (with the pairs)
only, without the thesis' settings.
"""

from __future__ import annotations

import ast
import dataclasses
import sys
import warnings
from pathlib import Path

import numpy as np

from spectrinsic.decompose.evaluation.mit import load_mit_object, mit_measures
from spectrinsic.decompose.methods.colour_naming import label_centroids
from spectrinsic.decompose.methods.names_shades import NamesAndShades, grid_edges
from spectrinsic.spectra.colorimetry import encode_srgb

DPI = 80


def display(linear: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """sRGB-encoded view, exposure at the 99th percentile inside the mask, white outside."""
    a = np.asarray(linear, dtype=np.float64)
    if a.ndim == 2:
        a = np.repeat(a[:, :, None], 3, axis=2)
    scale = np.percentile(a[mask], 99) or 1.0
    out = encode_srgb(np.clip(a / scale, 0.0, 1.0))
    out[~mask] = 1.0
    return out


def paint(mask: np.ndarray, values: np.ndarray) -> np.ndarray:
    """``(H, W, 3)`` image with *values* ``(N, 3)`` on the masked pixels, white elsewhere."""
    out = np.ones(mask.shape + (3,))
    out[mask] = values
    return out


def label_image(mask, candidates, index) -> np.ndarray:
    """Each pixel painted with its Appendix A label's centre of mass (sRGB-encoded)."""
    colours = np.nan_to_num(label_centroids()[candidates[index]], nan=0.5)
    return paint(mask, colours)


def random_colours(ids: np.ndarray, seed: int = 0) -> np.ndarray:
    palette = np.random.default_rng(seed).uniform(0.15, 0.95, size=(int(ids.max()) + 1, 3))
    return palette[ids]


def save(fig, path: Path) -> None:
    fig.savefig(path, dpi=DPI, bbox_inches="tight")
    print(path)


def panels(images: list[tuple[str, np.ndarray]], path: Path, title: str) -> None:
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(images), figsize=(2.6 * len(images), 2.6))
    for ax, (name, img) in zip(np.atleast_1d(axes), images, strict=True):
        ax.imshow(img, interpolation="nearest")
        ax.set_title(name, fontsize=8)
        ax.axis("off")
    fig.suptitle(title, fontsize=9)
    save(fig, path)
    plt.close(fig)


def ridge_figure(stages, path: Path, title: str) -> None:
    import matplotlib.pyplot as plt

    shades = stages.shades
    logc = np.log(np.maximum(stages.pixels, 1.0 / 255.0))
    rng = np.random.default_rng(0)
    pick = rng.choice(logc.shape[0], size=min(4000, logc.shape[0]), replace=False)
    palette = random_colours(np.arange(shades.n_ridges))
    colours = palette[shades.ridge]
    fig = plt.figure(figsize=(7.8, 2.6))
    ax = fig.add_subplot(1, 3, 1, projection="3d")
    ax.scatter(*logc[pick].T, s=1, c=np.clip(np.exp(logc[pick]), 0, 1), alpha=0.5)
    ax.set_title("log colours (Fig. 3.3b)", fontsize=8)
    ax2 = fig.add_subplot(1, 3, 2, projection="3d")
    ax2.scatter(*shades.ridge_points.T, s=3, c=palette[shades.ridge_of_point])
    ax2.set_title(f"{shades.n_ridges} ridges (Fig. 3.3c)", fontsize=8)
    for a in (ax, ax2):
        a.set_xlabel("log R", fontsize=6)
        a.set_ylabel("log G", fontsize=6)
        a.set_zlabel("log B", fontsize=6)
        a.tick_params(labelsize=5)
    ax3 = fig.add_subplot(1, 3, 3)
    ax3.imshow(paint(stages.mask, colours), interpolation="nearest")
    ax3.set_title("SD(p): each pixel's ridge (Eq. 3.3)", fontsize=8)
    ax3.axis("off")
    fig.suptitle(title, fontsize=9)
    save(fig, path)
    plt.close(fig)


def weight_image(method: NamesAndShades, stages) -> np.ndarray:
    """Each pixel's smallest edge weight: alpha dark (Case A), beta grey (B), gamma white (C)."""
    edges, _ = grid_edges(stages.mask)
    n = stages.pixels.shape[0]
    low = np.full(n, np.inf)
    np.minimum.at(low, edges[:, 0], stages.weights)
    np.minimum.at(low, edges[:, 1], stages.weights)
    low[~np.isfinite(low)] = method.gamma
    grey = np.log(low / method.gamma * method.gamma_over_alpha) / np.log(method.gamma_over_alpha)
    return paint(stages.mask, np.repeat(np.clip(grey, 0, 1)[:, None], 3, axis=1))


def stage_figures(obj, method: NamesAndShades, out: Path, tag: str) -> dict:
    stages = method.labelling(obj.image, obj.mask)
    result = method.reflectance(stages)
    scores = mit_measures(obj, result)
    m = obj.mask
    what = f"{obj.name}, {tag}"
    panels([("input", display(obj.image, m)),
            (f"{stages.candidates.size} observed labels (Fig. 3.2b)",
             label_image(m, stages.candidates, stages.observed))],
           out / f"nas-{obj.name}-{tag}-names.png", f"{what}: colour names (sec. 3.2.1)")
    ridge_figure(stages, out / f"nas-{obj.name}-{tag}-ridges.png",
                 f"{what}: colour shades (sec. 3.2.2)")
    regions_info = result.info["regions"]
    panels([("edge weight: A dark, B grey, C white", weight_image(method, stages)),
            (f"MRF labels: {np.unique(stages.labels).size} used",
             label_image(m, stages.candidates, stages.labels))],
           out / f"nas-{obj.name}-{tag}-labels.png", f"{what}: MRF (sec. 3.3, Eq. 3.4)")
    panels([("estimated reflectance", display(result.reflectance, m)),
            ("true reflectance", display(obj.reflectance, m)),
            (f"estimated shading ({regions_info} regions)", display(result.shading.mean(axis=2), m)),
            ("true shading", display(obj.shading, m))],
           out / f"nas-{obj.name}-{tag}-result.png",
           f"{what}: LMSE {scores['lmse']:.4f}, Corr {scores['corr']:.3f}, MSE {scores['mse']:.4f}")
    return scores


def main(argv: list[str]) -> int:
    import matplotlib

    matplotlib.use("Agg")
    warnings.simplefilter("ignore")
    default_only = "--default-only" in argv
    argv = [a for a in argv if a != "--default-only"]
    mit_dir, name, out = Path(argv[0]), argv[1], Path(argv[2])
    out.mkdir(parents=True, exist_ok=True)
    obj = load_mit_object(mit_dir / f"{name}.npz")
    if not default_only:
        print("thesis", stage_figures(obj, NamesAndShades.thesis(), out, "thesis"))
    if len(argv) > 3 or default_only:
        change = {k: ast.literal_eval(v) for k, v in (a.split("=", 1) for a in argv[3:])}
        method = dataclasses.replace(NamesAndShades(), **change)
        print("chosen", stage_figures(obj, method, out, "default"))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
