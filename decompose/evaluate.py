"""Evaluation of the bundled decomposers on rendered samples (thesis Tables 5.1, 5.3, 5.4).

Input: any iterable of sample dicts as :func:`spectrinsic.gt_export.load_sample` returns them
(``image``, ``reflectance``, ``shading``, ``mask``, ``ids``, ``meta``, optional
``image_camera/<name>`` and ``meta["matrices"]``). For each sample and method:

* scenario ``"srgb"``: the linear sRGB rendering is decomposed; reflectance is scored in colour
  against the absolute reflectance, shading in grey (mean over channels) against the grey
  shading, as sec. 5.2.5 does ("the shading evaluation ... discards color information");
* scenarios ``SC1``, ``SC3b``, ``SC4`` per camera (sec. 5.1.3): the camera rendering, corrected
  by :func:`spectrinsic.decompose.photometric.photometric_correction`, is decomposed and its
  reflectance scored against the absolute reflectance.

Outputs in ``out_dir``: ``scores.csv`` (sample, method, scenario, layer, metric, value), the
condition table (``lmse_by_condition.{csv,md}``, like Tables 5.3/5.4), the scenario table
(``lmse_by_scenario.{csv,md}``, like Table 5.1), ``figures/<sample>.png`` and
``estimates/<method>/<scenario>/<sample>/{reflectance,shading}.exr``.
"""

from __future__ import annotations

import csv
import logging
import re
from collections import defaultdict
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from spectrinsic.decompose.decomposition import Decomposer, Decomposition
from spectrinsic.decompose.judgements import sample_judgements
from spectrinsic.decompose.metrics import METRICS, WHDR_DELTA, get_metric, whdr
from spectrinsic.decompose.photometric import photometric_correction
from spectrinsic.decompose.registry import DECOMPOSERS, get_decomposer
from spectrinsic.errors import DatasetError
from spectrinsic.rng import seed_from_key

__all__ = [
    "CONDITION_GROUPS",
    "Score",
    "EvaluationResult",
    "sample_condition",
    "sample_kind",
    "evaluate_sample",
    "evaluation_mask",
    "BACKGROUND_OBJECTS",
    "evaluate",
    "condition_table",
    "scenario_table",
]

logger = logging.getLogger(__name__)

#: Lighting conditions of the dataset and the column of Tables 5.3/5.4 each belongs to.
CONDITION_GROUPS: dict[str, str] = {
    "white": "WL",
    "one-colour": "1L",
    "two-colour-a": "2L",
    "two-colour-b": "2L",
}
_GROUP_ORDER = ("WL", "1L", "2L")
_KINDS = {"object": "single objects", "complex": "complex scenes"}
#: Metrics of the grey shading layer (angular error needs colour).
_SHADING_METRICS = ("si_mse", "lmse", "almse", "corr", "lcorr", "dssim")
_PHOTOMETRIC = ("SC1", "SC3b", "SC4")


@dataclass(frozen=True)
class Score:
    """One number of ``scores.csv``; ``camera`` and ``photometric`` only for camera scenarios."""

    sample: str
    method: str
    scenario: str
    layer: str
    metric: str
    value: float
    camera: str = ""
    photometric: str = ""


@dataclass(frozen=True)
class EvaluationResult:
    """Scores and the files written."""

    scores: tuple[Score, ...]
    files: dict[str, Path] = field(default_factory=dict)


def _sample_id(sample: Mapping[str, Any]) -> str:
    meta = sample.get("meta", {})
    sid = meta.get("sample_id") or sample.get("sample_id")
    if not sid:
        raise DatasetError("sample has no meta['sample_id']")
    return str(sid)


def sample_condition(sample: Mapping[str, Any]) -> str:
    """Lighting condition: ``meta["condition"]``, else the last ``__`` field of the sample id."""
    meta = sample.get("meta", {})
    cond = meta.get("condition") or meta.get("scene_metadata", {}).get("condition")
    if not cond:
        cond = _sample_id(sample).rsplit("__", 1)[-1]
    if cond not in CONDITION_GROUPS:
        raise DatasetError(
            f"sample {_sample_id(sample)!r}: unknown condition {cond!r}; "
            f"expected one of {sorted(CONDITION_GROUPS)}"
        )
    return str(cond)


def sample_kind(sample: Mapping[str, Any]) -> str:
    """``"object"`` or ``"complex"``: ``meta["scene_kind"]``, else the ``obj-`` id prefix."""
    meta = sample.get("meta", {})
    kind = meta.get("scene_kind") or meta.get("scene_metadata", {}).get("kind")
    if not kind:
        kind = "object" if _sample_id(sample).startswith("obj") else "complex"
    if kind not in _KINDS:
        raise DatasetError(f"sample {_sample_id(sample)!r}: unknown scene kind {kind!r}")
    return str(kind)


