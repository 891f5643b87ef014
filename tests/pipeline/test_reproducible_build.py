"""Two builds of one sample with one seed give the same bytes, whatever Dr.Jit's thread count.

A batch of the default preset (160 spp, the band path, OIDN denoising, the camera layers), with
the RGB mode alone, at 32 x 32: a 160-spp render of 32² pixels is 163,840 lanes, cut by Dr.Jit
into work units whose borders fall inside pixels, so before the samples were split into powers
of two
(:mod:`spectrinsic.render.base.sample_split`) two threads added into those pixels in an order
that followed the schedule. Measured on the 2-core machine with the band path alone: 2 to 8
values differed between two runs with two threads, 13 between two threads and one. The second
build here runs on one Dr.Jit thread, so the comparison does not hang on how the two threads
happened to be scheduled: one thread adds every sample in lane order.

Every file of both builds is compared, none left out. The dataset's pages (manifest, card,
gallery) are not written here (``finalize=False``, a few seconds each); they are drawn from
these files, and tests/pipeline/test_pipeline.py compares the manifest of two builds.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

from spectrinsic.pipeline.dataset import build_dataset
from spectrinsic.pipeline.presets import get_preset
from spectrinsic.render import set_thread_count
from spectrinsic.render.base.variants import import_mitsuba

SAMPLE = "room-living__v1__two-colour-a"
CONFIG = get_preset("default", seed=3).with_options(
    width=32, height=32, modes=("rgb3",), batches=1, spp=160
)


def _hashes(root: Path) -> dict[str, str]:
    return {
        p.relative_to(root).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(root.rglob("*"))
        if p.is_file()
    }


def test_two_builds_with_one_seed_are_byte_identical(tmp_path):
    import_mitsuba()  # Dr.Jit on a suitable libLLVM before it is imported here
    import drjit

    threads = drjit.thread_count()
    first, second = tmp_path / "first", tmp_path / "second"
    assert build_dataset(first, CONFIG, only=SAMPLE, finalize=False).ok
    try:
        assert build_dataset(second, CONFIG, only=SAMPLE, render_threads=1, finalize=False).ok
    finally:
        set_thread_count(threads)
    a, b = _hashes(first), _hashes(second)
    assert f"{SAMPLE}/image.exr" in a and f"{SAMPLE}/intrinsics.exr" in a
    differing = sorted(k for k in a.keys() | b.keys() if a.get(k) != b.get(k))
    assert differing == []
