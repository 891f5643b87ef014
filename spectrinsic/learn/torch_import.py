"""The one import of PyTorch for the learning modules, behind a one-line error."""

from __future__ import annotations

from typing import Any

from ..errors import MissingDependencyError

__all__ = ["require_torch"]


def require_torch(what: str) -> Any:
    """The ``torch`` module, or :class:`MissingDependencyError` naming *what* needs it."""
    try:
        import torch
    except ImportError as exc:
        raise MissingDependencyError(
            f"{what} needs PyTorch, which is not installed: pip install 'spectrinsic[torch]'"
        ) from exc
    return torch
