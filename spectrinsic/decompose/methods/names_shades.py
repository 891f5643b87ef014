"""The thesis' method: shades and names of colour for intrinsic images (chapter 3; Serra et al. 2012).

Pipeline (Fig. 3.4):

1. **Colour names** (sec. 3.2.1): Benavente et al.'s memberships over the 11 basic terms,
   discretised to the Appendix A labels (:mod:`spectrinsic.decompose.methods.colour_naming`).
2. **Colour shades** (sec. 3.2.2): RAD ridges (MLSEC-ST creaseness, thinning, pruning) of the
   distribution of the log image's colours
   (:mod:`spectrinsic.decompose.methods.ridges`; "we apply a logarithm to the input image before obtaining
   its color-shade descriptor", sec. 3.5).
3. **MRF** (sec. 3.3, Eq. 3.4): ``E(x) = mu sum_i |x_i - y_i|_1 + (1 - mu) sum_ij w_ij |x_i - x_j|_1``
   on the 4-neighbourhood, with ``w_ij = alpha`` (different ridges), ``beta`` (same ridge, the
   pixel step not parallel to it) or ``gamma`` (same ridge, parallel), ``mu = 1/3``,
   ``gamma/alpha = 100``, ``gamma/beta = 2`` (sec. 3.5), minimised by alpha-expansion graph cuts
   (gco-wrapper, ``cut_general_graph``).
4. **Regions and their colour**: areas of uniform label (4-connected) are the regions ``U_i``;
   each takes its label's centre of mass in the RGB cube (sec. 3.3.3, ``reflectance_colour=
   "label-centroid"``) or, by default, the region's mean image colour (see below).
5. **Global coherence** (sec. 3.4, Eqs. 3.8-3.10): one scale ``lambda_i >= 1`` per region of
   uniform label so that the intensity ratios of touching regions follow the image's.

Simplifications, all documented where they act: the observations ``y_i`` and candidate labels
are the Appendix A labels that occur in the image (labels no pixel is observed with are not
offered); the thesis gives only ratios of ``alpha, beta, gamma`` and leaves the absolute scale and
the angle threshold open (``gamma = 1``, 30 degrees here); the angle ``theta_ij`` is measured
against the ridge tangent at ``pi(p_i)``, the limit of the chord ``pi(p_i) pi(p_j)`` for
neighbouring colours, and identical colours count as parallel; Eq. 3.9 is solved as a bounded
linear least-squares problem (:func:`spectrinsic.decompose.methods.coherence.bounded_minimum`, exact
active set) instead of belief propagation, with
``L^orig`` measured on the pixels along each shared boundary and each term divided by its mean
product so that dark and bright boundaries weigh alike.

Deviations that are defaults, each a named parameter (:meth:`NamesAndShades.thesis` switches
all of them off):

* ``split_by_ridge``: regions of one label that lie on different ridges are separated (two
  neighbouring materials with the same colour name would otherwise merge into one region);
* ``reflectance_colour="region-mean"``: a region takes its mean image colour rather than the
  label's centroid. On synthetic Mondrians (``tests/decompose``) the label centroids, which
  quantise every chromaticity to the ~250 labels in use, gave reflectance LMSE near 0.2, ten
  times worse than taking the image itself as reflectance;
* ``colour_constancy="grey-world"``: the light's colour, estimated over the whole image, is
  divided out of the reflectance (the MIT images of the thesis are under near-white light;
  the rendered set has coloured lights, under which every colour metric counts the cast);
* ``max_axis_angle=45``: RAD's crest bins more than 45 degrees from the grey diagonal of the
  log-colour histogram are cut before the ridges are labelled (a surface's ridge runs along
  the diagonal; a crest across it bridges two surfaces, which would otherwise share a ridge);
* ``flooding``: each colour takes the ridge of RAD's flooding step (histogram bins given to the
  ridges by descending density, :mod:`spectrinsic.decompose.methods.ridges`), not Eq. 3.3's nearest;
* ``merge_shading``: touching regions whose shared boundary is mostly Case C (one ridge, step
  along it: shading) are one region (:mod:`spectrinsic.decompose.methods.shade_cases`);
* ``pale_vs_chromatic``: white/grey-to-chromatic name edges are Case A (a white light's shading);
* ``sharp_edges="achromatic"``: sharp, high-contrast edges between achromatic names are Case A
  (the Retinex cue where the colour cues are silent; :mod:`spectrinsic.decompose.methods.
  sharp_edges`), and ``collapse_guard``: a collapsed result is re-solved or replaced
  (:mod:`spectrinsic.decompose.methods.collapse`; docs/names-shades-mit.md, round 5);
* ``blurred_steps``: across a sharp, high-contrast step, sec. 3.4's boundary intensities are
  extrapolated from the two pixels behind each side, past the pixels the optics (or a
  downscaling) mixed (:func:`spectrinsic.decompose.methods.coherence.global_coherence`;
  rounds 6 and 9);
* ``fine_detail``: the image's fine detail (within about 2 pixels) that the regions leave in
  the shading goes to the reflectance (the Retinex cue of sec. 2.2.1; the shading's 2-pixel
  Gaussian average, :mod:`spectrinsic.decompose.methods.shading_texture`; round 7);
* ``colour_constancy``, ``gamma=3`` (the thesis gives only ratios; ``gamma_over_alpha=100``
  and ``gamma_over_beta=2`` are the thesis' own), the cut's angle and the RAD parameters the
  thesis does not state (``creaseness=1.5``, ``sigma=2`` bins) chosen by :data:`PROTOCOL`
  (on the rendered set and again on the MIT development half, docs/names-shades-mit.md);
* ``expansion_cycles=2`` and ``name_bits=8``: speed (same scores on Mondrians).
"""

