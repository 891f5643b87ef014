"""The sim-to-real study's tables, figure and files."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path
from typing import Any

from ...file_writes import replacing, write_text_file
from ..glossary import abbreviations
from .compute import RunScore, Sim2RealResult
from .settings import FACTORS
from .stats import CONFIDENCE, Interval, paired_difference, t_interval

__all__ = ["arm_rows", "factor_rows", "format_sim2real", "write_sim2real"]

_MEASURES = (("mit", "mit_lmse"), ("test", "test_lmse"))


def _scores(runs: list[RunScore], arm: str, key: str) -> list[float]:
    return [float(getattr(r, key)) for r in sorted(runs, key=lambda r: r.seed) if r.arm == arm]


def _iv(iv: Interval) -> str:
    return f"{iv.mean:.4f} [{iv.lo:.4f}, {iv.hi:.4f}]"


def arm_rows(result: Sim2RealResult) -> list[dict[str, Any]]:
    """Per arm: samples, seeds, and each measure's mean with its t-interval."""
    rows = []
    for arm in dict.fromkeys(r.arm for r in result.runs):
        row: dict[str, Any] = {"arm": arm, "samples": len(result.arm_samples[arm])}
        for name, key in _MEASURES:
            iv = t_interval(_scores(result.runs, arm, key))
            row.update({f"{name}_mean": iv.mean, f"{name}_lo": iv.lo, f"{name}_hi": iv.hi})
            row["seeds"] = iv.n
        rows.append(row)
    return rows


def factor_rows(result: Sim2RealResult) -> list[dict[str, Any]]:
    """Per factor: the paired (by seed) difference of LMSE, arm with minus arm without; a
    negative difference is the factor helping (lower LMSE)."""
    rows = []
    for factor, (with_, without) in FACTORS.items():
        row: dict[str, Any] = {"factor": factor, "with": with_, "without": without}
        for name, key in _MEASURES:
            iv = paired_difference(
                _scores(result.runs, with_, key), _scores(result.runs, without, key)
            )
            row.update(
                {
                    f"{name}_diff": iv.mean,
                    f"{name}_lo": iv.lo,
                    f"{name}_hi": iv.hi,
                    f"{name}_significant": iv.significant,
                }
            )
        rows.append(row)
    return rows


def _verdict(row: dict[str, Any], name: str) -> str:
    if not row[f"{name}_significant"]:
        return "not significant"
    return "helps" if row[f"{name}_diff"] < 0 else "hurts"


def format_sim2real(result: Sim2RealResult) -> str:
    """The arms' table, the factors' table and the baselines, as markdown."""
    pct = f"{CONFIDENCE:.0%}"
    lines = [
        f"Sim-to-real study, preset {result.settings.preset}: mean LMSE (thesis Table 3.2 "
        f"protocol; lower is better) with {pct} t-intervals over seeds; MIT development half "
        f"({result.mit_objects} objects) and the synthetic test split "
        f"({result.test_samples} samples); {result.seconds / 60:.1f} min.",
        "",
        "| arm | train samples | seeds | MIT LMSE | synthetic test LMSE |",
        "|---|---|---|---|---|",
    ]
    for r in arm_rows(result):
        mit = Interval(r["mit_mean"], r["mit_lo"], r["mit_hi"], r["seeds"])
        test = Interval(r["test_mean"], r["test_lo"], r["test_hi"], r["seeds"])
        lines.append(f"| {r['arm']} | {r['samples']} | {r['seeds']} | {_iv(mit)} | {_iv(test)} |")
    lines += [
        "",
        f"Paired differences (with - without, by seed; < 0: the factor lowers LMSE), {pct} CI:",
        "",
        "| factor | with / without | MIT | verdict | synthetic test | verdict |",
        "|---|---|---|---|---|---|",
    ]
    for r in factor_rows(result):
        mit = Interval(r["mit_diff"], r["mit_lo"], r["mit_hi"], 0)
        test = Interval(r["test_diff"], r["test_lo"], r["test_hi"], 0)
        lines.append(
            f"| {r['factor']} | {r['with']} / {r['without']} | {_iv(mit)} | "
            f"{_verdict(r, 'mit')} | {_iv(test)} | {_verdict(r, 'test')} |"
        )
    lines += ["", "| bundled decomposer | MIT LMSE | synthetic test LMSE |", "|---|---|---|"]
    for name, (mit_v, test_v) in result.baselines.items():
        lines.append(f"| {name} | {mit_v:.4f} | {test_v:.4f} |")
    return "\n".join(lines) + "\n\n" + abbreviations(["LMSE", "CI", "rgb3"])