def _slug(text: str) -> str:
    return re.sub(r"[^a-z0-9]+", "-", text.lower()).strip("-") or "camera"


def _grey(a: np.ndarray) -> np.ndarray:
    a = np.asarray(a, dtype=np.float64)
    return a.mean(axis=2) if a.ndim == 3 else a


#: Object names excluded from the evaluation mask of single-object scenes: like the MIT
#: benchmark (Grosse et al. 2009), an object is scored on its own mask, not on the ground.
BACKGROUND_OBJECTS = frozenset({"ground"})


def evaluation_mask(sample: Mapping[str, Any]) -> np.ndarray:
    """Pixels scored: the ``mask``, minus background objects in single-object scenes."""
    image = np.asarray(sample["image"])
    mask = np.asarray(sample.get("mask", np.ones(image.shape[:2], bool)), dtype=bool)
    if sample_kind(sample) != "object":
        return mask
    objects = sample.get("meta", {}).get("objects") or {}
    ids = sample.get("ids")
    object_ids = ids.get("object") if isinstance(ids, Mapping) else None
    background = [int(k) for k, name in objects.items() if name in BACKGROUND_OBJECTS]
    if object_ids is None or not background:
        return mask
    return mask & ~np.isin(np.asarray(object_ids), background)


def _material_ids(sample: Mapping[str, Any]) -> np.ndarray | None:
    ids = sample.get("ids")
    if isinstance(ids, Mapping):
        ids = ids.get("material", ids.get("material_id"))
    return None if ids is None else np.asarray(ids)


def _camera_inputs(sample: Mapping[str, Any]) -> list[tuple[str, str, np.ndarray]]:
    """``(camera, scenario, corrected image)`` for every camera image and feasible scenario."""
    matrices = sample.get("meta", {}).get("matrices") or {}
    s_sen = matrices.get("S_Sen", {})
    l_clig = matrices.get("L_CLig", {})
    out = []
    for key in sorted(k for k in sample if k.startswith("image_camera/")):
        camera = key.split("/", 1)[1]
        image = np.asarray(sample[key], dtype=np.float64)
        light_cam = (l_clig.get(camera) or {}).get("scene")
        light_srgb = (l_clig.get("srgb") or {}).get("scene")
        available = {
            "SC1": light_cam is not None and camera in s_sen,
            "SC3b": light_srgb is not None,
            "SC4": True,
        }
        for scenario in _PHOTOMETRIC:
            if not available[scenario]:
                logger.info("sample %s, camera %s: no matrices for %s", _sample_id(sample),
                            camera, scenario)
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
    from spectrinsic.gt_export.exr import write_exr

    directory.mkdir(parents=True, exist_ok=True)
    write_exr(directory / "reflectance.exr", {"reflectance": result.reflectance})
    write_exr(directory / "shading.exr", {"shading": result.shading})


def evaluate_sample(
    sample: Mapping[str, Any],
    methods: Mapping[str, Decomposer],
    *,
    seed: int,
    metrics: Sequence[str] | None = None,
    n_judgements: int = 1000,
    out_dir: str | Path | None = None,
    cameras: bool = True,
    figure: bool = True,
) -> list[Score]:
    """Decompose one sample with every method and score the estimates.

    Parameters
    ----------
    sample
        A loader dict (module docstring).
    methods
        ``{name: decomposer}``.
    seed
        Root seed of the WHDR judgements (per sample: ``seed_from_key(seed, sample_id)``).
    metrics
        Reflectance metrics (registry names; default all); ``"whdr"`` is always added.
    out_dir
        Where estimates and the figure go (nothing is written when None).
    cameras
        Also run the photometric scenarios on the camera renderings.
    """
    sid = _sample_id(sample)
    image = np.asarray(sample["image"], dtype=np.float64)
    reflectance = np.asarray(sample["reflectance"], dtype=np.float64)
    shading = sample.get("shading_grey")
    shading = _grey(sample["shading"] if shading is None else shading)
    mask = evaluation_mask(sample)
    names = list(METRICS) if metrics is None else list(metrics)
    judgements = sample_judgements(
        reflectance, seed=seed_from_key(seed, sid), n_pairs=n_judgements, mask=mask,
        material_ids=_material_ids(sample), delta=WHDR_DELTA,
    )
    inputs: list[tuple[str, str, str, np.ndarray]] = [("srgb", "", "", image)]
    if cameras:
        inputs += [(f"{sc}_{_slug(cam)}", cam, sc, img) for cam, sc, img in _camera_inputs(sample)]
    scores: list[Score] = []
    figure_rows: list[tuple[str, Decomposition]] = []
    for method, decomposer in methods.items():
        for scenario, camera, photometric, img in inputs:
            result = decomposer(img, mask)
            extra = {"camera": camera, "photometric": photometric}
            for metric, value in _layer_scores(reflectance, result.reflectance, mask, names).items():
                scores.append(Score(sid, method, scenario, "reflectance", metric, value, **extra))
            scores.append(Score(sid, method, scenario, "reflectance", "whdr",
                                whdr(result.reflectance, judgements), **extra))
            if scenario == "srgb":
                est = _grey(result.shading)
                for metric, value in _layer_scores(shading, est, mask, _SHADING_METRICS).items():
                    scores.append(Score(sid, method, scenario, "shading", metric, value))
                figure_rows.append((method, result))
            if out_dir is not None:
                _write_estimate(Path(out_dir) / "estimates" / method / scenario / sid, result)
    if out_dir is not None and figure:
        _figure(Path(out_dir) / "figures" / f"{sid}.png", sid, image, reflectance,
                np.asarray(sample["shading"]), figure_rows)
    return scores


