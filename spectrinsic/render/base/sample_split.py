"""One render call's samples split so that its film's bits do not follow the thread schedule.

Mitsuba's JIT variants render every sample of one call as one wavefront laid out pixel by pixel
(the spp samples of a pixel in consecutive lanes; ``SamplingIntegrator::render`` in
``src/render/integrator.cpp``) and add each sample into its pixel of the film with an atomic
scatter-add (``ImageBlock::put``). Dr.Jit's LLVM backend runs a wavefront as work units on its
thread pool (``LLVMThreadState::launch`` in drjit-core): units of :data:`WORK_UNIT` lanes when
the wavefront has more than ``2 · WORK_UNIT`` lanes per thread, else one share per thread.
Where a pixel's lanes straddle two units, two threads add into that pixel, and the order of
those float additions, so the pixel's last bits, follows the thread schedule: two builds of
one sample with one seed differed run to run (docs/reproducibility.md).

So :func:`split_render` renders a sample count as powers of two of at most :data:`WORK_UNIT`
(:func:`sample_splits`: 160 = 128 + 32), each part with its own seed (:func:`part_seeds`). A
large part's units then hold whole pixels: one thread adds every sample of a pixel, in lane
order. A part too small for units of :data:`WORK_UNIT` lanes (:func:`single_thread`) runs on one
Dr.Jit thread, which adds in the same lane order. The film is then the same bits run to run and
for any number of threads. The parts' images are averaged with weights ``spp_i / spp`` in
float64, in part order: the same estimate (the mean of spp independent samples per pixel), and
a power-of-two count renders exactly as one call did.

Memory: a part is copied out of Dr.Jit's film and the film given back before the next part
renders. The last part of several is not developed by Mitsuba: its film's storage (``R, G, B``,
the weight, the AOVs) is divided by the weight in numpy a block of rows at a time and summed
into the mean (:func:`_develop_rows`, ``HDRFilm::develop``'s float32 division), where the first
part's storage gave Mitsuba's developed film bit for bit (:func:`_develops_raw`; an RGB
``hdrfilm``, as every film of the band path and the RGB passes): two films at the peak, not three.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from typing import Any

import numpy as np

from ...rng import seed_from_key

__all__ = ["WORK_UNIT", "sample_splits", "part_seeds", "single_thread", "split_render"]

#: Lanes per work unit of Dr.Jit's LLVM backend on large launches (``jitc_llvm_block_size``,
#: 16384 by default); no part of a split has more samples per pixel.
WORK_UNIT = 2**14


def sample_splits(spp: int) -> tuple[int, ...]:
    """*spp* as powers of two of at most :data:`WORK_UNIT`, largest first.

    >>> sample_splits(160), sample_splits(64), sample_splits(5)
    ((128, 32), (64,), (4, 1))
    >>> sample_splits(2**15 + 3)
    (16384, 16384, 2, 1)
    """
    if isinstance(spp, bool) or not isinstance(spp, int) or spp < 1:
        raise ValueError(f"samples per pixel {spp!r}: expected a positive integer")
    full, rest = divmod(spp, WORK_UNIT)
    bits = [1 << b for b in range(rest.bit_length() - 1, -1, -1) if rest >> b & 1]
    return (WORK_UNIT,) * full + tuple(bits)


def part_seeds(seed: int, parts: int) -> tuple[int, ...]:
    """Sampler seeds of the *parts* of one render: *seed* first (so a render of one part is
    the unsplit render), then seeds derived from it by key
    (:func:`~spectrinsic.rng.seed_from_key`), as independent as the batches' seeds.

    >>> part_seeds(7, 2)[0], len(set(part_seeds(7, 3)))
    (7, 3)
    """
    return (int(seed),) + tuple(seed_from_key(int(seed), f"samples-{i}") for i in range(1, parts))


def single_thread(lanes: int, threads: int) -> bool:
    """Whether a wavefront of *lanes* lanes is too small for Dr.Jit's units of
    :data:`WORK_UNIT` lanes on *threads* threads (it is then cut into one share per thread,
    whose borders may fall inside a pixel).

    >>> single_thread(32 * 32 * 32, 2), single_thread(32 * 32 * 128, 2)
    (True, False)
    """
    return threads > 1 and lanes <= 2 * WORK_UNIT * threads


@contextlib.contextmanager
def _threads(dr: Any, film: Any, spp: int) -> Iterator[None]:
    """Dr.Jit's thread pool inside the block: one thread where a wavefront of *film*'s pixels
    times *spp* is too small for its work units (:func:`single_thread`), else as it is."""
    before = dr.thread_count()
    width, height = film.crop_size()
    if before == 1 or not single_thread(int(width) * int(height) * spp, before):
        yield
        return
    dr.set_thread_count(1)
    try:
        yield
    finally:
        dr.set_thread_count(before)


#: What :meth:`str` of a film holds where :func:`_develop_rows` is ``HDRFilm::develop``.
_RGB_FILM = ("HDRFilm[", "pixel_format = rgb,")


def _develop_rows(raw: np.ndarray) -> np.ndarray:
    """``HDRFilm::develop`` (``src/films/hdrfilm.cpp``) of rows of an RGB film's raw storage
    ``(..., R G B W AOVs)``: every channel but the weight W, divided in float32 by W where it is
    not 0 (by 1 where it is), as a new array."""
    weight = raw[..., 3:4]
    values = np.concatenate([raw[..., :3], raw[..., 4:]], axis=-1)
    values /= np.where(weight == 0, np.float32(1), weight)
    return values


def _row_blocks(image: np.ndarray) -> Iterator[slice]:
    """Rows of *image* ``(H, W, C)`` in blocks of about 2**20 values (the float64 sums of a
    block, 8 MiB, are small beside a wide film)."""
    step = max(1, 2**20 // max(1, image[0].size))
    return (slice(start, start + step) for start in range(0, image.shape[0], step))


def _develops_raw(film: Any, image: Any) -> bool:
    """Whether *film*'s raw storage gives its developed *image* (evaluated) through
    :func:`_develop_rows`, bit for bit, compared a block of rows at a time (no third film)."""
    if not all(key in str(film) for key in _RGB_FILM):
        return False
    raw = film.develop(raw=True)
    view, developed = raw.numpy(), image.numpy()
    if view.shape != (*developed.shape[:2], developed.shape[2] + 1):
        return False
    return all(
        np.array_equal(_develop_rows(view[rows]).view(np.uint32), developed[rows].view(np.uint32))
        for rows in _row_blocks(developed)
    )


def _render_part(
    mi: Any, dr: Any, loaded: Any, count: int, seed: int, integrator: Any, *, check: bool
) -> tuple[np.ndarray, bool]:
    """One part's film as a float32 copy, at a peak of two films (not four): the film's
    storage is given back once its developed tensor is evaluated, the tensor once copied
    (with every band-path channel, each is the size of the image; Dr.Jit's allocation cache
    would keep them resident); and, with *check*, whether the storage develops to it
    (:func:`_develops_raw`, before the storage is given back)."""
    film = loaded.sensors()[0].film()
    with _threads(dr, film, count):
        image = mi.render(loaded, spp=count, seed=seed, integrator=integrator)
        dr.eval(image)  # in this thread count
    raw_ok = check and _develops_raw(film, image)
    film.prepare([])  # its storage swapped for one without AOVs
    dr.flush_malloc_cache()
    part: np.ndarray = np.array(image, dtype=np.float32)
    del image
    dr.flush_malloc_cache()
    return part, raw_ok


def _merge_last_part(
    dr: Any,
    loaded: Any,
    parts: list[np.ndarray],
    counts: tuple[int, ...],
    seed: int,
    integrator: Any,
) -> np.ndarray:
    """The last part rendered as ``mi.render`` does but left undeveloped, and the weighted mean
    taken over the other *parts* (of *counts*) with that part's rows developed from the film's storage
    (:func:`_develop_rows`): two films at the peak (the first part and the storage), not three
    (the held parts beside the storage and the developed tensor)."""
    sensor = loaded.sensors()[0]
    film = sensor.film()
    count = counts[-1]
    with _threads(dr, film, count), dr.suspend_grad():
        chosen = loaded.integrator() if integrator is None else integrator
        chosen.render(loaded, sensor, seed=seed, spp=count, develop=False, evaluate=True)
    sensor.sampler().seed(0, 1)  # as mi.render leaves it: its per-lane state given back
    raw = film.develop(raw=True)
    out = _weighted_mean(parts, counts, raw.numpy())
    del raw
    film.prepare([])
    dr.flush_malloc_cache()
    return out


def _weighted_mean(
    parts: list[np.ndarray], counts: tuple[int, ...], raw: np.ndarray | None = None
) -> np.ndarray:
    """``Σ_i counts_i · parts_i / Σ counts`` in float64, in part order, as float32, written
    over the first part a block of rows at a time (no float64 copy of the whole film); with
    *raw*, the last part's rows are developed from that film storage (:func:`_develop_rows`)."""
    out, spp = parts[0], sum(counts)
    for rows in _row_blocks(out):
        blocks = [part[rows] for part in parts]
        blocks += [] if raw is None else [_develop_rows(raw[rows])]
        total = np.multiply(blocks[0], counts[0], dtype=np.float64)
        for block, count in zip(blocks[1:], counts[1:], strict=True):
            total += np.multiply(block, count, dtype=np.float64)
        total /= spp
        out[rows] = total
    return out


