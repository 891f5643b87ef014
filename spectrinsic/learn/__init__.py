"""A reference network trained on spectrinsic data: a small U-Net predicting log reflectance and
log shading from the log image (:mod:`.unet`), its scale-invariant loss (:mod:`.loss`), the
training data (:mod:`.data`), the training loop with checkpoints (:mod:`.train`), its outputs
(:mod:`.card`) and inference (:mod:`.infer`).

PyTorch is the optional ``torch`` extra: every module imports it inside the functions that need
it (:func:`.torch_import.require_torch`), so importing this package never imports torch.
"""

from __future__ import annotations

__all__: list[str] = []
