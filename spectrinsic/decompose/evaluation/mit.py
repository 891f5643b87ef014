"""The MIT Intrinsic Images benchmark (Grosse et al., ICCV 2009) as the thesis scores it.

Folder format (what ``spectrinsic evaluate --mit DIR`` reads): one ``<object>.npz`` per object,
holding ``diffuse`` ``(H, W, 3)`` uint16 (the photograph without specularities, linear),
``reflectance`` ``(H, W, 3)`` uint16, ``shading`` ``(H, W)`` uint16 and ``mask`` ``(H, W)``
bool. Values are ``code / 65535``. The data are never shipped: they are read at run time
(e.g. the development half in ``$SPECTRINSIC_DATA/mit_intrinsic_dev``).

Protocol (Grosse et al. 2009; thesis sec. 3.5, Tables 3.1-3.5): the decomposer gets
``diffuse / 65535`` and the mask; reflectance (truth and estimate) is made grey by the mean of its
channels, the estimated shading too; each estimate is brought to the truth's units by one
least-squares scale over the mask (every measure below is scale-invariant except for the MIT
code's window floor, which assumes values in [0, 1]). Per layer:

* ``lmse``: thesis Eq. 2.5, 20-pixel windows every 10 pixels, one scale per window, ``alpha = 0``
  where the window's estimate energy is at most ``1e-5`` (the MIT code's ``ssq_error``);
* ``almse``: Eq. 2.6; ``corr``: Eq. 2.7 over the masked pixels (NaN for a constant layer,
  left out of the means);
* ``mse``: Eq. 2.4 relative to the truth's energy, ``min_alpha ||I_1 - alpha I_2||^2 /
  ||I_1||^2``: Table 3.4's per-object MSE are of that size (raccoon 0.0045 beside its LMSE
  0.0035; a per-pixel mean of images in [0, 1] is several times smaller).

An object's value of a measure is the mean of its shading and reflectance values; the MIT score
is the object's ``lmse``; a method's is the mean over objects (Table 3.2).
"""

from __future__ import annotations

import fnmatch
import logging
import time
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ...errors import DatasetError
from ...file_writes import write_text_file
from ...path_kinds import folder_problem
from ...results import write_csv
from ..decomposition import Decomposition
from ..metrics.scale import almse, correlation, lmse, si_mse

__all__ = [
    "ARRAYS",
    "LMSE_ENERGY_FLOOR",
    "MEASURES",
    "MitObject",
    "MitScore",
    "load_mit_object",
    "mit_folder_objects",
    "mit_measures",
    "mit_table",
    "score_mit",
    "evaluate_mit",
    "mit_markdown",
]

logger = logging.getLogger(__name__)

#: Arrays of an object file and their rank.
ARRAYS: Mapping[str, int] = {"diffuse": 3, "reflectance": 3, "shading": 2, "mask": 2}
#: Full scale of the stored 16-bit codes.
_FULL_SCALE = 65535.0
#: The MIT code's window floor: alpha = 0 where sum(e^2) <= this (images in [0, 1]).
LMSE_ENERGY_FLOOR = 1e-5
#: The four measures of thesis Table 3.2, in its column order (Corr. higher is better).
MEASURES: tuple[str, ...] = ("corr", "mse", "lmse", "almse")
#: Largest object file read (bytes): the MIT objects are a few MB each.
_MAX_FILE_BYTES = 256 * 1024 * 1024


@dataclass(frozen=True)
class MitObject:
    """One MIT object: input photograph, ground truth and mask.

    Attributes
    ----------
    name
        Object name (the file's stem, e.g. ``"raccoon"``).
    image
        ``(H, W, 3)`` float64 linear input in [0, 1] (``diffuse / 65535``).
    reflectance
        ``(H, W, 3)`` float64 ground-truth reflectance in [0, 1].
    shading
        ``(H, W)`` float64 ground-truth grey shading in [0, 1].
    mask
        ``(H, W)`` bool, the object's pixels.
    """

    name: str
    image: np.ndarray
    reflectance: np.ndarray
    shading: np.ndarray
    mask: np.ndarray


