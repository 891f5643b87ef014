"""Numbers of the rendering study: render one sample, its per-pixel errors, rows and summary.

Per pixel the error is Eq. 5.7 on CIE XYZ, :func:`spectrinsic.spectra.relative_error`; the
study evaluates it on the pixels :func:`valid_pixels` selects. Nothing here writes files or
text: :mod:`.report` and :mod:`.plot` do.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import SceneError, StudyError, validate_choice
from ...render import render_scene
from ...render.settings import RenderSettings
from ...rng import seed_from_key
from ...scenes import library
from ...scenes.library import CONDITIONS
from ...scenes.sample_id import SampleId
from ...spectra import relative_error

__all__ = [
    "QUALITIES",
    "StudyQuality",
    "REFERENCE_MODE",
    "COMPARED_MODES",
    "STUDY_CONDITIONS",
    "DARK_FRACTION",
    "MAX_DEPTH",
    "DEFAULT_SEED",
    "THESIS_MEAN_R",
    "SampleResult",
    "study_quality",
    "samples",
    "valid_pixels",
    "error_stats",
    "evaluate_sample",
    "summary",
]

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class StudyQuality:
    """Image size (pixels) and samples per pixel of a study render."""

    width: int
    height: int
    spp: int

    def render_settings(self, variant: str | None = None) -> RenderSettings:
        """One batch of :attr:`spp` samples of the compared modes and the reference, path depth
        :data:`MAX_DEPTH`, the reference also direct-only (for r of Eq. 5.8), with AOVs."""
        return RenderSettings(
            self.spp,
            modes=(*COMPARED_MODES, REFERENCE_MODE),
            max_depth=MAX_DEPTH,
            variant=variant,
            direct=(REFERENCE_MODE,),
            aovs=True,
        )


#: Quality presets; "default" runs in about 5 minutes on 2 shared cores.
QUALITIES: dict[str, StudyQuality] = {
    "preview": StudyQuality(64, 64, 16),
    "default": StudyQuality(128, 128, 32),
    "paper": StudyQuality(256, 256, 128),
}
REFERENCE_MODE = "bands31"
#: Compared mode -> the key prefix of its columns in rendering.json.
COMPARED_MODES: dict[str, str] = {"rgb3": "err3", "gauss3": "err3g", "rgb6": "err6"}
#: The study's conditions: the library's two-light ones (:data:`spectrinsic.scenes.CONDITIONS`).
STUDY_CONDITIONS: tuple[str, ...] = tuple(c for c in CONDITIONS if c.startswith("two-colour"))
#: Pixels with luminance Y below this fraction of the image's 99th-percentile Y are left out.
DARK_FRACTION = 0.02
#: Path depth of the full renders (the direct-only render has depth 2).
MAX_DEPTH = 8
DEFAULT_SEED = 0
#: Thesis section 5.2.3: mean r over its nine complex scenes.
THESIS_MEAN_R = 0.83


@dataclass(frozen=True)
class SampleResult:
    """One rendered sample: its row of numbers and the images its figure shows.

    ``reference``: ``(H, W, 3)`` linear CIE XYZ of the 31-band render; ``errors``: compared mode
    -> ``(H, W)`` float64 ε (a fraction, NaN where not evaluated).
    """

    sample: str
    row: dict[str, Any]
    reference: np.ndarray
    errors: dict[str, np.ndarray]


def study_quality(quality: str) -> StudyQuality:
    """The preset named *quality* (one of :data:`QUALITIES`)."""
    return QUALITIES[
        validate_choice(quality, QUALITIES, "rendering study quality", error=StudyError)
    ]


def samples(
    scenes: Sequence[str] | None,
    views: Sequence[int] | None,
    conditions: Sequence[str],
) -> Iterator[tuple[str, int, str]]:
    """``(scene, view, condition)`` of every sample: each complex scene (or *scenes*), each of
    its views (or *views*), each condition (validated against the library's)."""
    for condition in conditions:
        validate_choice(condition, CONDITIONS, "illumination condition", error=SceneError)
    names = list(scenes) if scenes is not None else library.scene_names("complex")
    for name in names:
        for view in list(views) if views is not None else range(library.n_views(name)):
            for condition in conditions:
                yield name, int(view), condition


def valid_pixels(reference_xyz: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """``(H, W)`` bool: pixels covered mostly by a material (*mask*) whose reference luminance Y
    exceeds :data:`DARK_FRACTION` of the 99th-percentile Y over *mask* (the thesis discards
    dark patches)."""
    y = reference_xyz[..., 1].astype(np.float64)
    bright = np.percentile(y[mask], 99) if mask.any() else 0.0
    return mask & (y > DARK_FRACTION * bright)


def error_stats(err: np.ndarray) -> dict[str, float]:
    """Mean, s.d. and max of a per-pixel error map in percent (NaNs ignored)."""
    v = err[np.isfinite(err)]
    if v.size == 0:
        return {"mean_pct": float("nan"), "sd_pct": float("nan"), "max_pct": float("nan")}
    return {
        "mean_pct": 100 * float(v.mean()),
        "sd_pct": 100 * float(v.std()),
        "max_pct": 100 * float(v.max()),
    }


def evaluate_sample(
    name: str,
    view: int,
    condition: str,
    *,
    quality: StudyQuality,
    seed: int,
    variant: str | None = None,
    data_dir: str | None = None,
) -> SampleResult:
    """Build and render one sample in every mode and compare each mode with the reference.

    The row holds, per compared mode, the mean, s.d. and max of ε in percent, the energy ratio
    r (Eq. 5.8) of the reference, the number of evaluated pixels and the render time (s).
    """
    sample = str(SampleId(name, view, condition))
    scene = library.build(
        name, view=view, condition=condition, seed=seed, width=quality.width, height=quality.height
    )
    t0 = time.perf_counter()
    result = render_scene(
        scene, quality.render_settings(variant), seed=seed_from_key(seed, sample), data_dir=data_dir
    )
    seconds = time.perf_counter() - t0
    ref = result.images[REFERENCE_MODE]
    valid = valid_pixels(ref, result.aovs["mask"])
    errors = {m: relative_error(result.images[m], ref, where=valid) for m in COMPARED_MODES}
    row: dict[str, Any] = {
        "scene": name,
        "view": int(view),
        "condition": condition,
        "illuminants": " + ".join(
            scene.metadata.get("illuminants", [li.spectrum for li in scene.lights])
        ),
    }
    for mode, prefix in COMPARED_MODES.items():
        stats = error_stats(errors[mode])
        row.update(
            {
                f"{prefix}_mean_pct": stats["mean_pct"],
                f"{prefix}_sd_pct": stats["sd_pct"],
                f"{prefix}_max_pct": stats["max_pct"],
            }
        )
    row.update(
        {
            "energy_ratio_r": result.energy_ratio(REFERENCE_MODE),
            "n_pixels": int(valid.sum()),
            "seconds": seconds,
        }
    )
    logger.info(
        "%s: err3 %.2f %%, err6 %.2f %%, r %.3f (%.1f s)",
        sample,
        row["err3_mean_pct"],
        row["err6_mean_pct"],
        row["energy_ratio_r"],
        seconds,
    )
    return SampleResult(sample, row, ref, errors)


def summary(rows: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """Means (and maxima) of the rows' errors, the mean energy ratio, and its mean per scene."""
    out: dict[str, Any] = {"n_rows": len(rows)}
    if not rows:
        return out
    for prefix in COMPARED_MODES.values():
        out[f"{prefix}_mean_pct"] = float(np.nanmean([r[f"{prefix}_mean_pct"] for r in rows]))
        out[f"{prefix}_max_pct"] = float(np.nanmax([r[f"{prefix}_max_pct"] for r in rows]))
    r = np.array([row["energy_ratio_r"] for row in rows])
    out["energy_ratio_r_mean"] = float(np.mean(r))
    out["energy_ratio_r_by_scene"] = {
        s: float(np.mean([row["energy_ratio_r"] for row in rows if row["scene"] == s]))
        for s in dict.fromkeys(row["scene"] for row in rows)
    }
    return out
