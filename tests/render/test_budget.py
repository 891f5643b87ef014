"""The render-memory preflight is an upper bound of what a render really takes (issue 17,
item 7): two small renders in fresh processes, their peak resident memory against the estimate."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import spectrinsic.render.band_path.traversal as traversal
from spectrinsic.mitsuba_import import import_mitsuba
from spectrinsic.render import RenderSettings, render_scene
from spectrinsic.render.budget import RenderLoad, estimate_render_bytes, traversal_channels
from spectrinsic.scenes import library
from spectrinsic.scenes.mitsuba_xml import load_mitsuba_xml

#: Runs ``spectrinsic`` with the arguments given in a fresh process that prints its own peak
#: resident memory in bytes (Linux ``ru_maxrss`` is in KiB).
_RUN = """
import resource, sys
from spectrinsic.cli import main
rc = main(["-q", *sys.argv[1:]])
print(rc, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024)
"""


def _peak(argv: list[str]) -> int:
    """The peak resident memory in bytes of ``spectrinsic *argv*`` in a fresh process."""
    done = subprocess.run(
        [sys.executable, "-P", "-c", _RUN, *argv],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    rc, peak = (int(x) for x in done.stdout.split()[-2:])
    assert rc == 0, done.stderr
    return peak


@pytest.mark.slow
@pytest.mark.parametrize("size", [64, 192])
def test_the_estimate_bounds_the_measured_peak(tmp_path, size):
    modes = "spectral,rgb3,rgb6"
    out = tmp_path / "o"
    argv = ["render", "obj-apple", "--width", str(size), "--height", str(size)]
    peak = _peak([*argv, "--spp", "2", "--modes", modes, "--out", str(out)])
    meta = json.loads((out / "meta.json").read_text())
    scene = library.build("obj-apple", condition="white", seed=0, width=size, height=size)
    load = RenderLoad.of_scene(scene)
    assert load.n_lights == len(meta["scene"]["lights"])
    settings = RenderSettings(2, modes=tuple(modes.split(",")))
    estimate = estimate_render_bytes(size, size, settings, load=load)
    assert peak <= estimate, (
        f"{size}x{size}: peak {peak / 2**20:.0f} MiB > estimate {estimate / 2**20:.0f} MiB"
    )


#: A room of multi-light interest at 48 x 48: a floor, a back wall, three diffuse cubes, a glass
#: sphere (glossy, no diffuse lobe) and a mirror, lit by an environment map (three channel
#: lights) and POINTS point lights.
_ROOM = """<scene version="3.0.0">
<bsdf type="diffuse" id="white"><spectrum name="reflectance" value="0.7"/></bsdf>
<bsdf type="dielectric" id="glass"><string name="int_ior" value="bk7"/></bsdf>
<bsdf type="conductor" id="mirror"><string name="material" value="none"/></bsdf>
<shape type="rectangle" id="floor"><ref id="white"/>
  <transform name="to_world"><scale value="4"/></transform></shape>
<shape type="rectangle" id="back"><ref id="white"/>
  <transform name="to_world"><scale value="4"/><rotate x="1" angle="90"/>
  <translate value="0 3 2"/></transform></shape>
{cubes}
<shape type="sphere" id="gem"><point name="center" x="0.6" y="0" z="0.5"/>
  <float name="radius" value="0.4"/><ref id="glass"/></shape>
<shape type="rectangle" id="looking-glass"><ref id="mirror"/>
  <transform name="to_world"><scale value="0.6"/><rotate x="1" angle="90"/>
  <translate value="-1 2.9 1"/></transform></shape>
{points}
<emitter type="envmap"><string name="filename" value="sky.exr"/>
  <transform name="to_world"><rotate x="1" angle="90"/></transform></emitter>
<sensor type="perspective"><float name="fov" value="50"/>
  <transform name="to_world"><lookat origin="0, -5, 2.5" target="0, 0, 0.5" up="0, 0, 1"/>
  </transform>
  <sampler type="independent"><integer name="sample_count" value="2"/></sampler>
  <film type="hdrfilm"><integer name="width" value="48"/><integer name="height" value="48"/>
  </film></sensor>
