"""Evaluation of decomposers on rendered samples (thesis Tables 5.1, 5.3, 5.4).

Input: any iterable of sample dicts as :func:`spectrinsic.gt_export.load_sample` returns them,
scored in their linear sRGB view whatever the set's working space
(:func:`spectrinsic.gt_export.sample.working_view.srgb_view`; ACEScg samples are converted, so
decomposers see sRGB images and metrics compare in sRGB) (``image`` / ``image_denoised``, ``reflectance``, ``shading``, ``shading_grey``, ``mask``,
``ids``, ``meta``, optional ``image_camera/<name>`` and ``meta["matrices"]``). Methods are
registered decomposers (plugins included) or :class:`~spectrinsic.decompose.evaluation.predictions.
Predictions`, a user's estimates read from files. For each sample and method:

* scenario ``"srgb"``: the linear sRGB image (:data:`INPUT_LAYERS`: ``image_denoised`` when
  present) is decomposed; reflectance is scored in colour against the absolute reflectance;
  shading twice (:data:`SCORED_LAYERS`): in grey against ``shading_grey``, as sec. 5.2.5 does
  ("the shading evaluation ... discards color information"), and in colour against the
  coloured ``shading`` (LMSE and the shading chromaticity error);
* scenarios ``SC1``, ``SC3b``, ``SC4`` per camera (sec. 5.1.3): the camera rendering, corrected
  by :func:`spectrinsic.decompose.evaluation.photometric.photometric_correction`, is decomposed and its
  reflectance scored against the absolute reflectance;
* scenario ``sensor_<camera>`` (``dataset --camera``; :mod:`~spectrinsic.decompose.evaluation.processed`):
  the camera chain's processed image, scored against the ground truth carried through it.

Outputs in ``out_dir`` (:func:`evaluate` writes the figures and estimates; the CLI then
passes its :class:`EvaluationResult` to :func:`spectrinsic.decompose.report.write_report`,
which writes the rest): ``scores.csv``
(sample, method, scenario, layer, metric, value, lighting group, dataset config hash), the condition tables like Tables 5.3/5.4,
the scenario table like Table 5.1, ``summary.png`` (method x condition), ``REPORT.md`` (every
table's numbers inline, abbreviations, the summary figure, methods and their parameters),
``figures/<sample>.png`` and ``estimates/<method>/<scenario>/<sample>/{reflectance,shading}.exr``
(the predictions layout, so an estimates folder can be scored again with ``--predictions``).
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import DatasetError, validate_choice
from ...gt_export.formats.exr import write_exr
from ...gt_export.formats.names import camera_slug
from ...gt_export.sample.working_view import srgb_view
from ...rng import seed_from_key
from ..decomposition import Decomposer, Decomposition
from ..methods.registry import available_decomposers, get_decomposer
from ..metrics import METRICS, WHDR_DELTA, get_metric, whdr
from ..metrics.judgements import Judgements, sample_judgements
from .photometric import SCENARIOS, photometric_correction
from .predictions import Predictions
from .processed import processed_inputs
from .sample_fields import (
    evaluation_mask,
    input_image,
    material_ids,
    sample_condition,
    sample_id_of,
    sample_kind,
)
from .sample_figure import sample_figure
from .scores import CONDITION_GROUPS, INPUT_LAYERS, SCORED_LAYERS, Score
from .targets import SPECULAR_LAYER, SPECULAR_METRICS, TARGETS, target_image, target_note

__all__ = [
    "CONDITION_GROUPS",
    "Score",
    "EvaluationResult",
    "evaluate_sample",
    "INPUT_LAYERS",
    "SCORED_LAYERS",
    "layer_metrics",
    "evaluate",
]

logger = logging.getLogger(__name__)

_GROUP_ORDER = ("WL", "1L", "2L")
#: Metrics of the grey shading layer (angular error needs colour).
_SHADING_GREY_METRICS = ("si_mse", "lmse", "almse", "corr", "lcorr", "dssim")
#: Metrics of the coloured shading layer.
_SHADING_COLOUR_METRICS = ("si_mse", "lmse", "shading_chromaticity")
#: Metrics of the grey reflectance (Table 3.2's four).
_REFLECTANCE_GREY_METRICS = ("si_mse", "lmse", "almse", "corr")
_PHOTOMETRIC = tuple(SCENARIOS)


@dataclass(frozen=True)
class EvaluationResult:
    """The scores of a run and what its report
    (:func:`spectrinsic.decompose.report.write_report`, called by the CLI) says of it.

    Attributes
    ----------
    scores
        Every score, in the order they were computed.
    samples
        sample id -> ``(kind, lighting condition)``.
    methods
        The decomposers (or predictions) scored, by name; their parameters go in ``methods.json``.
    inputs
        The image layers the methods decomposed (:data:`INPUT_LAYERS`), sorted.
    note
        The evaluation target's note (:func:`~spectrinsic.decompose.evaluation.targets.target_note`).
    config_hashes
        sample id -> its dataset's config hash (for ``scores.csv``).
    """

    scores: tuple[Score, ...]
    samples: Mapping[str, tuple[str, str]]
    methods: Mapping[str, Decomposer | Predictions]
    inputs: tuple[str, ...]
    note: str = ""
    config_hashes: Mapping[str, str] = field(default_factory=dict)


def _grey(a: np.ndarray) -> np.ndarray:
    a = np.asarray(a, dtype=np.float64)
    return a.mean(axis=2) if a.ndim == 3 else a


def _camera_inputs(sample: Mapping[str, Any], target: str) -> list[tuple[str, str, np.ndarray]]:
    """``(camera, scenario, corrected image)`` for every camera image and feasible scenario."""
    matrices = sample.get("meta", {}).get("matrices") or {}
    s_sen = matrices.get("S_Sen", {})
    l_clig = matrices.get("L_CLig", {})
    out = []
    for key in sorted(k for k in sample if k.startswith("image_camera/")):
        camera = key.split("/", 1)[1]
        image = target_image(sample, input_image(sample, camera)[1], target, camera)
        light_cam = (l_clig.get(camera) or {}).get("scene")
        light_srgb = (l_clig.get("srgb") or {}).get("scene")
        available = {
            "SC1": light_cam is not None and camera in s_sen,
            "SC3b": light_srgb is not None,
            "SC4": True,
        }
        for scenario in _PHOTOMETRIC:
            if not available[scenario]:
                logger.info(
                    "sample %s, camera %s: no matrices for %s",
                    sample_id_of(sample),
                    camera,
                    scenario,
                )
                continue
            light = light_cam if scenario == "SC1" else light_srgb
            corrected = photometric_correction(
                image, scenario, L_CLig=light, S_Sen=s_sen.get(camera)
            )
            out.append((camera, scenario, corrected))
    return out


def _layer_scores(
    truth: np.ndarray, estimate: np.ndarray, mask: np.ndarray, names: Sequence[str]
) -> dict[str, float]:
    scores = {}
    for name in names:
        try:
            scores[name] = get_metric(name).func(truth, estimate, mask=mask)
        except ValueError as exc:  # undefined for this image (e.g. constant ground truth)
            logger.warning("metric %s undefined: %s", name, exc)
            scores[name] = float("nan")
    return scores


def _write_estimate(directory: Path, result: Decomposition) -> None:
    directory.mkdir(parents=True, exist_ok=True)
    write_exr(directory / "reflectance.exr", {"reflectance": result.reflectance})
    write_exr(directory / "shading.exr", {"shading": result.shading})
    if result.specular is not None:
        write_exr(directory / "specular.exr", {"specular": result.specular})


def layer_metrics(layer: str, metrics: Sequence[str] | None = None) -> list[str]:
    """Registered metrics the evaluation applies to *layer* (:data:`SCORED_LAYERS`).

    *metrics* restricts the reflectance metrics (default: every metric registered for it).
    """
    if layer == "reflectance" and metrics is not None:
        return [get_metric(n).name for n in metrics]
    defaults = {
        "shading_grey": _SHADING_GREY_METRICS,
        "shading": _SHADING_COLOUR_METRICS,
        "reflectance_grey": _REFLECTANCE_GREY_METRICS,
        SPECULAR_LAYER: SPECULAR_METRICS,
    }
    if layer in defaults:
        return list(defaults[layer])
    return [n for n, m in METRICS.items() if layer in m.layers]


def _estimate(
    method: Decomposer | Predictions,
    sid: str,
    scenario: str,
    image: np.ndarray,
    mask: np.ndarray,
    target: str,
) -> Decomposition | None:
    if isinstance(method, Predictions):  # a predicted specular is in the full image only
        return method.load(sid, scenario, image, mask, subtract_specular=target == "full")
    return method(image, mask)


@dataclass(frozen=True)
class _Truth:
    """Ground truth of one sample as the scoring needs it."""

    sid: str
    mask: np.ndarray
    layers: dict[str, np.ndarray]
    judgements: Judgements


def _truth(sample: Mapping[str, Any], seed: int, n_judgements: int) -> _Truth:
    sid = sample_id_of(sample)
    reflectance = np.asarray(sample["reflectance"], dtype=np.float64)
    colour = np.asarray(sample["shading"], dtype=np.float64)
    grey = sample.get("shading_grey")
    mask = evaluation_mask(sample)
    judgements = sample_judgements(
        reflectance,
        seed=seed_from_key(seed, sid),
        n_pairs=n_judgements,
        mask=mask,
        material_ids=material_ids(sample),
        delta=WHDR_DELTA,
    )
    layers = {
        "reflectance": reflectance,
        "shading": colour,
        "shading_grey": _grey(colour if grey is None else grey),
        "reflectance_grey": _grey(reflectance),
    }
    if SPECULAR_LAYER in sample:
        layers[SPECULAR_LAYER] = np.asarray(sample[SPECULAR_LAYER], dtype=np.float64)
    return _Truth(sid, mask, layers, judgements)


def _score(
    truth: _Truth,
    result: Decomposition,
    method: str,
    scenario: str,
    names: Sequence[str],
    camera: str = "",
    photometric: str = "",
) -> list[Score]:
    """Scores of one estimate: reflectance always, shading (grey and colour) for sRGB input and
    a camera's processed image (:mod:`~spectrinsic.decompose.evaluation.processed`)."""
    extra = {"camera": camera, "photometric": photometric}
    estimates = {"reflectance": result.reflectance}
    if scenario == "srgb" or scenario.startswith("sensor_"):
        estimates.update(
            shading=result.shading,
            shading_grey=_grey(result.shading),
            reflectance_grey=_grey(result.reflectance),
        )
        if result.specular is not None and SPECULAR_LAYER in truth.layers:
            estimates[SPECULAR_LAYER] = result.specular
    out = []
    for layer, est in estimates.items():
        which = names if layer == "reflectance" else layer_metrics(layer)
        for metric, value in _layer_scores(truth.layers[layer], est, truth.mask, which).items():
            out.append(Score(truth.sid, method, scenario, layer, metric, value, **extra))
    out.append(
        Score(
            truth.sid,
            method,
            scenario,
            "reflectance",
            "whdr",
            whdr(result.reflectance, truth.judgements),
            **extra,
        )
    )
    return out


