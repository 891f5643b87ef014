"""A guard against collapsed decompositions: the shading took the image's sharp texture.

A decomposition has collapsed when the image has sharp, high-contrast edges
(:func:`spectrinsic.decompose.methods.sharp_edges.sharp_contrast_edges`, whatever their colour
names), at least :data:`MIN_EDGES` of them, and the reflectance carries less than a tenth
(:data:`ALMOST_NONE`) of their log-luminance step: the reflectance is almost flat where the
image has strong edges, which is the same as a shading that reproduces the image's texture
(``log I = log R + log S`` on every edge). By the Retinex cue (thesis sec. 2.2.1) sharp steps
are reflectance except at cast shadows and creases, so a sound decomposition keeps a good part
of them in the reflectance; on the MIT development half the ground truth itself keeps 0.32
(frog1, 251 such edges, deep creases) to 0.99 (teabag1, 1787) of it where there are at least
:data:`MIN_EDGES`, so a tenth is far from a true decomposition there (the value is "almost
none", not fitted). :data:`MIN_EDGES` is the perimeter of one window of the
benchmark's local error (20 pixels, Grosse et al.): fewer sharp edges are isolated pixels
(noise in the dark), not a texture.

:class:`CollapseCheck` is recorded in the method's diagnostics (``info["collapse"]``) with
what was done about it (:data:`ACTIONS`).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..decomposition import Decomposition
from .coherence import grid_edges
from .sharp_edges import log_luminance, sharp_contrast_edges

__all__ = [
    "ACTIONS",
    "ALMOST_NONE",
    "MIN_EDGES",
    "CollapseCheck",
    "check_collapse",
    "guard_collapse",
]

logger = logging.getLogger(__name__)

#: What the guard did: nothing (no collapse), re-solved with every sharp high-contrast edge as
#: Case A, or fell back to another method after the re-solve collapsed too.
ACTIONS = ("none", "re-solved", "fallback")
#: Share of the image's sharp step below which the reflectance has collapsed ("almost none").
ALMOST_NONE = 0.1
#: Fewest sharp, high-contrast edges that make a texture (the perimeter of a 20-pixel window).
MIN_EDGES = 80


@dataclass(frozen=True)
class CollapseCheck:
    """Whether a reflectance has collapsed (module docstring).

    Attributes
    ----------
    sharp_edges
        Number of the image's sharp, high-contrast 4-neighbour edges inside the mask.
    reflectance_share
        ``sum |d log R| / sum |d log I|`` over those edges (grey log luminance; 1 when there
        are none): the share of the image's sharp contrast the reflectance carries.
    collapsed
        ``reflectance_share <`` :data:`ALMOST_NONE` on at least :data:`MIN_EDGES` edges.
    """

    sharp_edges: int
    reflectance_share: float
    collapsed: bool

    def info(self, action: str, detail: str = "") -> dict[str, object]:
        """JSON-ready diagnostics with the guard's *action* (one of :data:`ACTIONS`)."""
        out: dict[str, object] = {
            "sharp_edges": self.sharp_edges,
            "reflectance_share": round(self.reflectance_share, 4),
            "collapsed": self.collapsed,
            "action": action,
        }
        return {**out, "detail": detail} if detail else out


def check_collapse(image: np.ndarray, reflectance: np.ndarray, mask: np.ndarray) -> CollapseCheck:
    """:class:`CollapseCheck` of a ``(H, W, 3)`` *reflectance* estimated from *image*.

    >>> x = np.tile(np.array([0.8, 0.05] * 8), (16, 1))
    >>> image = np.repeat(x[:, :, None], 3, axis=2)
    >>> mask = np.ones(x.shape, bool)
    >>> check_collapse(image, image, mask).collapsed
    False
    >>> check_collapse(image, np.ones_like(image), mask).collapsed
    True
    """
    _, flat = grid_edges(mask)
    log_image = log_luminance(image, mask)
    strong = sharp_contrast_edges(log_image, flat, mask)
    if not strong.any():
        return CollapseCheck(0, 1.0, False)
    log_refl = np.log(np.maximum(np.asarray(reflectance, np.float64).mean(axis=2), 1e-12))
    a, b = flat[strong, 0], flat[strong, 1]
    image_step = np.abs(log_image.ravel()[b] - log_image.ravel()[a]).sum()
    refl_step = np.abs(log_refl.ravel()[b] - log_refl.ravel()[a]).sum()
    share = float(refl_step / image_step)
    count = int(strong.sum())
    return CollapseCheck(count, share, count >= MIN_EDGES and share < ALMOST_NONE)


def guard_collapse(
    first: Decomposition,
    image: np.ndarray,
    mask: np.ndarray,
    resolve: Callable[[], Decomposition],
    fallback: tuple[str, Callable[[], Decomposition]],
) -> Decomposition:
    """*first* if it has not collapsed, else *resolve()*'s result if that has not, else the
    *fallback* method's; ``info["collapse"]`` says which (:meth:`CollapseCheck.info`).

    Parameters
    ----------
    first
        The decomposition of ``(H, W, 3)`` *image* over ``(H, W)`` bool *mask*.
    resolve
        The same method re-run with every sharp, high-contrast edge as a reflectance edge.
    fallback
        Name and call of the method used when the re-solve collapses too.
    """
    check = check_collapse(image, first.reflectance, mask)
    if not check.collapsed:
        first.info["collapse"] = check.info("none")
        return first
    second = resolve()
    again = check_collapse(image, second.reflectance, mask)
    detail = f"reflectance share {check.reflectance_share:.3f} < {ALMOST_NONE}"
    if not again.collapsed:
        logger.info("collapse: %s; re-solved (share %.3f)", detail, again.reflectance_share)
        second.info["collapse"] = check.info(
            "re-solved",
            f"{detail}; re-solved with every sharp edge as Case A, "
            f"share {again.reflectance_share:.3f}",
        )
        return second
    name, run = fallback
    logger.info(
        "collapse: %s, and %.3f re-solved; fell back to %s", detail, again.reflectance_share, name
    )
    third = run()
    third.info["collapse"] = check.info(
        "fallback", f"{detail}, {again.reflectance_share:.3f} re-solved; fell back to {name}"
    )
    return third
