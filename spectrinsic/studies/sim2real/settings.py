"""The sim-to-real study's settings: its presets, the one generated set they build, and the arms.

Every arm trains the same U-Net (:mod:`spectrinsic.learn`) on one generated set, built once, and
differs from its partner in one factor:

* ``spectral`` / ``rgb3``: the training image is the spectral reference render (``image``)
  or the 3-sensor render of the same scenes and lights (``image_rgb3``); same targets;
* ``coloured`` / ``white``: the scenes drawn in the coloured-light families (one-colour,
  two-colour) or in the white family, the same number of samples each;
* ``camera`` / ``no-camera``: the camera chain's processed image (``image_sensor_noisy/<cam>``,
  demosaicked, white-balanced, colour-matrixed, with its noise) and the ground truth carried
  into that space, or the reference image and ground truth (the ``spectral`` arm's runs).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

from ...errors import StudyError, validate_choice
from ...learn.data import TrainLayers

__all__ = ["Sim2RealSettings", "PRESETS", "Arm", "FACTORS", "arms", "preset"]


@dataclass(frozen=True)
class Sim2RealSettings:
    """One run of the study.

    Attributes
    ----------
    preset
        Its name (``small`` for 2 CPU cores, ``large`` for a GPU or a cluster).
    generator, count, size, spp, max_depth
        The generated set: scene generator, scenes (one sample each, its light family drawn
        by the generator), square image side in pixels, samples per pixel, path depth.
    camera
        The camera model of the camera arm (``dataset --camera``).
    steps, batch, crop
        Training of each run (:class:`spectrinsic.learn.train.TrainOptions`).
    device
        Where the networks train (``cpu``: deterministic; ``cuda`` for ``large``).
    seeds
        The seeds every arm is trained with (at least 3: the intervals need them).
    seed
        Root seed of the generated set.
    """

    preset: str
    generator: str = "objects-on-ground"
    count: int = 48
    size: int = 64
    spp: int = 16
    max_depth: int = 4
    camera: str = "nikon-d5100-npl"
    steps: int = 300
    batch: int = 4
    crop: int = 48
    device: str = "cpu"
    seeds: tuple[int, ...] = (0, 1, 2)
    seed: int = 0

    def __post_init__(self) -> None:
        if len(self.seeds) < 3:
            raise StudyError(f"sim2real: {len(self.seeds)} seeds; the intervals need at least 3")

    def to_dict(self) -> dict[str, Any]:
        record = asdict(self)
        record["seeds"] = list(self.seeds)
        return record


#: The presets. ``small`` is sized for 2 CPU cores in under an hour (48 scenes at 64², 5 arms x
#: 3 seeds x 300 steps of 4 crops of 48²; 18.9 min measured on the shared machine,
#: docs/sim2real.md); ``reduced`` is a smaller run (32 scenes, 8 spp, 200 steps; 22.5 min there
#: under a heavier load); ``large`` is for a GPU or a cluster.
PRESETS: dict[str, Sim2RealSettings] = {
    "small": Sim2RealSettings("small"),
    "reduced": Sim2RealSettings("reduced", count=32, spp=8, steps=200),
    "large": Sim2RealSettings(
        "large",
        generator="rooms",
        count=400,
        size=128,
        spp=64,
        max_depth=6,
        steps=5000,
        batch=8,
        crop=64,
        device="cuda",
        seeds=(0, 1, 2, 3, 4),
    ),  # fmt: skip
}


def preset(name: str) -> Sim2RealSettings:
    """The preset called *name* (one-line :class:`StudyError` with close names)."""
    return PRESETS[validate_choice(name, PRESETS, "sim2real preset", error=StudyError)]


@dataclass(frozen=True)
class Arm:
    """One arm: its name, its factor, the layers it trains on and its sample selection
    (``"all"``, ``"coloured"`` or ``"white"``)."""

    name: str
    factor: str
    layers: TrainLayers
    selection: str = "all"


#: factor -> (arm with the factor, arm without), the first arm's difference is first - second.
FACTORS: dict[str, tuple[str, str]] = {
    "spectral image": ("spectral", "rgb3"),
    "coloured lights": ("coloured", "white"),
    "camera chain": ("camera", "spectral"),
}


def arms(camera_key: str) -> tuple[Arm, ...]:
    """The five arms (the ``no-camera`` arm is the ``spectral`` one); *camera_key* is the
    camera's layer suffix (``Nikon 5100 (NPL)``)."""
    return (
        Arm("spectral", "spectral image", TrainLayers()),
        Arm("rgb3", "spectral image", TrainLayers(image="image_rgb3")),
        Arm("coloured", "coloured lights", TrainLayers(), "coloured"),
        Arm("white", "coloured lights", TrainLayers(), "white"),
        Arm(
            "camera",
            "camera chain",
            TrainLayers(
                f"image_sensor_noisy/{camera_key}",
                f"reflectance_sensor/{camera_key}",
                f"shading_sensor/{camera_key}",
            ),
        ),
    )