def evaluate_sample(
    sample: Mapping[str, Any],
    methods: Mapping[str, Decomposer | Predictions],
    *,
    seed: int,
    metrics: Sequence[str] | None = None,
    n_judgements: int = 1000,
    out_dir: str | Path | None = None,
    cameras: bool = True,
    figure: bool = True,
    save_estimates: bool = True,
    target: str = "full",
) -> list[Score]:
    """Decompose one sample with every method (or read its predictions) and score the estimates.

    Parameters
    ----------
    sample
        A loader dict (module docstring).
    methods
        ``{name: decomposer or Predictions}``.
    seed
        Root seed of the WHDR judgements (per sample: ``seed_from_key(seed, sample_id)``).
    metrics
        Reflectance metrics (registry names; default all registered for reflectance);
        ``"whdr"`` is always added. Shading metrics: :func:`layer_metrics`.
    out_dir
        Where estimates and the figure go (nothing is written when None).
    cameras
        Also run the photometric scenarios on the camera renderings.
    figure, save_estimates
        Draw the figure, write the estimates (of decomposers; predictions are files already).
    target
        ``"full"`` or ``"diffuse"``: the image decomposed (:mod:`spectrinsic.decompose.evaluation.targets`).
    """
    truth = _truth(sample, seed, n_judgements)
    names = layer_metrics("reflectance", metrics)
    image = target_image(sample, input_image(sample)[1], target)
    inputs: list[tuple[str, str, str, np.ndarray]] = [("srgb", "", "", image)]
    if cameras:
        inputs += [
            (f"{sc}_{camera_slug(cam)}", cam, sc, img)
            for cam, sc, img in _camera_inputs(sample, target)
        ]
    truths = {s: replace(truth, layers=gt) for s, _, gt in processed_inputs(sample, target)}
    inputs += [(s, "", "", img) for s, img, _ in processed_inputs(sample, target) if cameras]
    scores: list[Score] = []
    figure_rows: list[tuple[str, Decomposition]] = []
    for method, decomposer in methods.items():
        for scenario, camera, photometric, img in inputs:
            result = _estimate(decomposer, truth.sid, scenario, img, truth.mask, target)
            if result is None:
                continue
            scored = truths.get(scenario, truth)  # a processed image: its carried ground truth
            scores += _score(scored, result, method, scenario, names, camera, photometric)
            if scenario == "srgb":
                figure_rows.append((method, result))
            if save_estimates and out_dir is not None and not isinstance(decomposer, Predictions):
                _write_estimate(Path(out_dir) / "estimates" / method / scenario / truth.sid, result)
    if out_dir is not None and figure:
        sample_figure(
            Path(out_dir) / "figures" / f"{truth.sid}.png",
            truth.sid,
            inputs[0][3],
            truth.layers["reflectance"],
            truth.layers["shading"],
            figure_rows,
        )
    return scores