# long module: one method (thesis chapter 3), its five steps and the deviations acting in them

from __future__ import annotations

import logging
import time
import warnings
from dataclasses import dataclass, replace
from typing import Any, ClassVar, Literal

import numpy as np
import numpy.typing as npt

from ...errors import DecomposeError, MissingDependencyError, validate_choice
from ...spectra.colorimetry import decode_srgb as _srgb_decode
from ...spectra.colorimetry import encode_srgb as _srgb_encode
from ..decomposition import Decomposition, finish, prepare_input
from .coherence import global_coherence, grid_edges
from .collapse import guard_collapse
from .colour_naming import (
    appendix_a_labels,
    label_centroids,
    observed_labels,
)
from .constancy import discount_illuminant
from .retinex import ColourRetinex
from .ridges import RIDGE_DETECTORS, ColourShades, colour_shades
from .shade_cases import CASE_C, edge_cases, merge_shading_boundaries
from .shade_cases import split_pale_from_chromatic as _split_pale
from .shading_texture import return_fine_detail
from .sharp_edges import log_luminance, sharp_contrast_edges, split_sharp_achromatic

__all__ = ["Labelling", "NamesAndShades", "global_coherence", "grid_edges"]

logger = logging.getLogger(__name__)

#: The parameter protocols and their outcome (scripts/choose_parameters.py on the rendered set,
#: scripts/mit_ablation.py on the MIT development half; docs/names-shades-mit.md).
PROTOCOL = (
    "rendered set: hold-one-object-out over the 32 rendered single-object samples (8 objects x "
    "4 lights, default set, 256^2, image_denoised), score (LMSE grey shading + LMSE colour "
    "reflectance)/2; grid gamma_over_alpha in {10, 100} x mu in {1/3, 1/2} x colour_constancy in "
    "{none, grey-world, shades-of-grey, max-rgb}; chosen gamma_over_alpha=10, mu=1/3, grey-world "
    "(0.0600; held-out 0.0612; the thesis' settings without constancy 0.1071). MIT development "
    "half (10 photographs, thesis protocol, score = MIT LMSE): hold-one-object-out over gamma in "
    "{1, 3, 10, 30} x gamma_over_alpha in {10, 100} (6 points) x reflectance_colour x "
    "split_by_ridge x colour_constancy in {none, grey-world}, round 1 (hessian ridges): LMSE "
    "0.0449, held-out 0.0543. Round 2 adds RAD ridges (creaseness/sigma 1.5/2 at gamma 0.3, 1, 3, "
    "10; 1.5/1.5, 1.5/3, 1.25/2 and 1.0/1 at gamma 1; 13 MRF points, 104 grid points in all): "
    "chosen RAD, "
    "creaseness 1.5, sigma 2, gamma 1, gamma_over_alpha 10, region-mean, split by ridge, "
    "grey-world (LMSE 0.0314, held-out 0.0354; 8 of 10 folds chose it); the thesis' settings "
    "0.0721 (RAD) and 0.0716 (hessian). Round 3 adds RAD's crest cut across the grey diagonal "
    "(max_axis_angle 60 at gamma 1, 3, 10 and 45 at gamma 1, 3, 10, 30 at gamma 3; 184 grid "
    "points) and restricts the choice, in every fold alike, to points that lose to reflectance "
    "= image on at most 2 of the objects chosen on: chosen max_axis_angle 45, gamma 3, "
    "gamma_over_alpha 100 (the thesis' ratio), region-mean, split by ridge, grey-world (LMSE "
    "0.0296, held-out 0.0448, 8 of 10 objects below the baseline; unconstrained choice gamma 10, "
    "0.0295, 7 of 10). Round 4 (issue 33) chooses no parameter: structure only, on by default, "
    "off in thesis(), at round 3's values: RAD's flooding and regions joined across mostly-Case-C "
    "boundaries (LMSE 0.0277, hold-one-out 0.0277), then white/grey-to-chromatic name edges as "
    "Case A (round 4b: LMSE 0.0257, hold-one-out 0.0276 over 240 points), 8 of 10 below "
    "baseline. Round 5 (issue 48) chooses no parameter either: sharp (one-pixel step at least "
    "half the change over six pixels), high-contrast (one achromatic name, x3.7) edges between "
    "achromatic names are Case A, and a collapse guard re-solves or falls back (LMSE 0.0256; "
    "0.0255 once RAD's tied eigenvectors were made independent of the BLAS kernel); round 6 "
    "(issue 48) adds blurred_steps, no parameter either (LMSE 0.0255 unchanged, teabag1 0.0516 "
    "to 0.0515; synthetic blurred print 4.24 to 16.0); round 7 (issue 48) adds fine_detail, no "
    "parameter either (its 2-pixel scale is round 5's blur width, set before measuring): LMSE "
    "0.0255 to 0.0227, teabag1 0.0515 to 0.0289; round 9 (issue 48) changes how blurred_steps "
    "reads a step, no parameter either (extrapolated from the two pixels behind each side): "
    "LMSE 0.0227 unchanged, teabag1 0.0289 to 0.0269, at half size 0.0490 to 0.0452"
)
#: Linear values are normalised so that this percentile of the brightest channel maps to 1
#: before sRGB encoding for the naming model (which expects display values).
_EXPOSURE_PERCENTILE = 99.0
#: Floor of normalised linear values before the logarithm (1/255 of the exposure white).
_LOG_FLOOR = 1.0 / 255.0


