"""Peak resident memory of ``spectrinsic render`` against the size check's estimate
(``spectrinsic/render/budget.py``), on small Mitsuba XML scenes that vary the lights (point
lights, with or without an environment map: three channel lights), the bands (modes), the
surfaces and the resolution (docs/artist-interior-speed.md, "The estimate against measured
peaks").

A case is ``spectrinsic dataset --scenes`` of the scene (what ``render --ground-truth``
builds, at the default preset, with the spectral reference at the traversal's spp: the peak
does not depend on spp), or with ``--plain`` a plain ``spectrinsic render``. Each case renders
in a fresh process (``ru_maxrss``, Linux KiB), which also records the peak
of every band-path render call (``VmHWM`` reset through ``/proc/self/clear_refs`` before it)
and the channels of its film::

    PYTHONPATH=$PWD SPECTRINSIC_DATA=/work/shared/data python -P scripts/render_peaks.py \\
        --points 1 --envmap --boxes 4 --size 64x64 --spp 4 [--plain [--modes rgb3]]

prints one JSON line: the case, the peak, the estimate and the stages.
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

MiB = 2**20


def _xml(points: int, envmap: bool, boxes: int, width: int, height: int, spp: int) -> str:
    """A floor and a back wall, *boxes* diffuse cubes of distinct colours, a glass sphere and a
    mirror, *points* point lights and (*envmap*) the map ``sky.exr``."""
    parts = ['<scene version="3.0.0">']
    parts.append(
        '<bsdf type="diffuse" id="white"><spectrum name="reflectance" value="0.7"/></bsdf>'
    )
    parts.append('<bsdf type="dielectric" id="glass"><string name="int_ior" value="bk7"/></bsdf>')
    parts.append('<bsdf type="conductor" id="mirror"><string name="material" value="none"/></bsdf>')
    parts.append(
        '<shape type="rectangle" id="floor"><ref id="white"/><transform name="to_world">'
        '<scale value="4"/></transform></shape>'
    )
    parts.append(
        '<shape type="rectangle" id="back"><ref id="white"/><transform name="to_world">'
        '<scale value="4"/><rotate x="1" angle="90"/><translate value="0 3 2"/></transform></shape>'
    )
    side = max(1, int(np.ceil(np.sqrt(boxes))))
    for b in range(boxes):
        x, y = (b % side) / side * 3 - 1.5, (b // side) / side * 3 - 1.5
        r = 0.1 + 0.8 * (b + 1) / (boxes + 1)
        parts.append(
            f'<shape type="cube" id="box{b}"><bsdf type="diffuse"><spectrum name="reflectance" '
            f'value="360:{r:.3f}, 830:{1 - r:.3f}"/></bsdf><transform name="to_world">'
            f'<scale value="0.15"/><translate value="{x:.3f} {y:.3f} 0.15"/></transform></shape>'
        )
    parts.append(
        '<shape type="sphere" id="gem"><point name="center" x="0.6" y="0" z="0.5"/>'
        '<float name="radius" value="0.4"/><ref id="glass"/></shape>'
    )
    parts.append(
        '<shape type="rectangle" id="glass-wall"><ref id="mirror"/><transform name="to_world">'
        '<scale value="0.6"/><rotate x="1" angle="90"/><translate value="-1 2.9 1"/></transform>'
        "</shape>"
    )
    for p in range(points):
        x = -1.5 + 3.0 * p / max(points - 1, 1)
        parts.append(
            f'<emitter type="point"><point name="position" x="{x:.3f}" y="-1" z="3"/>'
            f'<spectrum name="intensity" value="{5 + p}"/></emitter>'
        )
    if envmap:
        parts.append(
            '<emitter type="envmap"><string name="filename" value="sky.exr"/>'
            '<transform name="to_world"><rotate x="1" angle="90"/></transform></emitter>'
        )
    parts.append(
        '<sensor type="perspective"><float name="fov" value="50"/><transform name="to_world">'
        '<lookat origin="0, -5, 2.5" target="0, 0, 0.5" up="0, 0, 1"/></transform>'
        f'<sampler type="independent"><integer name="sample_count" value="{spp}"/></sampler>'
        f'<film type="hdrfilm"><integer name="width" value="{width}"/>'
        f'<integer name="height" value="{height}"/></film></sensor>'
    )
    return "\n".join(parts + ["</scene>"])


def _write_sky(path: Path) -> None:
    """A 16 × 32 sky, bright at the zenith, with coloured stripes (three distinct channels)."""
    from spectrinsic.mitsuba_import import import_mitsuba

    mi = import_mitsuba()
    if mi.variant() is None:
        mi.set_variant("scalar_rgb")
    sky = np.linspace(2.0, 0.2, 16)[:, None, None] * np.ones((16, 32, 3))
    sky[:, ::4] *= (0.5, 0.8, 1.0)
    mi.Bitmap(np.ascontiguousarray(sky, np.float32)).write(str(path))


def _status(field: str) -> int:
    """``VmHWM`` / ``VmRSS`` of this process in bytes."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(field + ":"):
            return int(line.split()[1]) * 1024
    raise RuntimeError(f"no {field} in /proc/self/status")


