"""The daylight share of generated daylight rooms, measured (docs/daylight.md).

Builds N rooms of ``dataset --generator rooms --daylight-share 1`` (every room has a window,
sun and sky carry a drawn share of its flux, ``daylight.FLUX_SHARE``) at the preview preset,
then reads each sample's light records (``meta.json["lights"]``: each light's share of the
light arriving over the frame, from the rendered per-light transport) and prints the
distribution of sun + sky against the drawn flux share. With ``--only`` the rooms are
daylight-only and every share must be 1.

Run: ``python scripts/daylight_shares.py [N] [OUT] [--only]`` (about 20 s a room at 32² on
the 2-core machine).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from spectrinsic.cli import main as cli

DAYLIGHT = ("sun", "sky")


def build(n: int, out: Path, only: bool) -> None:
    args = ["-q", "dataset", "--generator", "rooms", "--daylight-share", "1"]
    args += ["--preset", "preview", "--resolution", "32x32", "--count", str(n), "--seed", "42"]
    if cli([*args, *(["--daylight-only"] if only else []), "--out", str(out)]) != 0:
        raise SystemExit(f"dataset build into {out} failed")


def shares(out: Path) -> list[tuple[str, float, float, float]]:
    """Per sample: id, drawn flux share, measured sun + sky share, sun share."""
    rows = []
    for meta_path in sorted(out.glob("*/meta.json")):
        meta = json.loads(meta_path.read_text())
        lights = {x["name"]: float(x["share"]) for x in meta["lights"]}
        drawn = float(meta["scene_metadata"]["daylight"]["flux_share"])
        rows.append((meta_path.parent.name, drawn, lights["sun"] + lights["sky"], lights["sun"]))
    return rows


def report(rows: list[tuple[str, float, float, float]]) -> str:
    day = np.array([r[2] for r in rows])
    drawn = np.array([r[1] for r in rows])
    q = np.percentile(day, [0, 10, 25, 50, 75, 90, 100])
    lines = [
        f"{name}  flux share {f:.2f}  daylight share {d:.3f}  sun {s:.3f}" for name, f, d, s in rows
    ]
    lines.append(
        f"n={len(rows)}  daylight share min/p10/p25/median/p75/p90/max: "
        + " / ".join(f"{v:.3f}" for v in q)
    )
    lines.append(
        f"rooms with daylight >= 20 %: {int((day >= 0.2).sum())}/{len(rows)}; >= 50 %: "
        f"{int((day >= 0.5).sum())}/{len(rows)}; correlation with the drawn flux share: "
        f"{np.corrcoef(drawn, day)[0, 1]:.2f}"
    )
    return "\n".join(lines)


if __name__ == "__main__":
    argv = [a for a in sys.argv[1:] if a != "--only"]
    n = int(argv[0]) if argv else 24
    out = Path(argv[1]) if len(argv) > 1 else Path("results/daylight-shares")
    if not out.exists():
        build(n, out, "--only" in sys.argv)
    print(report(shares(out)))