def _figure(result: Sim2RealResult, path: Path) -> None:
    from matplotlib.figure import Figure

    rows = arm_rows(result)
    fig = Figure(figsize=(8, 3.2))
    for k, (name, title) in enumerate((("mit", "MIT dev half"), ("test", "synthetic test"))):
        ax = fig.add_subplot(1, 2, k + 1)
        for i, r in enumerate(rows):
            ax.errorbar(
                i,
                r[f"{name}_mean"],
                fmt="o",
                capsize=4,
                yerr=[[r[f"{name}_mean"] - r[f"{name}_lo"]], [r[f"{name}_hi"] - r[f"{name}_mean"]]],
            )
            ax.scatter(
                [i] * r["seeds"],
                _scores(result.runs, r["arm"], f"{name}_lmse"),
                s=8,
                color="grey",
                zorder=3,
            )
        for j, (base, values) in enumerate(result.baselines.items()):
            ax.axhline(values[k], ls=("--", ":", "-.")[j % 3], lw=0.8, color="k", label=base)
        ax.set_xticks(range(len(rows)), [r["arm"] for r in rows], rotation=30)
        ax.set(title=title, ylabel="LMSE (lower is better)")
    fig.axes[0].legend(fontsize=6)
    fig.tight_layout()
    with replacing(path) as tmp:
        fig.savefig(tmp, dpi=120)


def write_sim2real(result: Sim2RealResult, out_dir: Path) -> dict[str, Path]:
    """``sim2real.md`` (the tables), ``sim2real.png`` (each arm's mean, interval and runs
    beside the baselines), ``sim2real_runs.csv`` and ``sim2real.json`` (settings, the set's
    config and hash, each arm's samples, every run)."""
    out_dir.mkdir(parents=True, exist_ok=True)
    paths = {
        k: out_dir / f"sim2real{s}"
        for k, s in (("md", ".md"), ("png", ".png"), ("csv", "_runs.csv"), ("json", ".json"))
    }
    write_text_file(paths["md"], format_sim2real(result) + "\n")
    _figure(result, paths["png"])
    text = io.StringIO(newline="")
    writer = csv.writer(text)
    writer.writerow(["arm", "seed", "mit_lmse", "test_lmse", "samples", "seconds"])
    for r in result.runs:
        writer.writerow(
            [
                r.arm,
                r.seed,
                f"{r.mit_lmse:.6g}",
                f"{r.test_lmse:.6g}",
                r.samples,
                f"{r.seconds:.1f}",
            ]
        )
    write_text_file(paths["csv"], text.getvalue())
    record = {
        "settings": result.settings.to_dict(),
        "dataset_config": result.config,
        "config_hash": result.config_hash,
        "arm_samples": result.arm_samples,
        "runs": [vars(r) for r in result.runs],
        "baselines": {
            k: {"mit_lmse": v[0], "test_lmse": v[1]} for k, v in result.baselines.items()
        },
        "arms": arm_rows(result),
        "factors": factor_rows(result),
        "seconds": result.seconds,
    }
    write_text_file(paths["json"], json.dumps(record, indent=1, allow_nan=True) + "\n")
    return paths
