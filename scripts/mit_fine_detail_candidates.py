"""Issue 48, round 8: candidate changes for teabag1 at half size, measured on the MIT development half.

Usage: python -P scripts/mit_fine_detail_candidates.py MIT_DIR CACHE_DIR [--variants=V,W] [OBJECT ...]
       python -P scripts/mit_fine_detail_candidates.py --upstream MIT_DIR [--variants=V,W] [OBJECT ...]

First form: names-and-shades without round 7's fine-detail step (``fine_detail=False``, the
``before`` of scripts/mit_stress.py) is run once per object and variant and cached in CACHE_DIR
(``OBJECT__VARIANT.npz``, reflectance and shading; existing files are reused, so a rerun costs
seconds; the files are keyed by object and variant only, so use a new folder after any change
to the method). Each candidate replaces round 7's step on that cached result; prints, per variant,
every object's MIT LMSE and its ratio to image-as-reflectance (IaR), the mean and the worst.
The last column, ``oracle-scales``, is a diagnostic, not a method: every region of the cached
reflectance (4-connected pixels of one value) takes its best scale against the *true*
reflectance, then round 7's step acts. Second form (``--upstream``): the defaults against three
changes before the step, each run in full (both are described in docs/names-shades-mit.md,
round 8). Each candidate's reason was written in its docstring before it was measured; none
has a constant of its own.
"""

from __future__ import annotations

import sys
import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np

import spectrinsic.decompose.methods.coherence as coherence
import spectrinsic.decompose.methods.collapse as collapse
import spectrinsic.decompose.methods.names_shades as names_shades
from spectrinsic.decompose.decomposition import Decomposition, finish, prepare_input
from spectrinsic.decompose.evaluation.mit import (
    MitObject,
    load_mit_object,
    mit_folder_objects,
    mit_measures,
)
from spectrinsic.decompose.evaluation.mit_variants import VARIANTS, apply_variant
from spectrinsic.decompose.methods.baselines import ImageAsReflectance
from spectrinsic.decompose.methods.shading_texture import (
    DETAIL_SIGMA,
    masked_gaussian,
    return_fine_detail,
)
from spectrinsic.decompose.methods.sharp_edges import SHARPNESS, achromatic_contrast
from spectrinsic.errors import DatasetError

Step = Callable[[Decomposition, np.ndarray, np.ndarray, MitObject], Decomposition]
DEFAULT_COHERENCE = coherence.global_coherence
DEFAULT_MINIMUM = coherence.bounded_minimum
#: The median's half-width: round 7's 2 px (a 5 x 5 window removes structures <= 2 px wide).
RADIUS = int(DETAIL_SIGMA)


def _from_shading(image: np.ndarray, mask: np.ndarray, shading: np.ndarray) -> Decomposition:
    """Reflectance ``image / shading`` (Eq. 3.1), 0 where the shading is 0 or off the mask."""
    with np.errstate(divide="ignore", invalid="ignore"):
        refl = np.where(shading > 0.0, image / np.where(shading > 0.0, shading, 1.0), 0.0)
    return finish(image, np.where(mask[:, :, None], refl, 0.0), mask, {})


