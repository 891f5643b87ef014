"""The rendered study (``spectrinsic study rendering``): colour error of diagonal renders with
all bounces, the rendered analogue of thesis Table 5.2, and the energy ratio r of Eq. 5.8.

Every complex library scene is rendered from each viewpoint under its two two-light conditions.
The reference is the 31-band cube (``bands31``, 10 nm box bands integrated against the CIE 1931
CMFs; it agrees with Mitsuba's spectral variant within 0.5 % in mean colour, see
``tests/render``), rendered with the same paths as the approximations (common random numbers),
so the differences are spectral error, not Monte Carlo noise. Compared with it:

* ``rgb3``: 3-channel diagonal render with the CIE 1931 CMFs as sensors;
* ``gauss3``: 3 Gaussian sensors (thesis Table 5.2's set) regressed to XYZ;
* ``rgb6``: 6 Gaussian sensors (the thesis' two-pass method) regressed to XYZ on the Munsell
  chips under the scene's lights.

Per pixel the error is Eq. 5.7 on CIE XYZ, ``ε = ‖p − p̂‖₂ / ‖p‖₂`` (XYZ: the space every mode is
converted to; linear sRGB would weigh channels differently but is a fixed linear map of it).
Like the thesis, which discards dark patches, pixels darker than :data:`DARK_FRACTION` of the
image's 99th-percentile luminance are left out, as are pixels not covered mostly by a material
(visible light sources). The energy ratio ``r = Σ‖p¹‖ / Σ‖p^∞‖`` uses the reference's direct-only
render (path depth 2) and full render (depth :data:`MAX_DEPTH`).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from spectrinsic.errors import validate_choice
from spectrinsic.results import provenance, write_csv, write_json

__all__ = [
    "QUALITIES",
    "StudyQuality",
    "REFERENCE_MODE",
    "COMPARED_MODES",
    "CONDITIONS",
    "DARK_FRACTION",
    "pixel_errors",
    "error_stats",
    "run_rendering_study",
    "format_rendering",
]

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class StudyQuality:
    """Image size and samples per pixel of a study render."""

    width: int
    height: int
    spp: int


#: Quality presets; "default" runs in about 5 minutes on 2 shared cores.
QUALITIES: dict[str, StudyQuality] = {
    "preview": StudyQuality(64, 64, 16),
    "default": StudyQuality(128, 128, 32),
    "paper": StudyQuality(256, 256, 128),
}
REFERENCE_MODE = "bands31"
#: Compared mode -> the key prefix of its columns in rendering.json.
COMPARED_MODES: dict[str, str] = {"rgb3": "err3", "gauss3": "err3g", "rgb6": "err6"}
#: The two-light conditions of the library.
CONDITIONS: tuple[str, ...] = ("two-colour-a", "two-colour-b")
#: Pixels with luminance Y below this fraction of the image's 99th-percentile Y are left out.
DARK_FRACTION = 0.02
MAX_DEPTH = 8
DEFAULT_SEED = 0
#: Thesis section 5.2.3: mean r over its nine complex scenes.
THESIS_MEAN_R = 0.83

Progress = Callable[..., Any]


def pixel_errors(estimate: np.ndarray, reference: np.ndarray, valid: np.ndarray | None = None) -> np.ndarray:
    """Per-pixel relative error ``‖p − p̂‖₂ / ‖p‖₂`` (Eq. 5.7), ``(H, W)`` float64, NaN where invalid.

    Parameters
    ----------
    estimate, reference
        ``(H, W, 3)`` linear colours (XYZ) of the approximation p̂ and the reference p.
    valid
        ``(H, W)`` bool pixels to evaluate (default: where ``‖p‖ > 0``).

    >>> p = np.ones((1, 2, 3)); q = p.copy(); q[0, 1] = [1.0, 1.0, 1.3]
    >>> np.round(pixel_errors(q, p), 4).tolist()
    [[0.0, 0.1732]]
    """
    ref = np.asarray(reference, np.float64)
    est = np.asarray(estimate, np.float64)
    norm = np.linalg.norm(ref, axis=-1)
    ok = norm > 0 if valid is None else np.asarray(valid, bool) & (norm > 0)
    err = np.full(norm.shape, np.nan)
    err[ok] = np.linalg.norm(est - ref, axis=-1)[ok] / norm[ok]
    return err


def error_stats(err: np.ndarray) -> dict[str, float]:
    """Mean, s.d. and max of a per-pixel error map in percent (NaNs ignored)."""
    v = err[np.isfinite(err)]
    if v.size == 0:
        return {"mean_pct": float("nan"), "sd_pct": float("nan"), "max_pct": float("nan")}
    return {"mean_pct": 100 * float(v.mean()), "sd_pct": 100 * float(v.std()), "max_pct": 100 * float(v.max())}


def _valid_pixels(reference_xyz: np.ndarray, mask: np.ndarray) -> np.ndarray:
    y = reference_xyz[..., 1].astype(np.float64)
    bright = np.percentile(y[mask], 99) if mask.any() else 0.0
    return mask & (y > DARK_FRACTION * bright)


def _srgb8(xyz: np.ndarray, scale: float) -> np.ndarray:
    import colour

    from spectrinsic.spectra import xyz_to_linear_srgb

    rgb = np.clip(xyz_to_linear_srgb(xyz) / scale, 0.0, 1.0)
    return np.asarray(colour.cctf_encoding(rgb, function="sRGB"))


def _figure(path: Path, title: str, reference: np.ndarray, errors: dict[str, np.ndarray]) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    top = max(float(np.nanmax(e)) if np.isfinite(e).any() else 0.0 for e in errors.values()) * 100 or 1.0
    fig, axes = plt.subplots(1, 1 + len(errors), figsize=(3.2 * (1 + len(errors)), 3.4))
    y = reference[..., 1]
    axes[0].imshow(_srgb8(reference, float(np.percentile(y, 99)) or 1.0))
    axes[0].set_title("reference (31 bands, sRGB)", fontsize=9)
    image = None
    for ax, (mode, err) in zip(axes[1:], errors.items(), strict=True):
        image = ax.imshow(100 * err, cmap="magma", vmin=0.0, vmax=top)
        ax.set_title(f"{mode}: mean {100 * np.nanmean(err):.2f} %", fontsize=9)
    for ax in axes:
        ax.set_axis_off()
    if image is not None:
        fig.colorbar(image, ax=list(axes[1:]), shrink=0.8, label="ε (%) Eq. 5.7 on XYZ")
    fig.suptitle(title, fontsize=10)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def run_rendering_study(
    out_dir: Path,
    *,
    quality: str = "default",
    data_dir: str | None = None,
    progress: Progress | None = None,
    seed: int = DEFAULT_SEED,
    scenes: Sequence[str] | None = None,
    views: Sequence[int] | None = None,
    conditions: Sequence[str] = CONDITIONS,
    variant: str | None = None,
) -> dict[str, Any]:
    """Render the complex scenes and write ``rendering.json``, ``rendering.csv`` and error maps.

    Parameters
    ----------
    out_dir
        Folder for ``rendering.json``, ``rendering.csv`` and ``rendering/<sample>.png``.
    quality
        One of :data:`QUALITIES`.
    progress
        Called once per rendered sample with its id (e.g. a tqdm step).
    seed
        Root seed of the illuminant draws (:func:`spectrinsic.scenes.library.build`) and of the
        sampler (offset per sample).
    scenes, views
        Subsets (default: every complex scene, every view).

    Returns
    -------
    The payload written to ``rendering.json``: ``rows`` (one per scene, view and condition),
    ``summary``, ``settings``, ``definitions``, ``provenance``, ``paths``.
    """
    from spectrinsic.render import render_scene
    from spectrinsic.rng import seed_from_key
    from spectrinsic.scenes import library

    q = QUALITIES[validate_choice(quality, QUALITIES, "rendering study quality")]
    names = list(scenes) if scenes is not None else library.scene_names("complex")
    modes = (*COMPARED_MODES, REFERENCE_MODE)
    out_dir = Path(out_dir)
    rows: list[dict[str, Any]] = []
    figures: list[str] = []
    started = time.perf_counter()
    for name in names:
        for view in (list(views) if views is not None else range(library.n_views(name))):
            for condition in conditions:
                sample = f"{name}__v{view}__{condition}"
                scene = library.build(name, view=view, condition=condition, seed=seed, width=q.width, height=q.height)
                t0 = time.perf_counter()
                result = render_scene(
                    scene, modes=modes, spp=q.spp, seed=seed_from_key(seed, sample), max_depth=MAX_DEPTH,
                    variant=variant, direct=(REFERENCE_MODE,), aovs=True, data_dir=data_dir,
                )
                seconds = time.perf_counter() - t0
                ref = result.images[REFERENCE_MODE]
                valid = _valid_pixels(ref, result.aovs["mask"])
                errors = {m: pixel_errors(result.images[m], ref, valid) for m in COMPARED_MODES}
                row: dict[str, Any] = {
                    "scene": name, "view": int(view), "condition": condition,
                    "illuminants": " + ".join(scene.metadata.get("illuminants", [li.spectrum for li in scene.lights])),
                }
                for mode, prefix in COMPARED_MODES.items():
                    stats = error_stats(errors[mode])
                    row.update({f"{prefix}_mean_pct": stats["mean_pct"], f"{prefix}_sd_pct": stats["sd_pct"],
                                f"{prefix}_max_pct": stats["max_pct"]})
                row.update({
                    "energy_ratio_r": result.energy_ratio(REFERENCE_MODE),
                    "n_pixels": int(valid.sum()),
                    "seconds": seconds,
                })
                rows.append(row)
                fig = _figure(out_dir / "rendering" / f"{sample}.png", sample.replace("__", "  "), ref, errors)
                figures.append(str(fig))
                logger.info("%s: err3 %.2f %%, err6 %.2f %%, r %.3f (%.1f s)", sample, row["err3_mean_pct"],
                            row["err6_mean_pct"], row["energy_ratio_r"], seconds)
                if progress is not None:
                    progress(sample)
    summary = _summary(rows)
    summary["seconds_total"] = time.perf_counter() - started
    payload: dict[str, Any] = {
        "study": "rendering",
        "rows": rows,
        "summary": summary,
        "settings": {**asdict(q), "quality": quality, "seed": seed, "max_depth": MAX_DEPTH,
                     "reference": REFERENCE_MODE, "compared": list(COMPARED_MODES),
                     "conditions": list(conditions), "dark_fraction": DARK_FRACTION},
        "definitions": {
            "error": "per pixel eps = ||p - p_hat||_2 / ||p||_2 (Eq. 5.7) on CIE 1931 XYZ; p: 31-band cube "
                     "integrated against the CMFs; mean, s.d., max over pixels covered mostly by a "
                     f"material with Y above {DARK_FRACTION:g} x the image's 99th-percentile Y",
            "energy_ratio_r": "sum_x ||p1(x)|| / sum_x ||p_inf(x)|| (Eq. 5.8) on XYZ of the reference; p1: "
                              "direct light only (path depth 2)",
            "thesis_mean_r": THESIS_MEAN_R,
        },
        "provenance": provenance(),
    }
    json_path = out_dir / "rendering.json"
    csv_path = out_dir / "rendering.csv"
    payload["paths"] = {"json": str(json_path), "csv": str(csv_path), "figures": figures}
    write_json(json_path, _finite(payload))
    write_csv(csv_path, rows)
    return payload


def _summary(rows: Sequence[dict[str, Any]]) -> dict[str, Any]:
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


def _finite(value: Any) -> Any:
    """NaN/inf -> None, so the JSON stays strict."""
    if isinstance(value, float):
        return value if np.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_finite(v) for v in value]
    return value


def format_rendering(payload: dict[str, Any]) -> str:
    """The study's rows as a fixed-width table (errors in %)."""
    head = f"{'scene':<14}{'v':>2} {'condition':<13}{'e3 mean':>8}{'e3 max':>8}{'e3g mean':>9}{'e6 mean':>8}{'e6 max':>8}{'r':>7}"
    lines = [head, "-" * len(head)]
    for r in payload["rows"]:
        lines.append(
            f"{r['scene']:<14}{r['view']:>2} {r['condition']:<13}{r['err3_mean_pct']:>8.2f}{r['err3_max_pct']:>8.2f}"
            f"{r['err3g_mean_pct']:>9.2f}{r['err6_mean_pct']:>8.2f}{r['err6_max_pct']:>8.2f}{r['energy_ratio_r']:>7.3f}"
        )
    s = payload["summary"]
    if s.get("n_rows"):
        lines.append(
            f"mean over {s['n_rows']} renders: err3 {s['err3_mean_pct']:.2f} %, err3g {s['err3g_mean_pct']:.2f} %, "
            f"err6 {s['err6_mean_pct']:.2f} %, r {s['energy_ratio_r_mean']:.3f} (thesis {THESIS_MEAN_R})"
        )
    return "\n".join(lines)
