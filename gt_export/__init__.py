"""spectrinsic.gt_export: ground-truth layers, their files, and reading them back.

The only package that imports OpenEXR. It takes arrays and a RenderResult-like record, never a
live renderer, and computes the exact ground truth (absolute reflectance, shading-illumination,
illuminant, camera views, chapter-4 matrices) from the scene's spectra.
"""

from spectrinsic.gt_export.check import check_dataset, check_sample
from spectrinsic.gt_export.exr import read_exr, write_exr
from spectrinsic.gt_export.gallery import build_gallery, contact_sheet
from spectrinsic.gt_export.layers import GroundTruth, Layer, LightRecord, compute_ground_truth
from spectrinsic.gt_export.loader import load_dataset, load_sample, torch_dataset
from spectrinsic.gt_export.relight import relight
from spectrinsic.gt_export.writer import (
    DEFAULT_CAMERAS,
    config_hash,
    export_sample,
    is_complete,
    remove_stale_temporaries,
    sample_dirs,
    write_dataset_card,
    write_manifest,
)

__all__ = [
    "DEFAULT_CAMERAS",
    "GroundTruth",
    "Layer",
    "LightRecord",
    "build_gallery",
    "check_dataset",
    "check_sample",
    "compute_ground_truth",
    "config_hash",
    "contact_sheet",
    "export_sample",
    "is_complete",
    "load_dataset",
    "load_sample",
    "read_exr",
    "relight",
    "remove_stale_temporaries",
    "sample_dirs",
    "torch_dataset",
    "write_dataset_card",
    "write_exr",
    "write_manifest",
]