def evaluate(
    samples: Iterable[Mapping[str, Any]],
    out_dir: str | Path,
    *,
    methods: Sequence[str] | Mapping[str, Decomposer | Predictions] | None = None,
    seed: int = 0,
    metrics: Sequence[str] | None = None,
    n_judgements: int = 1000,
    cameras: bool = True,
    figures: bool = True,
    save_estimates: bool = True,
    progress: Callable[[str], None] | None = None,
    target: str = "full",
) -> EvaluationResult:
    """Evaluate decomposers (or predictions) on *samples*: the scores, with the figures and
    estimates written as they are made; the tables and ``REPORT.md`` are
    :func:`spectrinsic.decompose.report.write_report`'s, from the record returned.

    Parameters
    ----------
    samples
        Loader dicts (e.g. :func:`spectrinsic.gt_export.load_dataset`).
    out_dir
        Output folder (created).
    methods
        Registry names or ``{name: decomposer or Predictions}``; default every registered
        decomposer, plugins included (:func:`spectrinsic.decompose.methods.registry.available_decomposers`).
    seed
        Root seed of the WHDR judgements.
    progress
        Called with each sample id once it is done (the CLI passes a tqdm update).
    target
        ``"full"`` (default) or ``"diffuse"``: the image methods decompose, named in the
        tables and ``REPORT.md`` (:mod:`spectrinsic.decompose.evaluation.targets`).
    """
    validate_choice(target, TARGETS, "evaluation target", error=DatasetError)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    if methods is None:
        methods = list(available_decomposers())
    if not isinstance(methods, Mapping):
        methods = {name: get_decomposer(name) for name in methods}
    scores: list[Score] = []
    samples_info: dict[str, tuple[str, str]] = {}
    hashes: dict[str, str] = {}  # each sample's dataset config hash, for scores.csv
    inputs: set[str] = set()
    glossy = False
    for stored in samples:
        sample = srgb_view(stored, stored.get("meta"))  # scored in linear sRGB, any working space
        glossy = glossy or SPECULAR_LAYER in sample
        sid = sample_id_of(sample)
        samples_info[sid] = (sample_kind(sample), sample_condition(sample))
        hashes[sid] = str((sample.get("meta") or {}).get("config_hash") or "")
        inputs.add(input_image(sample)[0])
        scores += evaluate_sample(
            sample,
            methods,
            seed=seed,
            metrics=metrics,
            n_judgements=n_judgements,
            out_dir=out,
            cameras=cameras,
            figure=figures,
            save_estimates=save_estimates,
            target=target,
        )
        if progress is not None:
            progress(sid)
    if not scores:
        raise DatasetError("no samples to evaluate")
    note = target_note(target, glossy)
    return EvaluationResult(
        tuple(scores), samples_info, methods, tuple(sorted(inputs)), note, hashes
    )