def masked_median(values: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """``(H, W)`` median over the (2 RADIUS + 1)^2 window of the masked pixels; 0 off the mask."""
    h, w = mask.shape
    pad = np.pad(np.where(mask, values, np.nan), RADIUS, constant_values=np.nan)
    side = 2 * RADIUS + 1
    stack = np.stack([pad[dy : dy + h, dx : dx + w] for dy in range(side) for dx in range(side)])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return np.where(mask, np.nanmedian(stack, axis=0), 0.0)


def median(res: Decomposition, image: np.ndarray, mask: np.ndarray, _: MitObject) -> Decomposition:
    """The shading's 5 x 5 median instead of its Gaussian: a median removes lines and spots at
    most 2 px wide (mixed pixels, noise) without a halo and keeps a step or a monotone ramp
    exactly (a cast shadow's edge, sharp or soft: sec. 2.2.1's exception)."""
    s = np.asarray(res.shading, np.float64)
    return _from_shading(
        image, mask, np.stack([masked_median(s[..., c], mask) for c in range(3)], 2)
    )


def median_residual(
    res: Decomposition, image: np.ndarray, mask: np.ndarray, _: MitObject
) -> Decomposition:
    """``M * G(S / M)``: the median ``M`` keeps the steps, the Gaussian averages the thin
    texture ``S / M`` that the median removed, as round 7 does."""
    s = np.asarray(res.shading, np.float64)
    out = []
    for c in range(3):
        m = masked_median(s[..., c], mask)
        ratio = np.where(m > 0.0, s[..., c] / np.where(m > 0.0, m, 1.0), 1.0)
        out.append(m * masked_gaussian(ratio, mask, DETAIL_SIGMA))
    return _from_shading(image, mask, np.stack(out, 2))


def log_gaussian(
    res: Decomposition, image: np.ndarray, mask: np.ndarray, _: MitObject
) -> Decomposition:
    """Round 7's Gaussian over ``log S`` (the module defines the detail in log, Eq. 3.1)."""
    s = np.log(np.maximum(np.asarray(res.shading, np.float64), 1e-6))
    g = np.stack([np.exp(masked_gaussian(s[..., c], mask, DETAIL_SIGMA)) for c in range(3)], 2)
    return _from_shading(image, mask, np.where(mask[:, :, None], g, 0.0))


def _same_as_neighbours(refl: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """``(H, W)`` bool: every 4-neighbour is in the mask with the same reflectance (a region's
    interior; names-and-shades gives each region one reflectance)."""
    r = np.asarray(refl, np.float64)
    same = mask.copy()
    same[[0, -1], :] = False
    same[:, [0, -1]] = False
    eq_h = np.all(r[:, 1:] == r[:, :-1], axis=2) & mask[:, 1:] & mask[:, :-1]
    eq_v = np.all(r[1:] == r[:-1], axis=2) & mask[1:] & mask[:-1]
    same[:, 1:] &= eq_h
    same[:, :-1] &= eq_h
    same[1:] &= eq_v
    same[:-1] &= eq_v
    return same


def boundary_only(
    res: Decomposition, image: np.ndarray, mask: np.ndarray, _: MitObject
) -> Decomposition:
    """Round 7's step only within 2 px of the method's region boundaries (where one colour and
    one scale per region leave mixed pixels and steps); inside a region the MRF's Case B/C
    edges already called the image's variation shading (sec. 3.3.2)."""
    from scipy.ndimage import binary_dilation

    boundary = mask & ~_same_as_neighbours(res.reflectance, mask)
    near = binary_dilation(boundary, np.ones((2 * RADIUS + 1,) * 2, bool)) & mask
    smooth = np.asarray(return_fine_detail(res, image, mask).shading, np.float64)
    shading = np.where(near[:, :, None], smooth, np.asarray(res.shading, np.float64))
    return _from_shading(image, mask, shading)


def interior_only(
    res: Decomposition, image: np.ndarray, mask: np.ndarray, _: MitObject
) -> Decomposition:
    """Round 7's Gaussian over the regions' interior pixels only (a boundary pixel mixes two
    reflectances through the blur, so ``image / region colour`` is no shading there); a pixel
    with no interior pixel within the Gaussian's reach keeps round 7's average."""
    from scipy.ndimage import gaussian_filter

    s = np.asarray(res.shading, np.float64)
    inside = _same_as_neighbours(res.reflectance, mask)
    den = gaussian_filter(inside.astype(np.float64), DETAIL_SIGMA, mode="constant")
    out = []
    for c in range(3):
        num = gaussian_filter(np.where(inside, s[..., c], 0.0), DETAIL_SIGMA, mode="constant")
        fall = masked_gaussian(s[..., c], mask, DETAIL_SIGMA)
        out.append(
            np.where(mask, np.where(den > 0.0, num / np.where(den > 0.0, den, 1.0), fall), 0.0)
        )
    return _from_shading(image, mask, np.stack(out, 2))


def object_relative(
    res: Decomposition, image: np.ndarray, mask: np.ndarray, obj: MitObject
) -> Decomposition:
    """Round 7's 2 px kept relative to the object: ``2 px x`` (this image's size / the
    original's), 1 px at half size, 2 px (round 7) at full size."""
    sigma = DETAIL_SIGMA * mask.shape[1] / obj.mask.shape[1]
    s = np.asarray(res.shading, np.float64)
    return _from_shading(
        image, mask, np.stack([masked_gaussian(s[..., c], mask, sigma) for c in range(3)], 2)
    )


def oracle_scales(
    res: Decomposition, image: np.ndarray, mask: np.ndarray, varied: MitObject
) -> Decomposition:
    """Diagnostic (reads the truth): each region's best scale against the true reflectance
    (geometric mean of the ratio), then round 7's step."""
    from skimage.measure import label

    refl = np.asarray(res.reflectance, np.float64)
    _, key = np.unique(refl[mask].round(7), axis=0, return_inverse=True)
    ids = np.zeros(mask.shape, np.int64)
    ids[mask] = key.ravel() + 1
    regions = label(ids, background=0, connectivity=1)
    truth, est = varied.reflectance.mean(axis=2), refl.mean(axis=2)
    ok = mask & (truth > 0.0) & (est > 0.0)
    log_ratio = np.log(truth[ok] / est[ok])
    n = int(regions.max()) + 1
    scale = np.bincount(regions[ok], log_ratio, n) / np.maximum(
        np.bincount(regions[ok], None, n), 1
    )
    fixed = finish(image, refl * np.exp(scale[regions])[:, :, None], mask, {})
    return return_fine_detail(fixed, image, mask)


STEPS: dict[str, Step] = {
    "no step": lambda res, image, mask, obj: res,
    "round 7": lambda res, image, mask, obj: return_fine_detail(res, image, mask),
    "median": median,
    "median-residual": median_residual,
    "log-gaussian": log_gaussian,
    "boundary-only": boundary_only,
    "interior-only": interior_only,
    "object-relative": object_relative,
    "oracle-scales": oracle_scales,
}


def contrast_over_two_pixels(log_lum: np.ndarray, flat: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """Round 5's sharp, high-contrast test with the contrast taken over the span of a step
    made within 2 px (the edge with one more pixel on either side, or the edge alone), as its
    sharpness test allows, instead of the edge's one-pixel step only."""
    from spectrinsic.decompose.methods.sharp_edges import _reach

    a, b = flat[:, 0], flat[:, 1]
    step = b - a
    values = log_lum.ravel()
    linear = np.exp(values)
    before, after = _reach(a, -step, mask), _reach(b, step, mask)
    sharp = np.abs(linear[b] - linear[a]) >= SHARPNESS * np.abs(linear[after] - linear[before])
    a1, b1 = _one_more(a, -step, mask), _one_more(b, step, mask)
    contrast = np.maximum.reduce(
        [
            np.abs(values[b] - values[a]),
            np.abs(values[b] - values[a1]),
            np.abs(values[b1] - values[a]),
        ]
    )
    return sharp & (contrast >= achromatic_contrast())


def _one_more(start: np.ndarray, step: np.ndarray, mask: np.ndarray) -> np.ndarray:
    h, w = mask.shape
    there = start + step
    horizontal = np.abs(step) == 1
    inside = np.where(horizontal, there // w == start // w, (there >= 0) & (there < h * w))
    ok = inside & mask.ravel()[np.clip(there, 0, h * w - 1)]
    return np.where(ok, there, start)


def scale_free_coherence(a) -> np.ndarray:
    """Eq. 3.10 with the trivial solution excluded by ``||lambda|| = 1`` instead of
    ``lambda >= 1`` on every region: per connected group of regions, the eigenvector of
    ``A^T A``'s smallest eigenvalue (positive: an irreducible M-matrix), minimum scaled to 1."""
    from scipy.sparse.csgraph import connected_components

    q = (a.T @ a).tocsr()
    lam = np.ones(q.shape[0])
    used = q.diagonal() > 0.0
    _, group = connected_components(q, directed=False)
    for g in np.unique(group):
        idx = np.flatnonzero((group == g) & used)
        if idx.size > 1:
            vec = np.abs(np.linalg.eigh(q[idx][:, idx].toarray())[1][:, 0])
            lam[idx] = vec / max(float(vec.min()), 1e-300)
    return lam


def thin_regions(regions: np.ndarray) -> np.ndarray:
    """``(R + 1,)`` bool: the region has no pixel whose four neighbours are all in it (it is
    made only of boundary pixels, which the blur mixes at a reflectance edge)."""
    same = regions > 0
    same[[0, -1], :] = False
    same[:, [0, -1]] = False
    eq_h, eq_v = regions[:, 1:] == regions[:, :-1], regions[1:] == regions[:-1]
    same[:, 1:] &= eq_h
    same[:, :-1] &= eq_h
    same[1:] &= eq_v
    same[:-1] &= eq_v
    thin = np.ones(int(regions.max()) + 1, bool)
    thin[regions[same]] = False
    thin[0] = False
    return thin


def thin_regions_second(
    regions: np.ndarray,
    region_intensity: np.ndarray,
    image_intensity: np.ndarray,
    blurred: np.ndarray | None = None,
) -> np.ndarray:
    """Sec. 3.4 in two stages: Eq. 3.9 on the pairs of regions that have an interior (as now,
    ``lambda >= 1``), then the thin regions' scales (:func:`thin_regions`: their colour and
    boundary reads are mixtures, which compress the ratios chained through them) minimise the
    same ``W`` with the others fixed (``Q_tt lambda_t = -Q_tf lambda_f``); a thin region that
    touches no other keeps the one-stage solution, rescaled to the first stage's."""
    import scipy.sparse as sp
    from scipy.sparse.linalg import spsolve

    thin = thin_regions(regions)
    one_stage = DEFAULT_MINIMUM

    def two_stages(a) -> np.ndarray:
        a = sp.csr_matrix(a)
        full = one_stage(a)
        touches = np.asarray(a[:, np.flatnonzero(thin)].getnnz(axis=1)).ravel() > 0
        lam = one_stage(a[~touches]) if (~touches).any() else np.ones(a.shape[1])
        q = (a.T @ a).tocsr()
        used = q.diagonal() > 0.0
        t, f = np.flatnonzero(thin & used), np.flatnonzero(~thin & used)
        if t.size and f.size:
            rhs = -np.asarray(q[t][:, f] @ lam[f]).ravel()
            with np.errstate(all="ignore"):
                sol = np.atleast_1d(spsolve(sp.csc_matrix(q[t][:, t]), rhs))
            bad = ~np.isfinite(sol) | (sol <= 0.0)
            sol[bad] = full[t][bad] * float(np.median(lam[f] / full[f]))
            lam[t] = sol
        return lam

    coherence.bounded_minimum = two_stages
    try:
        return DEFAULT_COHERENCE(regions, region_intensity, image_intensity, blurred)
    finally:
        coherence.bounded_minimum = one_stage


def _iar(varied: MitObject) -> float:
    return mit_measures(varied, ImageAsReflectance()(varied.image, varied.mask))["lmse"]


def _print(
    rows: dict[tuple[str, str, str], float],
    variants: list[str],
    names: list[str],
    objects: list[str],
) -> None:
    for variant in variants:
        print(f"\n## {variant}\n\n| object | IaR | " + " | ".join(names) + " |")
        print("|---" * (len(names) + 2) + "|")
        worst = dict.fromkeys(names, ("", 0.0))
        for obj in objects:
            iar = rows[(variant, obj, "IaR")]
            cells = []
            for n in names:
                ratio = rows[(variant, obj, n)] / iar
                worst[n] = max(worst[n], (obj, ratio), key=lambda t: t[1])
                cells.append(f"{rows[(variant, obj, n)]:.4f} ({ratio:.2f})")
            print(f"| {obj} | {iar:.4f} | " + " | ".join(cells) + " |")
        means = [np.mean([rows[(variant, o, n)] for o in objects]) for n in ["IaR", *names]]
        print("| mean | " + " | ".join(f"{m:.4f}" for m in means) + " |")
        print("| worst | | " + " | ".join(f"{worst[n][0]} {worst[n][1]:.2f}" for n in names) + " |")


def candidates(folder: Path, cache: Path, variants: list[str], objects: list[str] | None) -> None:
    """The first form (module docstring)."""
    cache.mkdir(parents=True, exist_ok=True)
    before = names_shades.NamesAndShades(fine_detail=False)
    rows: dict[tuple[str, str, str], float] = {}
    names_seen: list[str] = []
    for path in mit_folder_objects(folder, objects):
        obj = load_mit_object(path)
        names_seen.append(obj.name)
        for variant in variants:
            varied = apply_variant(variant, obj)
            file = cache / f"{obj.name}__{variant}.npz"
            if not file.exists():
                res = before(varied.image, varied.mask)
                np.savez_compressed(file, reflectance=res.reflectance, shading=res.shading)
            with np.load(file) as cached:
                res = Decomposition(cached["reflectance"], cached["shading"], {})
            image, mask = prepare_input(varied.image, varied.mask)
            rows[(variant, obj.name, "IaR")] = _iar(varied)
            for name, step in STEPS.items():
                out = step(res, image, mask, varied if name == "oracle-scales" else obj)
                rows[(variant, obj.name, name)] = mit_measures(varied, out)["lmse"]
    _print(rows, variants, list(STEPS), names_seen)


def upstream(folder: Path, variants: list[str], objects: list[str] | None) -> None:
    """The second form (module docstring)."""
    default_edges = names_shades.sharp_contrast_edges
    changes = {
        "defaults": (default_edges, DEFAULT_MINIMUM, DEFAULT_COHERENCE),
        "contrast-over-2-px": (contrast_over_two_pixels, DEFAULT_MINIMUM, DEFAULT_COHERENCE),
        "scale-free-coherence": (default_edges, scale_free_coherence, DEFAULT_COHERENCE),
        "thin-regions-second": (default_edges, DEFAULT_MINIMUM, thin_regions_second),
    }
    rows: dict[tuple[str, str, str], float] = {}
    names_seen: list[str] = []
    try:
        for path in mit_folder_objects(folder, objects):
            obj = load_mit_object(path)
            names_seen.append(obj.name)
            for variant in variants:
                varied = apply_variant(variant, obj)
                rows[(variant, obj.name, "IaR")] = _iar(varied)
                for name, (edges, minimum, solve) in changes.items():
                    names_shades.sharp_contrast_edges = collapse.sharp_contrast_edges = edges
                    coherence.bounded_minimum = minimum
                    names_shades.global_coherence = solve
                    res = names_shades.NamesAndShades()(varied.image, varied.mask)
                    rows[(variant, obj.name, name)] = mit_measures(varied, res)["lmse"]
    finally:
        names_shades.sharp_contrast_edges = collapse.sharp_contrast_edges = default_edges
        coherence.bounded_minimum = DEFAULT_MINIMUM
        names_shades.global_coherence = DEFAULT_COHERENCE
    _print(rows, variants, list(changes), names_seen)


def main(argv: list[str]) -> int:
    up = argv[:1] == ["--upstream"]
    args = argv[1:] if up else argv
    variants = list(VARIANTS)
    rest = []
    for arg in args:
        if arg.startswith("--variants="):
            variants = arg.split("=", 1)[1].split(",")
        else:
            rest.append(arg)
    need = 1 if up else 2
    unknown = [v for v in variants if v not in VARIANTS]
    if len(rest) < need or unknown:
        print(
            "usage: mit_fine_detail_candidates.py [--upstream] MIT_DIR [CACHE_DIR] "
            f"[--variants=V,W] [OBJECT ...]; variants: {', '.join(VARIANTS)}",
            file=sys.stderr,
        )
        return 2
    folder, objects = Path(rest[0]), rest[need:] or None
    if not up and Path(rest[1]).exists() and not Path(rest[1]).is_dir():
        print(
            f"mit_fine_detail_candidates.py: {rest[1]} is a file; expected a folder",
            file=sys.stderr,
        )
        return 2
    try:
        mit_folder_objects(folder, objects)
    except DatasetError as exc:
        print(f"mit_fine_detail_candidates.py: {exc}", file=sys.stderr)
        return 2
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        if up:
            upstream(folder, variants, objects)
        else:
            candidates(folder, Path(rest[1]), variants, objects)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
