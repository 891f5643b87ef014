"""The render-memory preflight is an upper bound of what a render really takes (issue 17,
item 7): two small renders in fresh processes, their peak resident memory against the estimate."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from spectrinsic.render import RenderSettings
from spectrinsic.render.budget import estimate_render_bytes

#: A render in a fresh process that prints its own peak resident memory in bytes (Linux
#: ``ru_maxrss`` is in KiB).
_RENDER = """
import resource, sys
from spectrinsic.cli import main
rc = main(["-q", "render", "obj-apple", "--width", sys.argv[1], "--height", sys.argv[1],
           "--spp", "2", "--modes", sys.argv[2], "--out", sys.argv[3]])
print(rc, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024)
"""


@pytest.mark.slow
@pytest.mark.parametrize("size", [64, 192])
def test_the_estimate_bounds_the_measured_peak(tmp_path, size):
    modes = "spectral,rgb3,rgb6"
    done = subprocess.run(
        [sys.executable, "-P", "-c", _RENDER, str(size), modes, str(tmp_path / "o")],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    rc, peak = (int(x) for x in done.stdout.split()[-2:])
    assert rc == 0, done.stderr
    meta = json.loads((tmp_path / "o" / "meta.json").read_text())
    n_lights = len(meta["scene"]["lights"])
    settings = RenderSettings(2, modes=tuple(modes.split(",")))
    estimate = estimate_render_bytes(size, size, settings, n_lights=n_lights)
    assert peak <= estimate, (
        f"{size}x{size}: peak {peak / 2**20:.0f} MiB > estimate {estimate / 2**20:.0f} MiB"
    )
