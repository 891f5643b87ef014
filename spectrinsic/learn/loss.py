"""The scale-invariant log loss.

Eigen, Puhrsch and Fergus, "Depth map prediction from a single image using a multi-scale deep
network", NIPS 2014, Eq. 4: with ``d_i = y_i - y*_i`` the difference of predicted and true logs
over the ``n`` valid values,

    D(y, y*) = (1/n) Σ d_i² - (λ/n²) (Σ d_i)²,

which for λ = 1 is blind to a global scale of the prediction (the mean of ``d`` is removed) and
for λ = 0.5 is the compromise Eigen et al. train with. Narihira, Maire and Yu, "Direct
intrinsics", ICCV 2015, train reflectance and shading with it (λ = 0.5), and Li and Snavely,
"CGIntrinsics", ECCV 2018, with its λ = 1 form (one least-squares scale per image); reflectance
and shading are each known only up to scale, so a scale-blind loss is the fair one.
"""

from __future__ import annotations

from typing import Any

__all__ = ["LAMBDA", "scale_invariant_loss"]

#: Eigen et al.'s λ (and Narihira et al.'s): half of the mean log difference is forgiven.
LAMBDA = 0.5


def scale_invariant_loss(pred: Any, target: Any, mask: Any, lam: float = LAMBDA) -> Any:
    """Eigen et al. 2014 Eq. 4, per image over the masked pixels and all channels, averaged
    over the batch.

    Parameters
    ----------
    pred, target
        ``(B, C, H, W)`` torch tensors of logs (natural log of linear values).
    mask
        ``(B, 1, H, W)`` bool or 0/1 tensor of the valid pixels.
    lam
        λ of Eq. 4 (1: fully scale-invariant).
    """
    weight = mask.to(pred.dtype).expand_as(pred)
    d = (pred - target) * weight
    n = weight.flatten(1).sum(1).clamp(min=1.0)
    sum_sq = (d * d).flatten(1).sum(1)
    total = d.flatten(1).sum(1)
    return (sum_sq / n - lam * (total / n) ** 2).mean()