def split_render(
    mi: Any, loaded: Any, *, spp: int, seed: int, integrator: Any = None
) -> np.ndarray:
    """``mi.render`` of *spp* samples per pixel, as float32, in the parts of
    :func:`sample_splits` on an LLVM variant (module docstring); one plain call on the other
    variants (scalar: one thread per image block; CUDA: not covered)."""
    if not mi.variant().startswith("llvm"):
        image = mi.render(loaded, spp=spp, seed=seed, integrator=integrator)
        return np.array(image, dtype=np.float32)
    import drjit as dr

    counts = sample_splits(spp)
    seeds = part_seeds(seed, len(counts))
    parts: list[np.ndarray] = []
    raw_ok = False  # whether the first part's storage develops as Mitsuba's film does
    for i, (count, part_seed) in enumerate(zip(counts[:-1], seeds[:-1], strict=True)):
        part, ok = _render_part(mi, dr, loaded, count, part_seed, integrator, check=i == 0)
        parts.append(part)
        raw_ok = raw_ok or ok
    if raw_ok:  # the last part's rows developed from its storage into the mean
        return _merge_last_part(dr, loaded, parts, counts, seeds[-1], integrator)
    parts.append(_render_part(mi, dr, loaded, counts[-1], seeds[-1], integrator, check=False)[0])
    # one part: x * spp / spp in float64 is x, the float32 film as it is
    return parts[0] if len(parts) == 1 else _weighted_mean(parts, counts)
