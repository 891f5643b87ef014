"""Issue 48, round 9: how sec. 3.4 reads the boundary intensities, measured on the MIT development half.

Usage: python -P scripts/mit_coherence_candidates.py MIT_DIR [--variants=V,W] [OBJECT ...]

Each object under each stress variant (:mod:`spectrinsic.decompose.evaluation.mit_variants`)
is labelled once (steps 1-3 of names-and-shades, which none of the candidates touches); every
candidate then runs steps 4-5 and round 7's fine-detail step on that labelling, so the 60 runs
of a candidate take seconds (the collapse guard, which never acts on MIT, is left out). Prints
per variant every object's MIT LMSE and its ratio to image-as-reflectance (IaR), the mean and
the worst, then how many runs exceed issue 48's 1.5x.

The candidates, each with its reason written before it was measured (docs/names-shades-mit.md,
round 9):

* ``round-8``: main before round 9; across a sharp, high-contrast step the boundary pixels are
  read up to 2 px inside while the pixels passed change like a symmetric blur (round 6's reads,
  copied here from main at 54b7b95).
* ``boundary``: every boundary read where it is (Eq. 3.8 as the thesis writes it).
* ``extrapolated`` (shipped): across a sharp, high-contrast step each side is extrapolated
  linearly in log from the two pixels behind its boundary pixel: that skips the mixed pixel and
  cancels a shading gradient to first order, the two failures of round 6's reads.
* ``extrapolated-everywhere``: the same at every region boundary (Eq. 3.8's premise is local
  everywhere; costs noise where the boundary pixels are not mixed).
* ``edge-ratios``: each region pair's ratio as the geometric mean of its per-edge ratios
  instead of the ratio of the two sides' means (the same shading holds edge by edge, not
  between means over a long boundary).
* ``least-absolute``: Eq. 3.9 in L1 instead of least squares (iteratively reweighted,
  weights ``1 / sqrt|r|`` on the rows, 20 rounds), so that the few boundaries where Eq. 3.8's
  premise fails (a crease taken for print) carry their error alone instead of spreading it
  over the chain of regions.
"""

from __future__ import annotations

import sys
import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np
import scipy.sparse as sp

import spectrinsic.decompose.methods.coherence as coherence
import spectrinsic.decompose.methods.names_shades as names_shades
from spectrinsic.decompose.decomposition import prepare_input
from spectrinsic.decompose.evaluation.mit import load_mit_object, mit_folder_objects, mit_measures
from spectrinsic.decompose.evaluation.mit_variants import VARIANTS, apply_variant
from spectrinsic.decompose.methods.baselines import ImageAsReflectance
from spectrinsic.decompose.methods.shading_texture import return_fine_detail
from spectrinsic.errors import DatasetError

Coherence = Callable[..., np.ndarray]
SHIPPED = coherence.global_coherence
READS = coherence._side_reads
MINIMUM = coherence.bounded_minimum
#: The issue's bound: no object above this times image-as-reflectance.
BOUND = 1.5


