"""Choose the bundled decomposers' parameters by hold-one-out over the rendered objects.

Usage: python -P scripts/choose_parameters.py DATASET OUT.json [retinex|names-shades ...]
       python -P scripts/choose_parameters.py --mit scripts/mit_ablation.json
       (names-shades' choice on the MIT development half, from the ablation's run of record)

The protocol is :mod:`spectrinsic.decompose.methods.protocol`; the grids are below. The chosen values
are copied by hand into the decomposers' defaults (PROTOCOL in retinex.py and names_shades.py);
the run of record, per grid point and sample, is scripts/choose_parameters.json.

Names-and-shades: the run of record here (gamma_over_alpha 10, mu 1/3, grey-world; 0.0600,
held-out 0.0612) predates the RAD ridges and is no longer what sets its defaults. They are now
chosen on the MIT development half by scripts/mit_ablation.py (``--merge`` prints the choice:
RAD cut at 45 degrees, gamma 3, gamma_over_alpha 100, region means, split by ridge, grey-world;
LMSE 0.0296, held-out 0.0448, 8 of 10 objects below reflectance = image; ``--mit`` prints it
again from that run of record). The rendered-set names-shades grid below runs at the current
defaults for the other parameters; its printed numbers are those of a fresh run, not of the
json, until the rendered set is scored again.
"""

from __future__ import annotations

import json
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from spectrinsic.decompose.evaluation.sample_fields import evaluation_mask, input_image
from spectrinsic.decompose.methods.constancy import with_constancy
from spectrinsic.decompose.methods.names_shades import NamesAndShades
from spectrinsic.decompose.methods.protocol import hold_one_out, scene_group, score_grid
from spectrinsic.decompose.methods.retinex import ColourRetinex
from spectrinsic.gt_export.sample import sample_dirs
from spectrinsic.gt_export.dataset.loader import load_sample

LAYERS = ["image", "image_denoised", "reflectance", "shading", "shading_grey", "mask",
          "object_id", "material_id"]
CONSTANCY = ["none", "grey-world", "shades-of-grey", "max-rgb"]
#: Grosse et al.'s grid for both thresholds, logspace(-1.5, 0, 5).
RETINEX_THRESHOLDS = [round(float(v), 4) for v in np.logspace(-1.5, 0.0, 5)]
GRIDS = {
    "retinex": (ColourRetinex, {"threshold_grey": RETINEX_THRESHOLDS,
                                "threshold_colour": RETINEX_THRESHOLDS}),
    "names-shades": (NamesAndShades, {"gamma_over_alpha": [10.0, 100.0],
                                      "mu": [1.0 / 3.0, 0.5]}),
}
#: Applied after each decomposition (with_constancy), so not decomposed again.
POST_GRID = {"colour_constancy": CONSTANCY}


def samples(dataset: Path):
    out = []
    for folder in sample_dirs(dataset):
        if not folder.name.startswith("obj-"):
            continue
        listed = json.loads((folder / "meta.json").read_text())["layers"]
        s = load_sample(folder, layers=[k for k in LAYERS if k in listed])
        out.append((folder.name, s, input_image(s)[1], evaluation_mask(s)))
    return out


def mit_choice(record: Path) -> int:
    """Print names-shades' MIT choice (scripts/mit_ablation.py's protocol) from its record."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("mit_ablation",
                                                  Path(__file__).with_name("mit_ablation.py"))
    ablation = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ablation)
    scores = json.loads(record.read_text())["scores"]
    choice = ablation.choose(scores)
    base = scores["image-as-reflectance"]
    per = scores[ablation.key(choice["chosen"])]
    wins = sum(v["lmse"] < base[o]["lmse"] for o, v in per.items())
    print("names-shades (MIT development half)", choice["chosen"],
          f"all {choice['chosen_lmse']:.4f}", f"held-out {choice['held_out_lmse']:.4f}",
          f"beats image-as-reflectance on {wins}/{len(per)}", flush=True)
    return 0


def main(argv: list[str]) -> int:
    warnings.simplefilter("ignore")
    if argv[0] == "--mit":
        return mit_choice(Path(argv[1]))
    dataset, target = Path(argv[0]), Path(argv[1])
    which = argv[2:] or list(GRIDS)
    data = samples(dataset)
    groups = {sid: scene_group(sid) for sid, *_ in data}
    report = json.loads(target.read_text()) if target.exists() else {}
    for name in which:
        make, grid = GRIDS[name]
        t0 = time.perf_counter()
        table = score_grid(data, make, grid, post_grid=POST_GRID, post=with_constancy)
        res = hold_one_out(table, groups)
        report[name] = {
            "grid": {**grid, **POST_GRID}, "samples": len(data), "groups": sorted(set(groups.values())),
            "chosen": dict(res.chosen), "chosen_score": res.chosen_score,
            "held_out_score": res.held_out_score,
            "folds": [{"held_out": f.held_out, "chosen": dict(f.chosen), "score": f.score}
                      for f in res.folds],
            "table": {json.dumps(dict(p)): v for p, v in table.items()},
            "seconds": round(time.perf_counter() - t0, 1),
        }
        target.write_text(json.dumps(report, indent=1))
        print(name, dict(res.chosen), f"all {res.chosen_score:.4f}",
              f"held-out {res.held_out_score:.4f}", f"{time.perf_counter() - t0:.0f}s", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
