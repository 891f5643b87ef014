"""Printing many problems readably: a message shared by several samples is one line with a count.

``check`` on a set of 68 samples used to print the same message 68 times (twice each, with the
noise lines). :func:`problem_lines` groups ``"<sample>: <message>"`` lines: a message found in
more than one sample becomes one line, ``N samples: <message> (a, b, c and N-3 more)``; the
others stay grouped under their sample, at most *max_per_sample* each.
"""

from __future__ import annotations

from collections.abc import Sequence

__all__ = ["problem_lines", "SHOWN_IDS"]

#: Sample ids named on a collapsed line before "and N more".
SHOWN_IDS = 3


def _ids(samples: Sequence[str]) -> str:
    shown = ", ".join(samples[:SHOWN_IDS])
    rest = len(samples) - SHOWN_IDS
    return f"{shown} and {rest} more" if rest > 0 else shown


def problem_lines(problems: Sequence[str], *, max_per_sample: int) -> list[str]:
    """The lines to print for *problems* (``"<sample>: <message>"`` each), in first-seen order."""
    by_message: dict[str, list[str]] = {}
    for line in problems:
        sample, _, message = line.partition(": ")
        by_message.setdefault(message, []).append(sample)
    out = [
        f"{len(samples)} samples: {message} ({_ids(samples)})"
        for message, samples in by_message.items()
        if len(samples) > 1
    ]
    grouped: dict[str, list[str]] = {}
    for message, samples in by_message.items():
        if len(samples) == 1:
            grouped.setdefault(samples[0], []).append(message)
    for sample, messages in grouped.items():
        out.append(f"{sample}: {len(messages)} problem(s)")
        out += [f"  - {m}" for m in messages[:max_per_sample]]
        if len(messages) > max_per_sample:
            out.append(f"  ... and {len(messages) - max_per_sample} more")
    return out
