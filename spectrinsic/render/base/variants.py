"""Choosing a Mitsuba variant (Mitsuba is imported through
:func:`spectrinsic.mitsuba_import.import_mitsuba`, which says why and how it picks a
``libLLVM``). Without a suitable ``libLLVM`` the LLVM variants are not used: renders fall back to
the (about twice slower) scalar variants with one :class:`~spectrinsic.errors.SpectrinsicWarning`.

Variants are chosen per pass (cuda > llvm > scalar; ``*_spectral`` for the spectral reference,
``*_rgb`` for diagonal passes and AOVs) and activated only inside :func:`variant_scope`; nothing
here runs at import time.
"""

from __future__ import annotations

import contextlib
import logging
import warnings
from collections.abc import Iterator
from types import ModuleType
from typing import Any, Literal

from ...errors import RenderError, SpectrinsicWarning, validate_choice
from ...mitsuba_import import (
    LLVM_ENV,
    LLVM_MIN_VERSION,
    import_mitsuba,
    llvm_version_from_name,
    loaded_libllvm,
)

__all__ = [
    "BACKENDS",
    "VariantKind",
    "import_mitsuba",
    "set_thread_count",
    "usable_backends",
    "choose_variant",
    "available_variants",
    "llvm_library",
    "variant_report",
    "variant_scope",
]

logger = logging.getLogger(__name__)

#: Dr.Jit backends in order of preference, with the prefix of their Mitsuba variants.
BACKENDS: dict[str, str] = {"cuda": "cuda_ad", "llvm": "llvm_ad", "scalar": "scalar"}

VariantKind = Literal["rgb", "spectral"]


def set_thread_count(n: int | None) -> None:
    """Limit Dr.Jit's thread pool in this process to *n* threads (``None``: leave it).

    With several worker processes on one machine, one pool per process sized to its share of
    the cores avoids oversubscription.
    """
    if n is None:
        return
    import_mitsuba()  # points Dr.Jit at a suitable libLLVM before drjit is first imported
    import drjit

    if drjit.thread_count() != n:
        drjit.set_thread_count(n)


def _llvm_suitable() -> bool:
    """Whether Dr.Jit loaded a ``libLLVM`` that can run spectrinsic's kernels."""
    import_mitsuba()
    path = loaded_libllvm()
    if not path:
        return False  # Dr.Jit would pick whatever libLLVM it finds: possibly 14/15, which crash
    version = llvm_version_from_name(path)  # an unversioned path set by the user is trusted
    return version is None or version >= LLVM_MIN_VERSION


def usable_backends() -> tuple[str, ...]:
    """Dr.Jit backends that can render here, best first (always ends with ``"scalar"``)."""
    import_mitsuba()
    import drjit as dr

    found = []
    if dr.has_backend(dr.JitBackend.CUDA):
        found.append("cuda")
    if _llvm_suitable() and dr.has_backend(dr.JitBackend.LLVM):
        found.append("llvm")
    found.append("scalar")
    return tuple(found)


def choose_variant(kind: VariantKind, requested: str | None = None) -> str:
    """The Mitsuba variant for a pass of *kind* (``"rgb"`` or ``"spectral"``).

    Parameters
    ----------
    kind
        ``"spectral"`` for the spectral reference, ``"rgb"`` for diagonal passes and AOVs.
    requested
        A backend (``"cuda"``, ``"llvm"``, ``"scalar"``) or any variant name, whose backend is
        used (``"llvm_ad_rgb"`` also selects ``llvm_ad_spectral`` for spectral passes).
        ``None``: the best usable backend, cuda > llvm > scalar.

    Raises
    ------
    RenderError
        If the requested backend cannot run here or Mitsuba lacks the variant.
    """
    validate_choice(kind, ("rgb", "spectral"), "variant kind", error=RenderError)
    mi = import_mitsuba()
    usable = usable_backends()
    if requested is not None:
        # "llvm" of "llvm", "llvm_ad_rgb" or "llvm_ad_spectral"; likewise cuda and scalar
        backend = validate_choice(
            requested.split("_", 1)[0], BACKENDS, "Mitsuba backend", error=RenderError
        )
        if backend not in usable:
            raise RenderError(
                f"Mitsuba backend {backend!r} (from {requested!r}) is not usable here; usable: "
                f"{', '.join(usable)}"
            )
    else:
        backend = usable[0]
        if backend == "scalar":
            warnings.warn(
                f"no libLLVM >= {LLVM_MIN_VERSION} found (set {LLVM_ENV}); rendering with Mitsuba's "
                "scalar variants, about twice slower",
                SpectrinsicWarning,
                stacklevel=2,
            )
    variant = f"{BACKENDS[backend]}_{kind}"
    if variant not in mi.variants():
        raise RenderError(
            f"this Mitsuba build lacks variant {variant!r}; it has {', '.join(mi.variants())}"
        )
    return variant


def llvm_library() -> str | None:
    """Path of the ``libLLVM`` Dr.Jit's LLVM backend uses, or ``None`` if none is suitable."""
    return loaded_libllvm() if _llvm_suitable() else None


def available_variants() -> list[str]:
    """Mitsuba variants usable here for spectrinsic's passes, best backend first
    (e.g. ``["llvm_ad_rgb", "llvm_ad_spectral", "scalar_rgb", "scalar_spectral"]``)."""
    mi = import_mitsuba()
    compiled = set(mi.variants())
    return [
        f"{BACKENDS[b]}_{kind}"
        for b in usable_backends()
        for kind in ("rgb", "spectral")
        if f"{BACKENDS[b]}_{kind}" in compiled
    ]


def variant_report() -> dict[str, Any]:
    """Versions, compiled and usable variants, the LLVM library and the variants chosen by default."""
    mi = import_mitsuba()
    import drjit as dr

    usable = usable_backends()
    prefix = BACKENDS[usable[0]]
    return {
        "mitsuba": mi.__version__,
        "drjit": getattr(dr, "__version__", "unknown"),
        "compiled": list(mi.variants()),
        "usable": available_variants(),
        "libllvm": llvm_library(),
        "backends": list(usable),
        "rgb": f"{prefix}_rgb",
        "spectral": f"{prefix}_spectral",
    }


@contextlib.contextmanager
def variant_scope(variant: str, *, restore: bool = True) -> Iterator[ModuleType]:
    """Make *variant* Mitsuba's active variant inside a ``with`` block; yields ``mitsuba``.

    On leaving the block, normally or by an exception, the variant that was active before it
    is active again (nested scopes unwind in order). With ``restore=False`` *variant* stays
    active: every switch reloads Mitsuba's Python modules (0.25 s on 2 cores), and a caller
    that sets the variant it needs at each of its scopes (the render pipeline) need not pay
    for switching back.

    One case cannot be undone: Mitsuba 3.9 keeps its current variant in C++ state that only
    ``set_variant(name)`` replaces (``set_variant(None)`` raises ``TypeError``), so there is no
    way back to "no variant". When no variant was active before the block, *variant* stays
    active after it: ``mi.variant()`` returns it until another variant is set. This happens
    at most once per process, at the first scope; spectrinsic sets variants nowhere else but
    in :mod:`spectrinsic.scenes.mitsuba_tree`, which needs some variant (``scalar_rgb``) to read a
    parsed XML scene's transforms when none is active.
    """
    mi = import_mitsuba()
    previous = mi.variant()
    mi.set_variant(variant)
    try:
        yield mi
    finally:
        if restore and previous is not None:
            mi.set_variant(previous)
