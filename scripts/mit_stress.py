"""Names-and-shades on the MIT development half under stress variants, before and after a change.

Usage: python -P scripts/mit_stress.py MIT_DIR OUT.json [--variants=V,W] [OBJECT ...]
       python -P scripts/mit_stress.py --table OUT.md PART.json ...

Every object of MIT_DIR (``$SPECTRINSIC_DATA/mit_intrinsic_dev``; all by default) under every
variant of :data:`spectrinsic.decompose.evaluation.mit_variants.VARIANTS` (all by default) is
decomposed by three methods and scored with the thesis' protocol (MIT LMSE,
:mod:`spectrinsic.decompose.evaluation.mit`): ``before`` (the defaults without round 7's
return of the fine detail to the reflectance; round 7 compared main at bbf89c8 here, rounds
5-6 main before issue 48), ``after`` (the defaults) and ``image-as-reflectance``. OUT.json keeps every score and the guard's action;
``--table`` merges parts (runs on disjoint objects can share the cores) into a markdown table
per variant with each object's ratio to image-as-reflectance and the worst case.
"""

from __future__ import annotations

import json
import sys
import time
import warnings
from pathlib import Path

from spectrinsic.decompose.evaluation.mit import load_mit_object, mit_folder_objects, mit_measures
from spectrinsic.decompose.evaluation.mit_variants import VARIANTS, apply_variant
from spectrinsic.decompose.methods.baselines import ImageAsReflectance
from spectrinsic.decompose.methods.names_shades import NamesAndShades
from spectrinsic.errors import DatasetError

METHODS = {
    "before": NamesAndShades(fine_detail=False),
    "after": NamesAndShades(),
    "image-as-reflectance": ImageAsReflectance(),
}
#: The issue's bound: no object above this times image-as-reflectance.
BOUND = 1.5


def score(folder: Path, variants: list[str], objects: list[str] | None) -> list[dict[str, object]]:
    """One row per (variant, object, method): MIT LMSE, seconds and the guard's action."""
    rows: list[dict[str, object]] = []
    for path in mit_folder_objects(folder, objects or None):
        obj = load_mit_object(path)
        for variant in variants:
            varied = apply_variant(variant, obj)
            for method, decompose in METHODS.items():
                t0 = time.perf_counter()
                result = decompose(varied.image, varied.mask)
                seconds = time.perf_counter() - t0
                lmse = mit_measures(varied, result)["lmse"]
                guard = result.info.get("collapse", {})
                action = guard.get("action", "") if isinstance(guard, dict) else ""
                rows.append(
                    {
                        "variant": variant,
                        "object": obj.name,
                        "method": method,
                        "lmse": lmse,
                        "seconds": round(seconds, 2),
                        "guard": action,
                    }
                )
                print(
                    f"{variant} {obj.name} {method}: {lmse:.4f} ({seconds:.1f} s) {action}",
                    flush=True,
                )
    return rows


def table(rows: list[dict[str, object]]) -> str:
    """Markdown: per variant, objects x (before, after, image-as-reflectance, after / IaR)."""
    by = {(r["variant"], r["object"], r["method"]): r for r in rows}
    lines = []
    for variant in VARIANTS:
        objects = sorted({str(r["object"]) for r in rows if r["variant"] == variant})
        if not objects:
            continue
        lines += [
            f"**{variant}**",
            "",
            "| object | before | after | image-as-reflectance | "
            "before / IaR | after / IaR | guard |",
            "|---|---|---|---|---|---|---|",
        ]
        sums = {"before": 0.0, "after": 0.0, "image-as-reflectance": 0.0}
        worst = ("", 0.0)
        for name in objects:
            v = {m: float(by[(variant, name, m)]["lmse"]) for m in sums}  # type: ignore[arg-type]
            for m in sums:
                sums[m] += v[m]
            ratio = v["after"] / v["image-as-reflectance"]
            worst = max(worst, (name, ratio), key=lambda t: t[1])
            flag = " **over 1.5**" if ratio > BOUND else ""
            lines.append(
                f"| {name} | {v['before']:.4f} | {v['after']:.4f} | "
                f"{v['image-as-reflectance']:.4f} | "
                f"{v['before'] / v['image-as-reflectance']:.2f} | {ratio:.2f}{flag} | "
                f"{by[(variant, name, 'after')]['guard']} |"
            )
        n = len(objects)
        lines.append(
            f"| **mean** | {sums['before'] / n:.4f} | {sums['after'] / n:.4f} | "
            f"{sums['image-as-reflectance'] / n:.4f} | | worst {worst[0]} {worst[1]:.2f} | |"
        )
        lines.append("")
    return "\n".join(lines)