def round_8_reads(regions, intensity, pa, pb, blurred):
    """Main's reads before round 9 (``coherence._past_blur`` at 54b7b95, reach 2)."""
    if blurred is None:
        return intensity[pa], intensity[pb]
    h, w = regions.shape
    flat_regions = regions.ravel()
    step = pb - pa
    horizontal = np.abs(step) == 1
    sign = np.sign(intensity[pa] - intensity[pb])
    here_a, here_b = pa.copy(), pb.copy()
    going = blurred.copy()
    for _ in range(2):
        next_a, next_b = here_a - step, here_b + step
        for here, there, own in ((here_a, next_a, pa), (here_b, next_b, pb)):
            in_image = np.where(horizontal, there // w == here // w, (there >= 0) & (there < h * w))
            going &= in_image & (flat_regions[np.clip(there, 0, h * w - 1)] == flat_regions[own])
        next_a, next_b = np.clip(next_a, 0, h * w - 1), np.clip(next_b, 0, h * w - 1)
        away_a = sign * (intensity[next_a] - intensity[here_a])
        away_b = -sign * (intensity[next_b] - intensity[here_b])
        going &= (away_a > 0) & (away_b > 0)
        going &= 2.0 * np.minimum(away_a, away_b) >= np.maximum(away_a, away_b)
        here_a = np.where(going, next_a, here_a)
        here_b = np.where(going, next_b, here_b)
    return intensity[here_a], intensity[here_b]


def least_absolute(a) -> np.ndarray:
    """Eq. 3.9 in L1: :func:`coherence.bounded_minimum` on rows reweighted by ``1/sqrt|r|``."""
    lam = MINIMUM(a)
    for _ in range(20):
        r = np.abs(a @ lam)
        lam = MINIMUM(sp.diags(1.0 / np.sqrt(np.maximum(r, 1e-6 * max(r.max(), 1e-300)))) @ a)
    return lam


def edge_ratios(regions, region_intensity, image_intensity, blurred=None) -> np.ndarray:
    """Eq. 3.9 with each pair's ratio the geometric mean of its per-edge ratios (shipped reads)."""
    n = int(regions.max()) + 1
    flat_regions = regions.ravel()
    _, flat = coherence.grid_edges(regions > 0)
    ra, rb = flat_regions[flat[:, 0]], flat_regions[flat[:, 1]]
    cross = ra != rb
    if not cross.any():
        return np.ones(n)
    pa, pb, ra, rb = flat[cross, 0], flat[cross, 1], ra[cross], rb[cross]
    marks = None if blurred is None else blurred[cross]
    va, vb = READS(regions, image_intensity.ravel(), pa, pb, marks)
    log_ratio = np.log(np.maximum(vb, 1e-12) / np.maximum(va, 1e-12))  # log(L_b / L_a)
    lo, hi = np.minimum(ra, rb), np.maximum(ra, rb)
    log_ratio = np.where(ra < rb, log_ratio, -log_ratio)  # log(L_hi / L_lo)
    pairs, inverse, counts = np.unique(lo * n + hi, return_inverse=True, return_counts=True)
    mean_log = np.bincount(inverse.ravel(), weights=log_ratio) / counts
    i, j = np.divmod(pairs, n)
    a_i = region_intensity[i] * np.exp(mean_log)  # lambda_i L_i L_j^orig / L_i^orig
    a_j = region_intensity[j]
    s = np.sqrt(2.0 * counts) / (0.5 * (a_i + a_j))
    rows = np.repeat(np.arange(pairs.size), 2)
    a = sp.csr_matrix(
        (np.stack([s * a_i, -s * a_j], 1).ravel(), (rows, np.stack([i, j], 1).ravel())),
        shape=(pairs.size, n),
    )
    lam = MINIMUM(a)
    lam[0] = 1.0
    return lam / lam[1:].min()


def everywhere(regions, region_intensity, image_intensity, blurred=None) -> np.ndarray:
    """The shipped extrapolation at every region boundary (every edge marked)."""
    return SHIPPED(regions, region_intensity, image_intensity, np.ones_like(blurred, bool))


#: Candidate -> (coherence function, reads, bounded minimum) put in place for its runs.
CANDIDATES: dict[str, tuple[Coherence, Callable, Callable]] = {
    "round-8": (SHIPPED, round_8_reads, MINIMUM),
    "boundary": (lambda r, ri, ii, blurred=None: SHIPPED(r, ri, ii, None), READS, MINIMUM),
    "extrapolated": (SHIPPED, READS, MINIMUM),
    "extrapolated-everywhere": (everywhere, READS, MINIMUM),
    "edge-ratios": (edge_ratios, READS, MINIMUM),
    "least-absolute": (SHIPPED, READS, least_absolute),
}


def measure(folder: Path, variants: list[str], objects: list[str] | None) -> dict:
    """``{(candidate, variant, object): (LMSE, IaR LMSE)}``."""
    method = names_shades.NamesAndShades()
    rows = {}
    for path in mit_folder_objects(folder, objects):
        obj = load_mit_object(path)
        for variant in variants:
            varied = apply_variant(variant, obj)
            stages = method.labelling(varied.image, varied.mask)
            image, mask = prepare_input(varied.image, varied.mask)
            iar = mit_measures(varied, ImageAsReflectance()(varied.image, varied.mask))["lmse"]
            for name, (solve, reads, minimum) in CANDIDATES.items():
                names_shades.global_coherence = solve
                coherence._side_reads, coherence.bounded_minimum = reads, minimum
                try:
                    result = return_fine_detail(method.reflectance(stages), image, mask)
                finally:
                    names_shades.global_coherence = SHIPPED
                    coherence._side_reads, coherence.bounded_minimum = READS, MINIMUM
                rows[(name, variant, obj.name)] = (mit_measures(varied, result)["lmse"], iar)
            print(f"{variant} {obj.name} done", file=sys.stderr, flush=True)
    return rows


def report(rows: dict, variants: list[str]) -> None:
    names = list(CANDIDATES)
    objects = sorted({key[2] for key in rows})
    for variant in variants:
        print(f"\n## {variant}\n\n| object | IaR | " + " | ".join(names) + " |")
        print("|---" * (len(names) + 2) + "|")
        for obj in objects:
            iar = rows[(names[0], variant, obj)][1]
            cells = [
                f"{rows[(n, variant, obj)][0]:.4f} ({rows[(n, variant, obj)][0] / iar:.2f})"
                for n in names
            ]
            print(f"| {obj} | {iar:.4f} | " + " | ".join(cells) + " |")
        means = [np.mean([rows[(n, variant, o)][0] for o in objects]) for n in names]
        iar_mean = np.mean([rows[(names[0], variant, o)][1] for o in objects])
        print(f"| mean | {iar_mean:.4f} | " + " | ".join(f"{m:.4f}" for m in means) + " |")
    print("\nruns above 1.5x IaR, worst ratio:")
    for n in names:
        ratios = [lmse / iar for (c, _, _), (lmse, iar) in rows.items() if c == n]
        print(f"  {n}: {sum(r > BOUND for r in ratios)} of {len(ratios)}, worst {max(ratios):.2f}")


def main(argv: list[str]) -> int:
    variants = list(VARIANTS)
    rest = []
    for arg in argv:
        if arg.startswith("--variants="):
            variants = arg.split("=", 1)[1].split(",")
        else:
            rest.append(arg)
    unknown = [v for v in variants if v not in VARIANTS]
    if not rest or unknown:
        print(
            "usage: mit_coherence_candidates.py MIT_DIR [--variants=V,W] [OBJECT ...]; "
            f"variants: {', '.join(VARIANTS)}",
            file=sys.stderr,
        )
        return 2
    folder, objects = Path(rest[0]), rest[1:] or None
    try:
        mit_folder_objects(folder, objects)
    except DatasetError as exc:
        print(f"mit_coherence_candidates.py: {exc}", file=sys.stderr)
        return 2
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        report(measure(folder, variants, objects), variants)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