</scene>
"""


def _room(folder: Path, points: int) -> Path:
    """:data:`_ROOM` with *points* point lights and its grey-and-blue sky map, in *folder*."""
    mi = import_mitsuba()
    if mi.variant() is None:
        mi.set_variant("scalar_rgb")
    sky = np.linspace(2.0, 0.2, 8)[:, None, None] * np.ones((8, 16, 3))
    sky[:, ::4] *= (0.5, 0.8, 1.0)  # three distinct channels
    mi.Bitmap(np.ascontiguousarray(sky, np.float32)).write(str(folder / "sky.exr"))
    cubes = "\n".join(
        f'<shape type="cube" id="box{b}"><bsdf type="diffuse"><spectrum name="reflectance" '
        f'value="360:{0.2 + 0.2 * b:.1f}, 830:{0.8 - 0.2 * b:.1f}"/></bsdf><transform '
        f'name="to_world"><scale value="0.15"/><translate value="{b - 1} -1 0.15"/></transform>'
        "</shape>"
        for b in range(3)
    )
    lights = "\n".join(
        f'<emitter type="point"><point name="position" x="{p - 1}" y="-1" z="3"/>'
        f'<spectrum name="intensity" value="{5 + p}"/></emitter>'
        for p in range(points)
    )
    path = folder / "room.xml"
    path.write_text(_ROOM.format(cubes=cubes, points=lights))
    return path


def test_the_band_path_film_holds_the_channels_the_estimate_counts(tmp_path, monkeypatch):
    """The film term of the estimate counts channels (``traversal_channels``: L·K transport,
    specular and white-at-metal accumulators and the first-hit maps): the band-path
    traversal's real film, recorded where it is rendered, has exactly as many, in a room lit
    by an environment map and four points (7 lights) with glass and a mirror, the direct
    traversal included. Counted independently, L·K = 7·(3 + 6) = 63 per part."""
    scene = load_mitsuba_xml(_room(tmp_path, 4))
    load = RenderLoad.of_scene(scene)
    assert (load.n_lights, load.glossy, load.metals) == (7, True, True)
    seen: list[int] = []
    real = traversal.timed_render

    def recorded(*args, **kwargs):
        image, seconds = real(*args, **kwargs)
        seen.append(image.shape[-1])
        return image, seconds

    monkeypatch.setattr(traversal, "timed_render", recorded)
    settings = RenderSettings(2, modes=("rgb3", "rgb6"), direct=True)
    render_scene(scene, settings, seed=0)
    maps = load.n_surfaces + load.n_texcols + 4
    assert tuple(seen) == (3 + 3 * 63 + maps, 3 + 2 * 63)
    assert tuple(seen) == traversal_channels(settings, load)


@pytest.mark.slow
def test_the_estimate_bounds_a_multi_light_environment_map_render(tmp_path):
    """A render of the room lit by an environment map and one point (4 lights, glass and a
    mirror: L·K transport, specular and white-at-metal accumulators, each light's share kept)
    at 48 x 48 in a fresh process peaks below the size check's estimate for it. Larger
    sizes, where the per-pixel terms dominate: docs/artist-interior-speed.md."""
    xml = _room(tmp_path, 1)
    argv = ["render", str(xml), "--modes", "rgb3,rgb6", "--per-light", "--spp", "2"]
    peak = _peak([*argv, "--out", str(tmp_path / "o")])
    load = RenderLoad.of_scene(load_mitsuba_xml(xml))
    assert load.n_lights == 4 and load.glossy and load.metals
    settings = RenderSettings(2, modes=("rgb3", "rgb6"), per_light=True)
    estimate = estimate_render_bytes(48, 48, settings, load=load)
    assert peak <= estimate, f"peak {peak / 2**20:.0f} MiB > estimate {estimate / 2**20:.0f} MiB"