def _display(a: np.ndarray) -> np.ndarray:
    """Tone-map a linear image for display: 99th percentile to 1, sRGB encoding."""
    a = np.asarray(a, dtype=np.float64)
    if a.ndim == 2:
        a = np.repeat(a[:, :, None], 3, axis=2)
    top = np.percentile(a, 99.0)
    a = np.clip(a / (top if top > 0 else 1.0), 0.0, 1.0)
    return np.where(a <= 0.0031308, 12.92 * a, 1.055 * a ** (1 / 2.4) - 0.055)


def _figure(path: Path, sid: str, image, reflectance, shading, rows) -> None:
    from matplotlib.figure import Figure  # no pyplot: no global backend state

    panels = [("ground truth", image, reflectance, shading)]
    panels += [(m, None, r.reflectance, r.shading) for m, r in rows]
    fig = Figure(figsize=(7.5, 2.4 * len(panels)))
    axes = fig.subplots(len(panels), 3, squeeze=False)
    for row, (label, img, refl, shad) in enumerate(panels):
        for col, (title, data) in enumerate((("input", img), ("reflectance", refl),
                                             ("shading", shad))):
            ax = axes[row, col]
            ax.set_axis_off()
            if data is not None:
                ax.imshow(_display(data), interpolation="nearest")
                ax.set_title(f"{label}: {title}" if col else f"{title}", fontsize=8)
            elif col == 0:
                ax.text(0.5, 0.5, label, ha="center", va="center", fontsize=10)
    fig.suptitle(sid, fontsize=9)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=80)


def _mean(values: list[float]) -> float:
    finite = [v for v in values if np.isfinite(v)]
    return float(np.mean(finite)) if finite else float("nan")


def condition_table(
    scores: Iterable[Score], kinds: Mapping[str, str], conditions: Mapping[str, str],
    *, metric: str = "lmse",
) -> list[dict[str, Any]]:
    """Rows like Tables 5.3/5.4: mean *metric* per method, scene kind, layer and WL/1L/2L.

    ``kinds`` and ``conditions`` map sample ids to ``"object"/"complex"`` and a condition.
    """
    groups: dict[tuple[str, str, str, str], list[float]] = defaultdict(list)
    for s in scores:
        if s.scenario == "srgb" and s.metric == metric:
            group = CONDITION_GROUPS[conditions[s.sample]]
            groups[(kinds[s.sample], s.method, s.layer, group)].append(s.value)
    rows = []
    for kind in _KINDS:
        methods = sorted({k[1] for k in groups if k[0] == kind}, key=_method_order)
        for method in methods:
            row: dict[str, Any] = {"scene_kind": kind, "method": method}
            for layer in ("reflectance", "shading"):
                for g in _GROUP_ORDER:
                    vals = groups.get((kind, method, layer, g), [])
                    row[f"{layer}_{g}"] = _mean(vals)
            rows.append(row)
    return rows


def scenario_table(scores: Iterable[Score], *, metric: str = "lmse") -> list[dict[str, Any]]:
    """Rows like Table 5.1: mean reflectance *metric* per method, camera and SC1/SC3b/SC4."""
    groups: dict[tuple[str, str, str], list[float]] = defaultdict(list)
    for s in scores:
        if s.camera and s.layer == "reflectance" and s.metric == metric:
            groups[(s.camera, s.method, s.photometric)].append(s.value)
    rows = []
    for camera in sorted({k[0] for k in groups}):
        for method in sorted({k[1] for k in groups if k[0] == camera}, key=_method_order):
            row: dict[str, Any] = {"camera": camera, "method": method}
            for sc in _PHOTOMETRIC:
                row[sc] = _mean(groups.get((camera, method, sc), []))
            rows.append(row)
    return rows


