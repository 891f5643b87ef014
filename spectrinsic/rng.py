"""Seeds. Randomness is always an explicit seed or ``numpy.random.Generator``; never a default.

Per-item seeds (one per sample, scene or draw) come from :func:`seed_from_key`: a hash of the
root seed and the item's name, so an item's seed does not depend on which other items exist or
in which order they are built.
"""

from __future__ import annotations

import hashlib

import numpy as np

__all__ = ["seed_from_key", "generator"]


def seed_from_key(root: int, key: str) -> int:
    """A 32-bit seed for a named item (e.g. a sample id), stable across runs and orderings.

    >>> seed_from_key(0, "obj-vase__v0__white") == seed_from_key(0, "obj-vase__v0__white")
    True
    >>> 0 <= seed_from_key(0, "a") < 2**32, seed_from_key(0, "a") != seed_from_key(1, "a")
    (True, True)
    """
    digest = hashlib.sha256(f"{root}:{key}".encode()).digest()
    return int.from_bytes(digest[:4], "little")


def generator(seed: int | np.random.Generator) -> np.random.Generator:
    """Return a Generator for *seed*, passing an existing Generator through."""
    if isinstance(seed, np.random.Generator):
        return seed
    return np.random.default_rng(seed)
