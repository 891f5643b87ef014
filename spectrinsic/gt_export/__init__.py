"""spectrinsic.gt_export: ground-truth layers, their files, and reading them back.

The only package that imports OpenEXR. It takes arrays and a RenderResult-like record, never a
live renderer, and computes the exact ground truth (absolute reflectance, shading-illumination,
illuminant, camera views, chapter-4 matrices) from the scene's spectra.

Its modules, by stage (no import cycle among them: tests/gt_export/test_imports.py):

* computation: ``layers/`` (one module per family of layers, composed by
  ``layers.compose.compute_ground_truth``), ``irradiance``, ``denoise``;
* the sample folder's format: ``sample`` (file names, canonical JSON, hashes, the seal of
  ``meta.json``, listing), ``json_fields`` and ``sample_meta`` (the one validated reader of
  ``meta.json``: :class:`SampleMeta`), ``exr``, ``png``, ``names``, ``integrity`` (which
  samples may be resumed, replaced or removed);
* writing a sample: ``previews``, ``writer``; output folders: ``folders/`` (the ``--out``
  rule, staging, the dataset marker in ``build_folder``);
* dataset products: ``manifest`` (hashes, splits, noise summary), ``card`` (``DATASET.md``),
  ``diversity``, ``check``, ``shards``, ``loader`` (``load_sample``, ``load_dataset``);
* the viewer: ``gallery``.
"""

from .dataset.card import write_dataset_card
from .dataset.check import check_dataset, check_sample
from .dataset.gallery import build_gallery, contact_sheet
from .dataset.loader import load_dataset, load_sample, torch_dataset
from .dataset.manifest import write_manifest
from .folders.build_folder import remove_owned_temporaries
from .formats.exr import read_exr, write_exr
from .layers import GroundTruth, Layer, LightRecord, compute_ground_truth
from .relight import relight
from .sample import config_hash, sample_dirs
from .sample.meta import SampleMeta, read_meta
from .sample.writer import DEFAULT_CAMERAS, export_sample, is_complete

__all__ = [
    "DEFAULT_CAMERAS",
    "GroundTruth",
    "Layer",
    "LightRecord",
    "SampleMeta",
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
    "read_meta",
    "relight",
    "remove_owned_temporaries",
    "sample_dirs",
    "torch_dataset",
    "write_dataset_card",
    "write_exr",
    "write_manifest",
]
