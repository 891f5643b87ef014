"""``LayerSettings``: which ground-truth layers one sample gets, as one frozen record.

:func:`~spectrinsic.gt_export.layers.compute_ground_truth` and
:func:`~spectrinsic.gt_export.sample.writer.export_sample` take this record instead of a
dozen keywords. It is built in two places only: from a dataset's settings
(:meth:`spectrinsic.pipeline.presets.DatasetConfig.layer_settings`, the same record for every
sample of a build) and from a written sample's ``meta.json``
(:func:`spectrinsic.gt_export.relight.settings_of`, so a relit sample gets the layers its
source has). The working space travels in it as the :class:`WorkingSpace` record, validated
where it entered (the dataset config or the meta reader), never as a name.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field, replace

from ...errors import DatasetError
from ...spectra.camera_model import CameraModel
from ...spectra.working_space import DEFAULT_WORKING_SPACE, WorkingSpace, working_space
from .records import camera_key

__all__ = ["DEFAULT_CAMERAS", "LayerSettings"]

#: Cameras exported by default when the 31-band cube is available (shipped by colour-science).
DEFAULT_CAMERAS: tuple[str, ...] = ("camera:Nikon 5100 (NPL)", "camera:Sigma SDMerill (NPL)")


@dataclass(frozen=True)
class LayerSettings:
    """The layers of one sample beyond the default ones, and what they are computed with.

    Attributes
    ----------
    cameras
        Camera sensor sets (``"camera:Nikon 5100 (NPL)"``) for per-camera layers (an image
        from the 31-band cube, relative reflectance, shading, residual, illuminant in that
        camera's RGB). ``None``: :data:`DEFAULT_CAMERAS` when the render has the cube, in
        :func:`~spectrinsic.gt_export.sample.writer.export_sample` (none in
        :func:`~spectrinsic.gt_export.layers.compute_ground_truth`). With a *camera*, its
        sensitivities are added when missing (the chain runs on that camera's image).
    camera
        A camera chain to run the sample through (raw mosaic, DNG, processed image; the
        ground truth in the processed linear space), or ``None``.
    write_cube
        Also write the 31-band cube (``cube.exr``).
    denoise
        Take ``shading``, ``residual`` and ``illuminant`` from the OIDN-denoised irradiance.
    spectral_layers
        Also write the per-band intrinsic layers (``spectral.exr``); needs the 31-band cube.
    working_space
        The RGB working space of the RGB layers (ACEScg by default), recorded in
        ``meta.json["working_space"]``.
    data_dir
        Spectral data directory (for ``sfu:`` and data-directory spectra and cameras).
    noise_id
        The sample id the camera chain's noise is seeded from (with the sample's seed);
        ``None``: the sample's own id. A relit sample carries its source's id, so its raw
        mosaic has the noise of a direct render of that sample under the new lights.
    scene_folder
        The folder of the scene file the scene was read from (``None`` for generated
        scenes): every ``csv:`` spectrum the sample records (``scene.json``, ``meta.json``) is
        named by its path relative to it (a file outside it by its file name), so no written
        file holds a path of the machine that built it
        (:func:`~spectrinsic.spectra.user_spectra.portable_csv`). Per scene file: a build sets
        it per task with :meth:`for_scene_folder`.
    """

    cameras: tuple[str, ...] | None = None
    camera: CameraModel | None = None
    write_cube: bool = False
    denoise: bool = False
    spectral_layers: bool = False
    working_space: WorkingSpace = field(
        default_factory=lambda: working_space(DEFAULT_WORKING_SPACE)
    )
    data_dir: str | None = None
    noise_id: str | None = None
    scene_folder: str | None = None

    def __post_init__(self) -> None:
        cams = self.cameras
        if cams is not None:  # a list from JSON; the chain's own camera added once
            cams = tuple(cams)
            if self.camera is not None and self.camera.sensitivities not in cams:
                cams += (self.camera.sensitivities,)
            object.__setattr__(self, "cameras", cams)
            keys = {c: camera_key(c) for c in cams}
            twice = sorted({k for k in keys.values() if list(keys.values()).count(k) > 1})
            if twice:  # sensor CSVs are keyed by file name: two would share their layers
                raise DatasetError(
                    f"cameras {list(cams)}: two name the same layers {twice[0]!r}; give sensor "
                    "CSVs different file names"
                )

    def with_cube(self, has_cube: bool) -> LayerSettings:
        """These settings with ``cameras=None`` resolved for a render that has (or lacks) the
        31-band cube: :data:`DEFAULT_CAMERAS` or none."""
        if self.cameras is not None:
            return self
        return replace(self, cameras=DEFAULT_CAMERAS if has_cube else ())

    def for_scene_folder(self, folder: str | os.PathLike[str] | None) -> LayerSettings:
        """These settings for a scene read from a file in *folder* (``None``: no file)."""
        return replace(self, scene_folder=None if folder is None else os.fspath(folder))
