"""Running the sim-to-real study: one generated set, the arms trained seed by seed, each run
scored on the MIT photographs and on the set's held-out test split with the thesis' protocol.

The set and the weights live in a temporary folder for the run: what is kept is each arm's
generator settings (the set's config and hash), its samples and its scores.
"""

from __future__ import annotations

import tempfile
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from ...arrays import StepProgress
from ...decompose.evaluation.mit import MitObject, load_mit_object, mit_measures
from ...decompose.methods.registry import get_decomposer
from ...errors import StudyError
from ...gt_export.dataset.loader import load_sample, split_samples
from ...gt_export.sample import sample_dirs
from ...gt_export.sample.meta import read_meta
from ...learn.card import write_outputs
from ...learn.train import TrainOptions, train
from ...pipeline.dataset import build_dataset
from ...pipeline.presets import DatasetConfig
from ...pipeline.source_plan import generator_source
from .settings import Arm, Sim2RealSettings, arms

__all__ = ["BASELINES", "RunScore", "Sim2RealResult", "dataset_config", "run_sim2real"]

#: The bundled decomposers scored beside the network on the same images.
BASELINES = ("image-as-reflectance", "colour-retinex", "names-shades")
#: The MIT development half inside the data directory.
MIT_FOLDER = "mit_intrinsic_dev"


@dataclass(frozen=True)
class RunScore:
    """One trained run: arm, seed, mean LMSE (Table 3.2's, the mean of shading and grey
    reflectance) on MIT and on the synthetic test split, samples trained on, seconds."""

    arm: str
    seed: int
    mit_lmse: float
    test_lmse: float
    samples: int
    seconds: float


@dataclass(frozen=True)
class Sim2RealResult:
    """The study's result: its settings, the set's config (the arms' generator settings) and
    hash, each arm's sample ids, every run's scores, the baselines' ``{name: (mit, test)}``
    and the wall time."""

    settings: Sim2RealSettings
    config: dict[str, Any]
    config_hash: str
    arm_samples: dict[str, list[str]]
    runs: list[RunScore]
    baselines: dict[str, tuple[float, float]]
    mit_objects: int
    test_samples: int
    seconds: float


def dataset_config(settings: Sim2RealSettings) -> DatasetConfig:
    """The generated set every arm trains on: the spectral reference, the rgb3 render and the
    31-band cube (the camera chain's input) of each scene, run through *settings.camera*."""
    return DatasetConfig.from_settings(
        f"sim2real-{settings.preset}",
        width=settings.size,
        height=settings.size,
        spp=settings.spp,
        spectral_spp=max(1, settings.spp // 4),
        max_depth=settings.max_depth,
        modes=("spectral", "rgb3", "bands31"),
        batches=1,
        denoise=False,
        camera=settings.camera,
        seed=settings.seed,
        source=generator_source(settings.generator, settings.count),
    )


def _selection(folders: list[Path], arm: Arm) -> list[str]:
    ids = sorted(f.name for f in folders)
    white = [i for i in ids if i.endswith("__white")]
    coloured = [i for i in ids if not i.endswith("__white")]
    n = min(len(white), len(coloured))
    if arm.selection == "all":
        return ids
    if n == 0:
        raise StudyError(
            f"sim2real: the train split holds {len(white)} white and {len(coloured)} "
            "coloured-light samples; the coloured/white arms need both (more --count)"
        )
    return (white if arm.selection == "white" else coloured)[:n]


def _camera_key(folder: Path) -> str:
    prefix = "image_sensor_noisy/"
    keys = [k for k in read_meta(folder).layers if k.startswith(prefix)]
    if not keys:
        raise StudyError(f"sim2real: {folder} has no camera-chain image ({prefix}<camera>)")
    return keys[0].removeprefix(prefix)


def _test_objects(dataset: Path) -> list[MitObject]:
    """The test split's samples as MIT objects: the reference image, reflectance and grey
    shading in the linear sRGB view."""
    objects = []
    for folder in split_samples(dataset, "test"):
        s = load_sample(
            folder, layers=("image", "reflectance", "shading_grey", "mask"), space="srgb"
        )
        objects.append(
            MitObject(
                folder.name,
                np.clip(s["image"], 0, None),
                s["reflectance"],
                s["shading_grey"],
                s["mask"],
            )
        )
    return objects


def _mean_lmse(method: Any, objects: list[MitObject]) -> float:
    if not objects:
        return float("nan")
    values = [mit_measures(o, method(o.image, o.mask))["lmse"] for o in objects]
    return float(np.nanmean(values))


def _train_run(
    dataset: Path, work: Path, arm: Arm, ids: list[str], seed: int, settings: Sim2RealSettings
) -> tuple[Path, float]:
    options = TrainOptions(
        steps=settings.steps,
        seed=seed,
        batch=settings.batch,
        crop=settings.crop,
        layers=arm.layers,
        samples=tuple(ids),
        checkpoint_every=settings.steps,
        device=settings.device,
    )
    out = work / f"{arm.name}-seed{seed}"
    out.mkdir()
    result = train(dataset, out, options)
    write_outputs(out, dataset, options, result)
    return out / "weights.pt", result.seconds


def run_sim2real(
    settings: Sim2RealSettings, *, data_dir: str | None, progress: StepProgress | None
) -> Sim2RealResult:
    """Build the set, train every arm with every seed, score the runs and the baselines."""
    began = time.perf_counter()
    mit_dir = Path(data_dir or "") / MIT_FOLDER
    mit = [load_mit_object(p) for p in sorted(mit_dir.glob("*.npz"))] if data_dir else []
    config = dataset_config(settings)
    with tempfile.TemporaryDirectory(prefix="spectrinsic-sim2real-") as tmp:
        dataset, work = Path(tmp) / "set", Path(tmp) / "runs"
        work.mkdir()
        build_dataset(dataset, config, data_dir=data_dir)
        if progress is not None:
            progress(f"built {len(sample_dirs(dataset))} samples")
        test = _test_objects(dataset)
        train_folders = split_samples(dataset, "train")
        plan = arms(_camera_key(train_folders[0]))
        arm_samples = {a.name: _selection(train_folders, a) for a in plan}
        runs = []
        for arm in plan:
            for seed in settings.seeds:
                weights, seconds = _train_run(
                    dataset, work, arm, arm_samples[arm.name], seed, settings
                )
                unet = get_decomposer(f"unet:{weights}")
                runs.append(
                    RunScore(
                        arm.name,
                        seed,
                        _mean_lmse(unet, mit),
                        _mean_lmse(unet, test),
                        len(arm_samples[arm.name]),
                        seconds,
                    )
                )
                if progress is not None:
                    progress(f"{arm.name} seed {seed}: MIT LMSE {runs[-1].mit_lmse:.4f}")
        baselines = {
            name: (_mean_lmse(get_decomposer(name), mit), _mean_lmse(get_decomposer(name), test))
            for name in BASELINES
        }
    return Sim2RealResult(
        replace(settings),
        config.to_dict(),
        config.config_hash(),
        arm_samples,
        runs,
        baselines,
        len(mit),
        len(test),
        time.perf_counter() - began,
    )