def _method_order(name: str) -> tuple[int, str]:
    order = list(DECOMPOSERS)
    return (order.index(name) if name in order else len(order), name)


def _write_csv(path: Path, rows: list[dict[str, Any]], columns: Sequence[str]) -> None:
    with path.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(columns))
        writer.writeheader()
        for row in rows:
            writer.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in row.items()})


def _markdown(rows: list[dict[str, Any]], columns: Sequence[str], headers: Sequence[str]) -> str:
    def fmt(v: Any) -> str:
        return ("—" if not np.isfinite(v) else f"{v:.3f}") if isinstance(v, float) else str(v)

    lines = ["| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
    lines += ["| " + " | ".join(fmt(r[c]) for c in columns) + " |" for r in rows]
    return "\n".join(lines)


def evaluate(
    samples: Iterable[Mapping[str, Any]],
    out_dir: str | Path,
    *,
    methods: Sequence[str] | Mapping[str, Decomposer] | None = None,
    seed: int = 0,
    metrics: Sequence[str] | None = None,
    n_judgements: int = 1000,
    cameras: bool = True,
    figures: bool = True,
    save_estimates: bool = True,
    progress: Callable[[str], None] | None = None,
) -> EvaluationResult:
    """Evaluate decomposers on *samples* and write scores, tables, figures and estimates.

    Parameters
    ----------
    samples
        Loader dicts (e.g. :func:`spectrinsic.gt_export.load_dataset`).
    out_dir
        Output folder (created).
    methods
        Registry names or ``{name: decomposer}``; default every registered decomposer.
    seed
        Root seed of the WHDR judgements.
    progress
        Called with each sample id once it is done (the CLI passes a tqdm update).
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    if methods is None:
        methods = list(DECOMPOSERS)
    if not isinstance(methods, Mapping):
        methods = {name: get_decomposer(name) for name in methods}
    scores: list[Score] = []
    kinds: dict[str, str] = {}
    conditions: dict[str, str] = {}
    for sample in samples:
        sid = _sample_id(sample)
        kinds[sid], conditions[sid] = sample_kind(sample), sample_condition(sample)
        scores += evaluate_sample(
            sample, methods, seed=seed, metrics=metrics, n_judgements=n_judgements,
            out_dir=out if (save_estimates or figures) else None, cameras=cameras,
            figure=figures,
        )
        if progress is not None:
            progress(sid)
    if not scores:
        raise DatasetError("no samples to evaluate")
    files: dict[str, Path] = {}
    files["scores"] = out / "scores.csv"
    _write_csv(files["scores"], [
        {"sample": s.sample, "method": s.method, "scenario": s.scenario, "layer": s.layer,
         "metric": s.metric, "value": s.value} for s in scores
    ], ("sample", "method", "scenario", "layer", "metric", "value"))

    cond_rows = condition_table(scores, kinds, conditions)
    cond_cols = ["scene_kind", "method"] + [
        f"{layer}_{g}" for layer in ("reflectance", "shading") for g in _GROUP_ORDER
    ]
    files["condition_csv"] = out / "lmse_by_condition.csv"
    _write_csv(files["condition_csv"], cond_rows, cond_cols)
    md = ["# LMSE by lighting condition (like thesis Tables 5.3 and 5.4)", "",
          "Reflectance in colour, shading in grey; 20x20 windows every 10 px, one scale per "
          "window; mean over samples.", ""]
    for kind, title in _KINDS.items():
        rows = [r for r in cond_rows if r["scene_kind"] == kind]
        if rows:
            md += [f"## {title.capitalize()}", "", _markdown(
                rows, cond_cols[1:],
                ["method"] + [f"{lay[:4]}. {g}" for lay in ("reflectance", "shading")
                              for g in _GROUP_ORDER],
            ), ""]
    files["condition_md"] = out / "lmse_by_condition.md"
    files["condition_md"].write_text("\n".join(md), encoding="utf-8")

    scen_rows = scenario_table(scores)
    scen_cols = ["camera", "method", *_PHOTOMETRIC]
    files["scenario_csv"] = out / "lmse_by_scenario.csv"
    _write_csv(files["scenario_csv"], scen_rows, scen_cols)
    md = ["# Reflectance LMSE by photometric scenario (like thesis Table 5.1)", ""]
    md += [_markdown(scen_rows, scen_cols, scen_cols) if scen_rows
           else "No camera renderings in this dataset: Table 5.1 needs `image_camera/<name>`."]
    files["scenario_md"] = out / "lmse_by_scenario.md"
    files["scenario_md"].write_text("\n".join(md) + "\n", encoding="utf-8")
    return EvaluationResult(tuple(scores), files)