def summary(rows: list[dict[str, object]]) -> str:
    """Markdown: objects x variants, each cell "after (after / IaR)"; means before and after."""
    lmse = {(r["variant"], r["object"], r["method"]): float(r["lmse"]) for r in rows}  # type: ignore[arg-type]
    variants = [v for v in VARIANTS if any(r["variant"] == v for r in rows)]
    objects = sorted({str(r["object"]) for r in rows})
    lines = [
        "| object | " + " | ".join(variants) + " |",
        "|---|" + "---|" * len(variants),
    ]
    for name in objects:
        cells = []
        for v in variants:
            if (v, name, "after") not in lmse:
                cells.append("")
                continue
            ratio = lmse[(v, name, "after")] / lmse[(v, name, "image-as-reflectance")]
            mark = "**" if ratio > BOUND else ""
            cells.append(f"{mark}{lmse[(v, name, 'after')]:.4f} ({ratio:.2f}){mark}")
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    for method in ("after", "before", "image-as-reflectance"):
        means = []
        for v in variants:
            vals = [lmse[(v, o, method)] for o in objects if (v, o, method) in lmse]
            means.append(f"{sum(vals) / len(vals):.4f}" if vals else "")
        lines.append(f"| mean {method} | " + " | ".join(means) + " |")
    return "\n".join(lines)


def main(argv: list[str]) -> int:
    if len(argv) >= 2 and argv[0] == "--table":
        if Path(argv[1]).exists():
            print(f"mit_stress.py: {argv[1]} exists; expected a new file", file=sys.stderr)
            return 2
        rows = []
        for part in argv[2:]:
            try:
                rows += json.loads(Path(part).read_text(encoding="utf-8"))
            except (OSError, ValueError) as exc:
                print(
                    f"mit_stress.py: {part}: {exc} (expected a JSON file this script wrote)",
                    file=sys.stderr,
                )
                return 2
        Path(argv[1]).write_text(summary(rows) + "\n\n" + table(rows) + "\n", encoding="utf-8")
        return 0
    if len(argv) < 2:
        print(
            "usage: mit_stress.py MIT_DIR OUT.json [--variants=V,W] [OBJECT ...] | "
            "--table OUT.md PART.json ...",
            file=sys.stderr,
        )
        return 2
    variants = list(VARIANTS)
    rest = []
    for arg in argv[2:]:
        if arg.startswith("--variants="):
            variants = arg.split("=", 1)[1].split(",")
        else:
            rest.append(arg)
    unknown = [v for v in variants if v not in VARIANTS]
    if unknown:
        print(
            f"mit_stress.py: unknown variant {', '.join(unknown)}; expected {', '.join(VARIANTS)}",
            file=sys.stderr,
        )
        return 2
    out = Path(argv[1])
    if out.exists():
        print(f"mit_stress.py: {out} exists; expected a new file", file=sys.stderr)
        return 2
    try:
        mit_folder_objects(Path(argv[0]), rest or None)
    except DatasetError as exc:
        print(f"mit_stress.py: {exc}", file=sys.stderr)
        return 2
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        rows = score(Path(argv[0]), variants, rest)
    out.write_text(json.dumps(rows, indent=1) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