def _import_gco() -> Any:
    """The ``gco`` module of gco-wrapper (alpha-expansion graph cuts), its import warnings hushed."""
    try:
        with warnings.catch_warnings():  # gco aliases np.int/np.float/np.bool on import
            warnings.simplefilter("ignore", FutureWarning)
            import gco
    except ImportError as exc:  # pragma: no cover - declared dependency
        raise MissingDependencyError(
            "names-shades needs gco-wrapper (pip install gco-wrapper)"
        ) from exc
    return gco


@dataclass(frozen=True)
class Labelling:
    """What steps 1-3 of :class:`NamesAndShades` produce (the stages the figures show).

    Attributes
    ----------
    image
        ``(H, W, 3)`` float64 input as given (clipped at 0).
    mask
        ``(H, W)`` bool pixels decomposed; the per-pixel arrays below follow its raster order.
    linear
        ``(H, W, 3)`` input divided by its exposure white (99th percentile of the brightest
        channel).
    pixels
        ``(N, 3)`` masked ``linear`` clipped to [0, 1].
    candidates
        ``(K,)`` Appendix A label indices observed in the image (the MRF's label set).
    observed
        ``(N,)`` observation ``y_i`` of each pixel, an index into ``candidates`` (sec. 3.2.1).
    shades
        Colour-shade descriptor of the log colours (sec. 3.2.2).
    cases
        ``(E,)`` Case A/B/C of the 4-neighbour edges (:func:`grid_edges` order; sec. 3.3.2,
        :func:`spectrinsic.decompose.methods.shade_cases.edge_cases`).
    weights
        ``(E,)`` ``w_ij`` of the same edges (alpha, beta or gamma by case).
    labels
        ``(N,)`` MRF output, an index into ``candidates`` (sec. 3.3).
    timings
        Seconds per step (``names_s``, ``shades_s``, ``mrf_s``).
    """

    image: np.ndarray
    mask: np.ndarray
    linear: np.ndarray
    pixels: np.ndarray
    candidates: np.ndarray
    observed: np.ndarray
    shades: ColourShades
    cases: np.ndarray
    weights: np.ndarray
    labels: np.ndarray
    timings: dict[str, float]