def _child(out: str, argv: list[str]) -> None:
    """Render in this process, each band-path render call's own peak recorded."""
    import spectrinsic.render.band_path.traversal as traversal
    from spectrinsic.cli import main

    stages: list[dict[str, float]] = []
    peak = [0]
    timed = traversal.timed_render

    def recorded(*args, **kwargs):  # type: ignore[no-untyped-def]
        peak[0] = max(peak[0], _status("VmHWM"))
        before = _status("VmRSS")
        Path("/proc/self/clear_refs").write_text("5")  # VmHWM := VmRSS
        image, seconds = timed(*args, **kwargs)
        top = _status("VmHWM")
        peak[0] = max(peak[0], top)
        stages.append(
            {"channels": image.shape[-1], "before_mib": before / MiB, "peak_mib": top / MiB}
        )
        return image, seconds

    traversal.timed_render = recorded
    rc = main(["-q", *argv, "--out", out])
    peak[0] = max(
        peak[0], _status("VmHWM"), resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    )
    print(json.dumps({"rc": rc, "peak": peak[0], "stages": stages}))


def _estimate(xml: Path, args: argparse.Namespace) -> int:
    """The size check's estimate of the case, from the scene as the command line reads it."""
    from spectrinsic.pipeline.presets import get_preset
    from spectrinsic.render.budget import RenderLoad, estimate_render_bytes
    from spectrinsic.render.settings import RenderSettings
    from spectrinsic.scenes.mitsuba_xml import load_mitsuba_xml

    width, height = (int(v) for v in args.size.split("x"))
    scene = load_mitsuba_xml(xml)
    if args.plain:
        modes = tuple(args.modes.split(",")) if args.modes else RenderSettings(1).modes
        settings = RenderSettings(args.spp, modes=modes)
    else:
        settings = get_preset("default").render.with_options(spp=args.spp, spectral_spp=args.spp)
    return estimate_render_bytes(width, height, settings, load=RenderLoad.of_scene(scene))


def main() -> None:
    if sys.argv[1:2] == ["child"]:
        _child(sys.argv[2], sys.argv[3:])
        return
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--points", type=int, default=1)
    parser.add_argument("--envmap", action="store_true")
    parser.add_argument("--boxes", type=int, default=4)
    parser.add_argument("--size", default="64x64")
    parser.add_argument("--spp", type=int, default=4)
    parser.add_argument("--modes", default="")
    parser.add_argument("--plain", action="store_true", help="a plain render, no ground truth")
    parser.add_argument("--estimate-only", action="store_true", help="print the estimate alone")
    args = parser.parse_args()
    if args.modes and not args.plain:
        parser.error("--modes applies with --plain (a ground-truth build renders the preset's)")
    width, height = (int(v) for v in args.size.split("x"))
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        _write_sky(folder / "sky.exr")
        xml = folder / "scene.xml"
        xml.write_text(_xml(args.points, args.envmap, args.boxes, width, height, args.spp))
        if args.estimate_only:
            print(json.dumps({**vars(args), "estimate": _estimate(xml, args)}))
            return
        argv = ["--spp", str(args.spp), "--resolution", f"{width}x{height}"]
        if args.plain:
            argv = ["render", str(xml), *argv] + (["--modes", args.modes] if args.modes else [])
        else:  # render --ground-truth's build, its spectral spp the traversal's (faster)
            argv = ["dataset", "--scenes", str(xml), "--spectral-spp", str(args.spp), *argv]
        done = subprocess.run(
            [sys.executable, "-P", __file__, "child", str(folder / "out"), *argv],
            capture_output=True,
            text=True,
            check=False,
        )
        if done.returncode != 0 or not done.stdout.strip():
            sys.exit(f"render_peaks: the render failed:\n{done.stderr[-2000:]}")
        record = json.loads(done.stdout.strip().splitlines()[-1])
        record.update(vars(args), estimate=_estimate(xml, args))
        record["ratio"] = record["estimate"] / record["peak"]
        print(json.dumps(record))


if __name__ == "__main__":
    main()
