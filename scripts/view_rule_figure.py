"""Figure of the view rule's measurements (docs/figures/view-rule-rooms.png).

For each of N generated rooms (root seed 11), the first camera the generator draws that sees
enough furniture is judged *before* the rule re-draws it: the four measurements against their
thresholds, and the share that passes. Run: ``python scripts/view_rule_figure.py [N] [OUT]``
(about 1 s per room on one core, plus the rule's re-draws).
"""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from spectrinsic.scenes.generators import GENERATORS, GeneratorOptions, generate
from spectrinsic.scenes.generators import view_rule as vr


def _first_views(n: int) -> list[vr.ViewJudgement]:
    """Judgements of each room's first camera: the rooms layout drawn with its rule off."""
    options = GeneratorOptions(width=64, height=48)
    rooms = GENERATORS["rooms"]
    GENERATORS["rooms"] = lambda rng, opts: replace(rooms(rng, opts), view_rule=False)
    try:
        scenes = [
            generate("rooms", root_seed=11, index=i, view=0, options=options) for i in range(n)
        ]
    finally:
        GENERATORS["rooms"] = rooms
    return [vr.judge_view(s.meshes, s.lights, s.camera) for s in scenes]


def main(n: int = 200, out: str = "docs/figures/view-rule-rooms.png") -> None:
    from matplotlib.figure import Figure

    js = _first_views(n)
    passed = sum(j.ok for j in js)
    panels = [
        (
            "largest material share of the frame",
            [j.max_material_share for j in js],
            vr.MAX_SHARE,
            "max",
        ),
        ("materials over 2 % of the frame", [j.n_materials for j in js], vr.MIN_MATERIALS, "min"),
        ("lit share of the frame", [j.lit_share for j in js], vr.MIN_LIT_SHARE, "min"),
        ("median irradiance / target", [j.median_light for j in js], vr.MIN_MEDIAN_LIGHT, "min"),
    ]
    fig = Figure(figsize=(10, 2.8))
    for ax, (title, values, limit, kind) in zip(fig.subplots(1, 4), panels, strict=True):
        ax.hist(np.asarray(values, float), bins=20, color="#4c72b0")
        ax.axvline(limit, color="#c44e52", ls="--", label=f"{kind} {limit:g}")
        ax.set_title(title, fontsize=8)
        ax.legend(fontsize=7)
    fig.suptitle(
        f"View rule on the first camera of {n} generated rooms (seed 11): "
        f"{passed} pass ({passed / n:.0%}); the others are re-drawn",
        fontsize=9,
    )
    fig.tight_layout()
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=100)
    print(f"{out}: {passed} of {n} first views pass ({passed / n:.0%})")


if __name__ == "__main__":
    main(*(int(a) if i == 0 else a for i, a in enumerate(sys.argv[1:])))