@dataclass(frozen=True)
class MitScore:
    """The Table 3.2 measures of one method on one object.

    Attributes
    ----------
    method, obj
        Method and object names.
    values
        ``{f"{measure}_{layer}": value}`` for each measure of :data:`MEASURES` and layer
        ``shading`` / ``reflectance``, and ``{measure: mean of the two layers}``.
    seconds
        Wall time of the decomposition (0 for predictions read from files).
    """

    method: str
    obj: str
    values: Mapping[str, float]
    seconds: float = 0.0


def load_mit_object(path: Path) -> MitObject:
    """Read one ``<object>.npz`` (module docstring); :class:`DatasetError` naming what is wrong."""
    path = Path(path)
    if path.stat().st_size > _MAX_FILE_BYTES:
        raise DatasetError(f"MIT object {str(path)!r} is larger than {_MAX_FILE_BYTES} bytes")
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {k: np.asarray(data[k]) for k in ARRAYS if k in data.files}
    except (OSError, ValueError) as exc:
        raise DatasetError(f"MIT object {str(path)!r} is not a readable .npz: {exc}") from exc
    missing = [k for k in ARRAYS if k not in arrays]
    if missing:
        raise DatasetError(
            f"MIT object {str(path)!r} lacks {', '.join(missing)} (expected {', '.join(ARRAYS)})"
        )
    shape = arrays["mask"].shape
    for key, rank in ARRAYS.items():
        a = arrays[key]
        if a.ndim != rank or a.shape[:2] != shape or (rank == 3 and a.shape[2] != 3):
            raise DatasetError(
                f"MIT object {str(path)!r}: {key} has shape {a.shape}; expected "
                f"{shape + ((3,) if rank == 3 else ())}"
            )
    mask = arrays["mask"].astype(bool)
    if not mask.any():
        raise DatasetError(f"MIT object {str(path)!r}: the mask selects no pixel")

    def unit(a: np.ndarray) -> np.ndarray:
        return np.asarray(a, dtype=np.float64) / _FULL_SCALE

    return MitObject(
        path.stem,
        unit(arrays["diffuse"]),
        unit(arrays["reflectance"]),
        unit(arrays["shading"]),
        mask,
    )


def mit_folder_objects(folder: Path, patterns: Iterable[str] | None = None) -> list[Path]:
    """The object files of an MIT-format *folder*, sorted by name; only the objects whose name
    matches one of the glob *patterns* if given.

    Raises :class:`DatasetError` for a missing folder, one without ``.npz`` files, or patterns
    that match nothing.
    """
    folder = Path(folder)
    if (problem := folder_problem(folder)) is not None:
        raise DatasetError(
            f"MIT folder {str(folder)!r} {problem} (expected a folder of "
            f"<object>.npz files, e.g. $SPECTRINSIC_DATA/mit_intrinsic_dev)"
        )
    files = sorted(p for p in folder.glob("*.npz") if p.is_file())
    if not files:
        raise DatasetError(f"MIT folder {str(folder)!r} holds no <object>.npz file")
    if patterns is None:
        return files
    globs = list(patterns)
    chosen = [p for p in files if any(fnmatch.fnmatchcase(p.stem, g) for g in globs)]
    if not chosen:
        raise DatasetError(
            f"no object of MIT folder {str(folder)!r} matches "
            f"{', '.join(globs)}; it holds {', '.join(p.stem for p in files)}"
        )
    return chosen


