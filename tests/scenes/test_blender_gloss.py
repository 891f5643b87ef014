"""The .blend importer maps Principled BSDF metallic/roughness/IOR to glossy materials."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

MAKE = Path(__file__).with_name("make_blend_gloss.py")


def test_principled_metallic_roughness_and_ior(tmp_path):
    pytest.importorskip("bpy", reason="the optional 'blender' extra (bpy) is not installed")
    from spectrinsic.scenes.blender import load_blend

    out = tmp_path / "gloss.blend"
    proc = subprocess.run(
        [sys.executable, "-P", str(MAKE), "--", str(out)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0 and out.is_file(), proc.stderr[-2000:]
    mats = {m.name: m for m in load_blend(out).materials}
    copper, coat, matte = mats["Copper"], mats["munsell:5R 4/14"], mats["flat:0.5"]
    assert (copper.kind, copper.metal, copper.spectrum) == ("conductor", "Cu", "flat:0")
    assert copper.roughness == pytest.approx(0.09, rel=1e-5)  # alpha = roughness squared
    assert (coat.kind, coat.spectrum) == ("plastic", "munsell:5R 4/14")
    assert coat.roughness == pytest.approx(0.04, rel=1e-5) and coat.ior == pytest.approx(
        1.45, rel=1e-5
    )
    assert matte.kind == "diffuse"  # Roughness 0.8: Lambertian, as every material before
