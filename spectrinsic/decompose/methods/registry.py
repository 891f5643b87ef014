"""Registry of the decomposers, with validated dispatch and a plugin hook.

Bundled methods are in :data:`DECOMPOSERS`. An installed package adds its own through the
entry-point group :data:`ENTRY_POINT_GROUP`: in its ``pyproject.toml``::

    [project.entry-points."spectrinsic.decomposers"]
    my-method = "my_package.module:MyDecomposer"

A method with a file argument is named ``NAME:ARGUMENT``: ``unet:WEIGHTS`` is the U-Net
of ``spectrinsic train`` with its ``weights.pt`` (:data:`FILE_DECOMPOSERS`).

The entry point's name is the method's name in the registry and the tables; the object it loads
is a factory: called with keyword parameters (none for the defaults) it returns a decomposer,
``decomposer(image, mask=None) -> Decomposition``
(:class:`spectrinsic.decompose.decomposition.Decomposer`). A frozen dataclass like the bundled
ones works as is. :func:`available_decomposers` lists both, bundled first.
"""

from __future__ import annotations

import inspect
import logging
from collections.abc import Callable, Mapping
from importlib import metadata
from typing import Any

import numpy.typing as npt

from ...errors import DecomposeError, SpectrinsicError, did_you_mean, validate_choice
from ..decomposition import Decomposer, Decomposition
from .baselines import ImageAsReflectance, ImageAsShading
from .names_shades import NamesAndShades
from .retinex import ColourRetinex
from .unet import UNetDecomposer

__all__ = [
    "DECOMPOSERS",
    "FILE_DECOMPOSERS",
    "ENTRY_POINT_GROUP",
    "PluginError",
    "available_decomposers",
    "plugin_decomposers",
    "get_decomposer",
    "decompose",
]

logger = logging.getLogger(__name__)

#: Name -> factory (keyword parameters -> decomposer), in the order tables list them.
DECOMPOSERS: Mapping[str, Callable[..., Any]] = {
    "names-shades": NamesAndShades,
    "colour-retinex": ColourRetinex,
    "image-as-reflectance": ImageAsReflectance,
    "image-as-shading": ImageAsShading,
}

#: Name -> factory of one file argument, used as ``NAME:FILE`` (not in the default methods:
#: they need their file).
FILE_DECOMPOSERS: Mapping[str, Callable[[str], Any]] = {"unet": UNetDecomposer}

#: Entry-point group through which installed packages add decomposers.
ENTRY_POINT_GROUP = "spectrinsic.decomposers"


class PluginError(SpectrinsicError, RuntimeError):
    """A ``spectrinsic.decomposers`` entry point that cannot be loaded or is not a factory."""


def plugin_decomposers() -> dict[str, Callable[..., Any]]:
    """Factories registered by installed packages under :data:`ENTRY_POINT_GROUP`.

    Raises :class:`PluginError` for an entry point that fails to import, is not callable, or
    reuses a bundled method's name.
    """
    found: dict[str, Callable[..., Any]] = {}
    for ep in sorted(metadata.entry_points(group=ENTRY_POINT_GROUP), key=lambda e: e.name):
        if ep.name in DECOMPOSERS:
            raise PluginError(
                f"entry point {ep.name!r} ({ep.value}) in {ENTRY_POINT_GROUP!r} reuses the name "
                f"of a bundled decomposer; choose another name"
            )
        try:
            factory = ep.load()
        except Exception as exc:  # any import failure of third-party code
            raise PluginError(
                f"entry point {ep.name!r} ({ep.value}) in {ENTRY_POINT_GROUP!r} cannot be "
                f"loaded: {type(exc).__name__}: {exc}"
            ) from exc
        if not callable(factory):
            raise PluginError(
                f"entry point {ep.name!r} ({ep.value}) must load a callable factory of "
                f"decomposers; got {type(factory).__name__}"
            )
        found[ep.name] = factory
        logger.debug("decomposer plugin %s from %s", ep.name, ep.value)
    return found


def available_decomposers() -> dict[str, Callable[..., Any]]:
    """Bundled decomposers, then the installed plugins (read afresh at each call)."""
    return {**DECOMPOSERS, **plugin_decomposers()}


def _check_parameters(name: str, factory: Callable[..., Any], params: Mapping[str, Any]) -> None:
    """Raise :class:`DecomposeError` naming any of *params* that *factory* does not take.

    Factories whose signature cannot be read, or that take ``**kwargs``, are not checked.
    """
    try:
        signature = inspect.signature(factory)
    except (TypeError, ValueError):  # some builtins and extension types have none
        return
    accepted = [
        p.name
        for p in signature.parameters.values()
        if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)
    ]
    if any(p.kind is p.VAR_KEYWORD for p in signature.parameters.values()):
        return
    unknown = [k for k in params if k not in accepted]
    if unknown:
        bad = unknown[0]
        raise DecomposeError(
            f"decomposer {name!r} has no parameter {bad!r}"
            + (f" (nor {', '.join(map(repr, unknown[1:]))})" if len(unknown) > 1 else "")
            + f"; it accepts {', '.join(map(repr, accepted)) or 'none'}"
            + did_you_mean(bad, accepted)
        )


def get_decomposer(name: str, **params: Any) -> Decomposer:
    """The decomposer called *name* (bundled or plugin), built with keyword *params*.

    Raises
    ------
    DecomposeError
        For an unknown *name* (with the known ones), or a parameter the decomposer does not
        take (with the ones it does).
    """
    base, sep, argument = name.partition(":")
    if sep and base in FILE_DECOMPOSERS:
        if not argument or params:
            raise DecomposeError(
                f"decomposer {name!r}: expected {base}:FILE with a file and no other parameter"
            )
        return FILE_DECOMPOSERS[base](argument)  # type: ignore[no-any-return]
    if name in FILE_DECOMPOSERS:
        raise DecomposeError(f"decomposer {name!r} needs its file: {name}:FILE")
    factories = DECOMPOSERS if name in DECOMPOSERS else available_decomposers()
    factory = factories[validate_choice(name, factories, "decomposer", error=DecomposeError)]
    _check_parameters(name, factory, params)
    decomposer = factory(**params)
    if not callable(decomposer):
        raise PluginError(
            f"decomposer {name!r}: its factory returned a non-callable {type(decomposer).__name__}"
        )
    return decomposer


def decompose(
    image: npt.ArrayLike, mask: npt.ArrayLike | None = None, *, method: str, **params: Any
) -> Decomposition:
    """Decompose a linear ``(H, W, 3)`` image with the registered *method*."""
    return get_decomposer(method, **params)(image, mask)