def _to_truth_units(truth: np.ndarray, estimate: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """*estimate* times the least-squares scale that fits it to *truth* over the mask."""
    den = float((estimate[mask] ** 2).sum())
    return estimate * (float((truth[mask] * estimate[mask]).sum()) / den if den > 0.0 else 0.0)


def mit_measures(obj: MitObject, result: Decomposition) -> dict[str, float]:
    """Table 3.2's four measures of *result* on *obj* (module docstring for the protocol)."""
    m = obj.mask
    pairs = {
        "shading": (obj.shading, np.asarray(result.shading, np.float64).mean(axis=2)),
        "reflectance": (
            obj.reflectance.mean(axis=2),
            np.asarray(result.reflectance, np.float64).mean(axis=2),
        ),
    }
    out: dict[str, float] = {}
    for layer, (truth, raw) in pairs.items():
        truth = np.where(m, truth, 0.0)
        est = _to_truth_units(truth, np.where(m, raw, 0.0), m)
        out[f"corr_{layer}"] = correlation(truth, est, mask=m)
        out[f"mse_{layer}"] = si_mse(truth, est, mask=m) / float(np.mean(truth[m] ** 2))
        out[f"lmse_{layer}"] = lmse(truth, est, mask=m, energy_floor=LMSE_ENERGY_FLOOR)
        out[f"almse_{layer}"] = almse(truth, est, mask=m)
    for measure in MEASURES:
        out[measure] = 0.5 * (out[f"{measure}_shading"] + out[f"{measure}_reflectance"])
    return out


#: What a method is for :func:`score_mit`: a decomposer, or an object with ``load(...)``.
Method = Any


def _estimate(method: Method, obj: MitObject) -> Decomposition:
    load = getattr(method, "load", None)
    if (
        load is not None
    ):  # predictions read from files (spectrinsic.decompose.evaluation.predictions)
        found = load(obj.name, "srgb", obj.image, obj.mask)
        assert found is not None  # raises for a sample without files
        return found
    return method(obj.image, obj.mask)


def score_mit(
    files: Iterable[Path],
    methods: Mapping[str, Method],
    *,
    progress: Callable[[str], None] | None = None,
) -> Iterator[MitScore]:
    """Decompose (or read) each object of *files* with each method and yield its scores."""

    for path in files:
        obj = load_mit_object(path)
        for name, method in methods.items():
            t0 = time.perf_counter()
            result = _estimate(method, obj)
            seconds = time.perf_counter() - t0
            values = mit_measures(obj, result)
            logger.info("mit %s %s: lmse %.4f (%.1f s)", name, obj.name, values["lmse"], seconds)
            yield MitScore(name, obj.name, values, seconds)
        if progress is not None:
            progress(obj.name)


def mit_table(scores: Iterable[MitScore]) -> list[dict[str, Any]]:
    """Rows like thesis Table 3.2: per method, the mean over objects of each measure, the
    objects counted, and the number of objects on which it beats ``image-as-reflectance``
    in LMSE (when that baseline was scored)."""
    by: dict[str, dict[str, Mapping[str, float]]] = {}
    for s in scores:
        by.setdefault(s.method, {})[s.obj] = s.values
    baseline = by.get("image-as-reflectance")
    rows = []
    for method, objects in by.items():
        row: dict[str, Any] = {"method": method, "objects": len(objects)}
        for measure in MEASURES:
            finite = [v[measure] for v in objects.values() if np.isfinite(v[measure])]
            row[measure] = float(np.mean(finite)) if finite else float("nan")
        if baseline is not None:
            row["beats_baseline"] = sum(
                1 for o, v in objects.items() if o in baseline and v["lmse"] < baseline[o]["lmse"]
            )
        rows.append(row)
    return rows


def evaluate_mit(
    files: Iterable[Path],
    methods: Mapping[str, Method],
    out: Path,
    *,
    progress: Callable[[str], None] | None = None,
) -> dict[str, Path]:
    """Score *methods* on the MIT objects *files* and write, under *out*, ``mit_scores.csv``
    (one row per method and object, each measure per layer and their mean),
    ``mit_table_3_2.csv`` and ``mit_table_3_2.md`` (:func:`mit_table`). Returns the paths."""

    scores = list(score_mit(files, methods, progress=progress))
    out = Path(out)
    per_object = [
        {"method": s.method, "object": s.obj, **s.values, "seconds": s.seconds} for s in scores
    ]
    rows = mit_table(scores)
    files_out = {
        "scores": write_csv(out / "mit_scores.csv", per_object, float_format=".6g"),
        "table_csv": write_csv(out / "mit_table_3_2.csv", rows, float_format=".6g"),
    }
    md = out / "mit_table_3_2.md"
    write_text_file(md, mit_markdown(rows))
    files_out["table_md"] = md
    return files_out


def mit_markdown(rows: Iterable[Mapping[str, Any]]) -> str:
    """Thesis Table 3.2 layout of :func:`mit_table` rows (LMSE is the MIT score)."""
    rows = list(rows)
    extra = any("beats_baseline" in r for r in rows)
    head = "| method | objects | Corr. | MSE | LMSE | aLMSE |" + (
        " beats baseline |" if extra else ""
    )
    lines = [head, "|---" * (head.count("|") - 1) + "|"]
    for r in rows:
        cells = [r["method"], str(r["objects"])] + [f"{r[m]:.4f}" for m in MEASURES]
        if extra:
            cells.append(str(r.get("beats_baseline", "")))
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"