@dataclass(frozen=True)
class NamesAndShades:
    """Serra et al. (2012) names-and-shades intrinsic decomposition (thesis chapter 3).

    Attributes
    ----------
    mu
        Weight of the singleton term in Eq. 3.4 (sec. 3.5: 1/3).
    gamma
        Pairwise weight of same-ridge parallel neighbours (Case C); absolute scale not given in
        the thesis.
    gamma_over_alpha, gamma_over_beta
        Weight ratios (sec. 3.5: 100 and 2, the defaults; :data:`PROTOCOL` chose 100 on the
        MIT development half); any ``gamma_over_alpha >= gamma_over_beta`` keeps the thesis'
        ``alpha <= beta <= gamma``, ``alpha << gamma``.
    parallel_threshold_deg
        ``thr`` of sec. 3.3.2: steps within this angle of the ridge are parallel (Case C).
    bins, sigma
        Colour-histogram resolution and smoothing (derivative scale) of the colour-shade
        descriptor, in bins.
    ridge_detector, creaseness
        Ridge detector of the colour-shade descriptor (:data:`spectrinsic.decompose.methods.ridges.
        RIDGE_DETECTORS`: ``"rad"``, RAD's MLSEC-ST creaseness, thinning and pruning, as the
        thesis cites; ``"hessian"``, the earlier pragmatic detector) and RAD's creaseness
        threshold.
    max_axis_angle
        RAD: crest bins whose local direction is further than this (degrees) from the grey
        diagonal of the log-colour histogram are cut out, so that the ridges of two surfaces
        joined by a crest across the diagonal come out as two (:func:`spectrinsic.decompose.
        ridges.colour_shades`); ``None``: no cut.
    flooding
        RAD's flooding: each colour takes the ridge whose histogram domain (bins flooded from
        the ridges by descending density) holds it, instead of the nearest ridge (Eq. 3.3).
    merge_shading
        Touching regions whose shared boundary is mostly Case C are one region of uniform
        reflectance (:mod:`spectrinsic.decompose.methods.shade_cases`).
    pale_vs_chromatic
        Edges between a white/grey name and a chromatic one are Case A whatever the ridges say
        (:func:`spectrinsic.decompose.methods.shade_cases.split_pale_from_chromatic`).
    sharp_edges
        Sharp, high-contrast edges (1-2 px, one achromatic name step in one pixel) are Case A:
        ``"achromatic"`` those between two achromatic names (default), ``"all"`` every one,
        ``"none"`` none (:mod:`spectrinsic.decompose.methods.sharp_edges`).
    collapse_guard
        A result whose reflectance lost almost all (more than 90 %) of the image's sharp,
        high-contrast steps is re-solved with
        ``sharp_edges="all"``, else replaced by colour Retinex; ``info["collapse"]`` says which
        (:mod:`spectrinsic.decompose.methods.collapse`).
    blurred_steps
        Across sharp, high-contrast steps (:func:`spectrinsic.decompose.methods.sharp_edges.
        sharp_contrast_edges`), where the boundary pixels mix both reflectances, sec. 3.4's
        boundary intensities ``L^orig`` are extrapolated (linearly in log) from the two pixels
        behind each side, which also cancels a shading gradient to first order
        (:func:`spectrinsic.decompose.methods.coherence.global_coherence`).
    fine_detail
        The image's fine detail (log luminance within about 2 pixels) that the regions leave in
        the shading goes back to the reflectance: the shading is replaced by its 2-pixel
        Gaussian average and the reflectance is ``image / shading``; ``info["texture"]`` says
        how much moved (:mod:`spectrinsic.decompose.methods.shading_texture`;
        docs/names-shades-mit.md, round 7).
    global_coherence
        Apply sec. 3.4 (off reproduces Fig. 3.7(c)).
    reflectance_colour
        ``"label-centroid"``: each region takes its label's centre of mass in the RGB cube
        (sec. 3.3.3, as the thesis). ``"region-mean"``: the region's mean image colour
        (default; keeps chromaticities the label palette cannot express).
    split_by_ridge
        Regions are connected areas of equal label *and* equal ridge (default) rather than of
        equal label only.
    name_bits
        Colours are named once per distinct value after rounding the sRGB encoding to
        ``name_bits`` bits (8: the thesis' 8-bit images; 0: every pixel as it is). Speed only.
    expansion_cycles
        Cycles of alpha-expansion over all labels (``-1``: until no expansion lowers the energy,
        as the thesis' graph cuts). Default 2: on a 400x400 Mondrian the reflectance LMSE is the
        same (2e-4) and the MRF takes 2.5 times less.
    colour_constancy
        Global light colour divided out of the reflectance after sec. 3.4
        (:data:`spectrinsic.decompose.methods.constancy.CONSTANCY`; not in the thesis, whose MIT images
        are under near-white light); the shading then carries it.
    """

    mu: float = 1.0 / 3.0
    gamma: float = 3.0
    gamma_over_alpha: float = 100.0
    gamma_over_beta: float = 2.0
    parallel_threshold_deg: float = 30.0
    bins: int = 64
    sigma: float = 2.0
    ridge_detector: str = "rad"
    creaseness: float = 1.5
    max_axis_angle: float | None = 45.0
    flooding: bool = True
    merge_shading: bool = True
    pale_vs_chromatic: bool = True
    sharp_edges: Literal["none", "achromatic", "all"] = "achromatic"
    collapse_guard: bool = True
    blurred_steps: bool = True
    fine_detail: bool = True
    global_coherence: bool = True
    reflectance_colour: Literal["label-centroid", "region-mean"] = "region-mean"
    split_by_ridge: bool = True
    colour_constancy: str = "grey-world"
    name_bits: int = 8
    expansion_cycles: int = 2
    name: str = "names-shades"

    #: How the defaults were chosen (recorded in every evaluation report).
    protocol: ClassVar[str] = PROTOCOL

    @classmethod
    def thesis(cls) -> NamesAndShades:
        """The thesis' own settings (sec. 3.3-3.5): every documented deviation switched off.

        ``mu = 1/3``, ``gamma/alpha = 100``, ``gamma/beta = 2`` (``gamma = 1``: the thesis gives
        only the ratios), label-centroid colours, regions
        of equal label only, no colour constancy, alpha-expansion to convergence, RAD ridges
        (sec. 3.2.2; its creaseness and scale, which the thesis does not give, as the defaults;
        no cut of crests across the grey diagonal), nearest ridges (Eq. 3.3, no flooding) and
        regions of the MRF's labels as they are (no merge across shading boundaries).
        """
        return cls(
            gamma=1.0,
            gamma_over_alpha=100.0,
            gamma_over_beta=2.0,
            mu=1.0 / 3.0,
            reflectance_colour="label-centroid",
            split_by_ridge=False,
            colour_constancy="none",
            expansion_cycles=-1,
            max_axis_angle=None,
            flooding=False,
            merge_shading=False,
            pale_vs_chromatic=False,
            sharp_edges="none",
            collapse_guard=False,
            blurred_steps=False,
            fine_detail=False,
            name="names-shades-thesis",
        )

    def __call__(self, image: npt.ArrayLike, mask: npt.ArrayLike | None = None) -> Decomposition:
        """Decompose a linear ``(H, W, 3)`` image into reflectance and shading.

        The five steps of the module docstring (:meth:`labelling` then :meth:`reflectance`);
        ``info`` records each step's time in seconds, the collapse guard's check and what the
        fine-detail step moved (``info["texture"]``); that step acts last, on whatever the
        collapse guard returns.
        """
        result = self.reflectance(self.labelling(image, mask))
        img, m = prepare_input(image, mask)
        if self.collapse_guard:
            again = replace(self, sharp_edges="all", collapse_guard=False, fine_detail=False)
            fallback = ("colour-retinex", lambda: ColourRetinex()(img, m))
            result = guard_collapse(result, img, m, lambda: again(img, m), fallback)
        return return_fine_detail(result, img, m) if self.fine_detail else result

    def labelling(self, image: npt.ArrayLike, mask: npt.ArrayLike | None = None) -> Labelling:
        """Steps 1-3 (names, shades, MRF) of a linear ``(H, W, 3)`` image (:class:`Labelling`)."""
        validate_choice(
            self.reflectance_colour,
            ("label-centroid", "region-mean"),
            "reflectance_colour",
            error=DecomposeError,
        )
        validate_choice(
            self.ridge_detector, RIDGE_DETECTORS, "ridge_detector", error=DecomposeError
        )
        validate_choice(
            self.sharp_edges, ("none", "achromatic", "all"), "sharp_edges", error=DecomposeError
        )
        gco = _import_gco()
        t0 = time.perf_counter()
        img, m = prepare_input(image, mask)
        scale = float(np.percentile(img[m].max(axis=1), _EXPOSURE_PERCENTILE))
        linear = img / (scale if scale > 0.0 else 1.0)
        pixels = np.clip(linear[m], 0.0, 1.0)

        # 1. colour names -> Appendix A labels observed in the image
        candidates, y, distance = self._names(pixels)
        t1 = time.perf_counter()

        # 2. colour shades on the log image
        log_colours = np.log(np.maximum(pixels, _LOG_FLOOR))
        shades = colour_shades(
            log_colours,
            bins=self.bins,
            sigma=self.sigma,
            detector=self.ridge_detector,
            creaseness=self.creaseness,
            max_axis_angle=self.max_axis_angle,
            flooding=self.flooding,
        )
        t2 = time.perf_counter()

        # 3. MRF (Eq. 3.4) by alpha-expansion
        edges, flat = grid_edges(m)
        cases = edge_cases(
            edges, log_colours, shades.ridge, shades.tangent, self.parallel_threshold_deg
        )
        if self.pale_vs_chromatic:  # a white light keeps a white or grey surface achromatic
            cases = _split_pale(cases, edges, appendix_a_labels()[candidates[y]])
        if self.sharp_edges != "none":  # the Retinex cue where the names are achromatic
            strong = sharp_contrast_edges(log_luminance(img, m), flat, m)
            names = appendix_a_labels()[candidates[y]] if self.sharp_edges == "achromatic" else None
            cases = split_sharp_achromatic(cases, edges, names, strong)
        w = self.gamma / np.array([self.gamma_over_alpha, self.gamma_over_beta, 1.0])
        labels = self._mrf(gco, edges, w[cases], y, distance)
        timings = {"names_s": t1 - t0, "shades_s": t2 - t1, "mrf_s": time.perf_counter() - t2}
        return Labelling(
            img, m, linear, pixels, candidates, y, shades, cases, w[cases], labels, timings
        )

    def reflectance(self, stages: Labelling) -> Decomposition:
        """Steps 4-5 (regions, their colour, global coherence) on a :meth:`labelling`.

        Only the fields acting after the MRF (``reflectance_colour``, ``split_by_ridge``,
        ``global_coherence``, ``blurred_steps``, ``colour_constancy``) are read, so one labelling serves every
        value of them.
        """
        t3 = time.perf_counter()
        m, linear = stages.mask, stages.linear
        regions, colours = self._regions(stages)
        n_regions = int(regions.max())
        if self.global_coherence:
            blurred = None
            if self.blurred_steps:  # read past the optics' mixed pixels at reflectance steps
                blurred = sharp_contrast_edges(log_luminance(stages.image, m), grid_edges(m)[1], m)
            lam = global_coherence(regions, colours.mean(axis=1), linear.mean(axis=2), blurred)
        else:
            lam = np.ones(n_regions + 1)
        reflectance, light = discount_illuminant(
            (lam[:, None] * colours)[regions], linear, m, self.colour_constancy
        )
        timings = {**stages.timings, "coherence_s": time.perf_counter() - t3}
        info = {
            "observed_labels": int(stages.candidates.size),
            "labels": int(np.unique(stages.labels).size),
            "regions": n_regions,
            "ridges": stages.shades.n_ridges,
            "light_colour": light,
            **{k: round(v, 4) for k, v in timings.items()},
        }
        logger.debug("names-shades: %s", info)
        return finish(stages.image, reflectance, m, info)

    def _names(self, pixels: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Step 1: the candidate labels ``(K,)`` (Appendix A indices observed in the image), each
        pixel's observation ``y`` ``(N,)`` as an index into them, and the label-to-label L1
        distance ``(K, K)`` of their membership vectors."""
        observed = observed_labels(_srgb_encode(pixels), self.name_bits)
        candidates, y = np.unique(observed, return_inverse=True)
        vectors = appendix_a_labels()[candidates]
        distance = np.abs(vectors[:, None, :] - vectors[None, :, :]).sum(axis=2)
        return candidates, y, distance

    def _mrf(
        self,
        gco: Any,
        edges: np.ndarray,
        weights: np.ndarray,
        y: np.ndarray,
        distance: np.ndarray,
    ) -> np.ndarray:
        """Step 3: each masked pixel's label ``(N,)`` (an index into the candidates) minimising
        Eq. 3.4 by alpha-expansion; the observations themselves if there is nothing to cut."""
        unary = self.mu * distance[y]
        if distance.shape[0] > 1 and edges.shape[0] > 0:
            return np.asarray(
                gco.cut_general_graph(
                    edges,
                    (1.0 - self.mu) * weights,
                    unary,
                    distance,
                    n_iter=self.expansion_cycles,
                    algorithm="expansion",
                    init_labels=y.astype(np.int32),
                )
            )
        return np.asarray(y)

    def _regions(self, stages: Labelling) -> tuple[np.ndarray, np.ndarray]:
        """Step 4: the region image ``(H, W)`` (0 off the mask, regions 1..R) and each region's
        linear RGB colour ``(R + 1, 3)``, at least 1e-6 (row 0 is unused)."""
        from skimage.measure import label as connected_regions

        m, labels, candidates, pixels = stages.mask, stages.labels, stages.candidates, stages.pixels
        label_image = np.zeros(m.shape, dtype=np.int64)
        label_image[m] = labels + 1
        if self.split_by_ridge:
            label_image[m] += (candidates.size + 1) * stages.shades.ridge
        regions = connected_regions(label_image, background=0, connectivity=1)
        if self.merge_shading:
            regions = merge_shading_boundaries(regions, grid_edges(m)[1], stages.cases == CASE_C)
        n_regions = int(regions.max())
        region_of_pixel = regions[m]
        counts = np.bincount(region_of_pixel, minlength=n_regions + 1).astype(np.float64)
        mean_colour = (
            np.stack(
                [
                    np.bincount(region_of_pixel, weights=pixels[:, c], minlength=n_regions + 1)
                    for c in range(3)
                ],
                axis=1,
            )
            / np.maximum(counts, 1.0)[:, None]
        )
        region_label = np.zeros(n_regions + 1, dtype=np.int64)
        region_label[region_of_pixel] = candidates[labels]
        if self.reflectance_colour == "label-centroid":
            colours = _srgb_decode(np.nan_to_num(label_centroids()[region_label], nan=-1.0))
            missing = ~np.isfinite(label_centroids()[region_label][:, 0])
            colours[missing] = mean_colour[missing]  # labels the cube sampling never reached
        else:
            colours = mean_colour
        return regions, np.maximum(colours, 1e-6)
