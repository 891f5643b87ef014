"""The controls of docs/sim2real.md: MIT LMSE of the untrained U-Net (seeds 0-2) and of the
split R = S = sqrt(I), which the geometric mean of the unet decomposer reduces to when the
network's heads carry no information. Run: python -P scripts/sim2real_controls.py MIT_DIR."""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np
import torch

from spectrinsic.decompose.decomposition import finish, prepare_input
from spectrinsic.decompose.evaluation.mit import load_mit_object, mit_measures
from spectrinsic.decompose.methods.unet import UNetDecomposer
from spectrinsic.learn.unet import FORMAT, UNetConfig, make_unet


def sqrt_split(image, mask=None):
    img, m = prepare_input(image, mask)
    return finish(img, np.sqrt(img), m, {})


def main(mit_dir: Path) -> None:
    objects = [load_mit_object(p) for p in sorted(mit_dir.glob("*.npz"))]
    torch.set_num_threads(1)
    with tempfile.TemporaryDirectory() as tmp:
        for seed in (0, 1, 2):
            torch.manual_seed(seed)
            net = make_unet(UNetConfig())
            path = Path(tmp) / f"untrained{seed}.pt"
            record = {
                "format": FORMAT,
                "net": UNetConfig().to_dict(),
                "state_dict": net.state_dict(),
            }
            torch.save(record, path)
            unet = UNetDecomposer(str(path))
            lmse = np.mean([mit_measures(o, unet(o.image, o.mask))["lmse"] for o in objects])
            print(f"untrained U-Net, seed {seed}: MIT LMSE {lmse:.4f}")
    lmse = np.mean([mit_measures(o, sqrt_split(o.image, o.mask))["lmse"] for o in objects])
    print(f"R = S = sqrt(I): MIT LMSE {lmse:.4f}")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: python -P scripts/sim2real_controls.py MIT_DIR")
    main(Path(sys.argv[1]))
