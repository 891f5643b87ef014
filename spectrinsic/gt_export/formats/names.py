"""File-name-safe names: the one slug of spectrinsic's file and scenario names.

Used for camera layer files (``camera-nikon-5100-npl``), camera scenarios of the evaluation
(``SC4_nikon-5100-npl``) and the gallery's per-condition contact sheets.
"""

from __future__ import annotations

import re

__all__ = ["slug", "camera_slug"]

_NOT_SLUG = re.compile(r"[^a-z0-9]+")


def slug(text: str, *, fallback: str = "") -> str:
    """Lower-case *text*, each run of characters other than ``a-z0-9`` replaced by ``-``, no
    leading or trailing ``-``; *fallback* when nothing is left.

    >>> slug("Nikon 5100 (NPL)"), slug("two-colour-a"), slug("(!)", fallback="none")
    ('nikon-5100-npl', 'two-colour-a', 'none')
    """
    return _NOT_SLUG.sub("-", text.lower()).strip("-") or fallback


def camera_slug(name: str) -> str:
    """Slug of a camera sensor set, with or without its family prefix: ``"camera:Nikon 5100
    (NPL)"`` and ``"Nikon 5100 (NPL)"`` both give ``"nikon-5100-npl"`` (``"camera"`` if empty).
    """
    return slug(name.split(":", 1)[-1], fallback="camera")
