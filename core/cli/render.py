"""``spectrinsic render``: render one scene in several modes and write the raw passes as EXR.

``SCENE`` is a library scene name (``spectrinsic.scenes.library``) or a YAML scene file. For
every mode ``DIR/<mode>.exr`` holds float32 layers ``raw`` (the K raw channels, named after the
sensors, e.g. ``raw.B400``), ``xyz`` (CIE 1931 XYZ), and when asked ``direct`` and
``light<i>`` (XYZ); ``DIR/aovs.exr`` holds coverage, ids, depth and normals; ``DIR/meta.json``
the render settings, variants, timings and the scene. Ground-truth layers are written by
``spectrinsic dataset``, not here.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
from pathlib import Path
from typing import Any

from spectrinsic.errors import RenderError, SceneError

__all__ = ["register", "run", "load_scene_argument", "write_render"]

DEFAULT_MODES = "spectral,rgb3,rgb6,bands31"
#: First bytes of every uncompressed ``.blend`` file.
BLEND_MAGIC = b"BLENDER"


def _modes_help() -> str:
    from spectrinsic.render.modes import RENDER_MODES

    return "; ".join(f"{m.name}: {m.description}" for m in RENDER_MODES.values())


def register(sub: argparse._SubParsersAction) -> None:
    from spectrinsic.pipeline.presets import get_preset

    # one set of documented defaults: those of the dataset's default preset
    default = get_preset("default")
    p = sub.add_parser(
        "render", help="render a scene in several colour modes and write raw passes as EXR",
        description="Render SCENE (a library scene name, a YAML or a .blend file) with Mitsuba 3 "
                    "in each mode and write float32 EXR files with named channels into --out "
                    "(raw passes, XYZ, AOVs; ground-truth layers come from `spectrinsic dataset`). "
                    f"Defaults are the dataset's default preset: {default.spp} spp, path depth "
                    f"{default.max_depth}, library scenes at {default.width}x{default.height}. "
                    f"Modes: {_modes_help()}.",
    )
    p.add_argument("scene", metavar="SCENE", help="library scene name (e.g. room-living) or a .yaml scene file")
    p.add_argument("--condition", default="white", help="library scenes: illumination condition (default: white)")
    p.add_argument("--view", type=int, default=0, help="library scenes: camera viewpoint (default: 0)")
    p.add_argument("--modes", default=DEFAULT_MODES, help=f"comma-separated render modes (default: {DEFAULT_MODES})")
    p.add_argument("--out", type=Path, required=True, metavar="DIR", help="output folder")
    p.add_argument("--spp", type=int, default=None,
                   help=f"samples per pixel of every pass (default: {default.spp}, the default "
                        "preset's; with --ground-truth the chosen preset's)")
    p.add_argument("--seed", type=int, default=0, help="sampler seed and library illuminant seed (default: 0)")
    p.add_argument("--width", type=int, default=None,
                   help=f"image width (default: the scene's, {default.width} for the library)")
    p.add_argument("--height", type=int, default=None,
                   help=f"image height (default: the scene's, {default.height} for the library)")
    p.add_argument("--max-depth", type=int, default=default.max_depth,
                   help=f"longest path, 2 = direct light only (default: {default.max_depth})")
    p.add_argument("--variant", default=None, help="Mitsuba backend or variant (default: best usable)")
    p.add_argument("--per-light", action="store_true", help="also write one image per light")
    p.add_argument("--direct", action="store_true", help="also write direct-light-only images")
    p.add_argument("--no-aovs", action="store_true", help="skip coverage/id/depth/normal maps")
    p.add_argument("--ground-truth", action="store_true",
                   help="write every ground-truth layer instead of raw passes: a one-sample dataset "
                        "built by the same path as `spectrinsic dataset --scenes` (uses --preset)")
    p.add_argument("--preset", default="preview", help="with --ground-truth: quality preset (preview)")
    p.add_argument("--material-map", metavar="FILE", default=None,
                   help="with --ground-truth: material name -> spectrum map for .blend and mesh files")
    p.set_defaults(func=run)


def load_scene_argument(
    scene: str, *, condition: str, view: int, seed: int, width: int | None, height: int | None,
    data_dir: str | None = None,
) -> Any:
    """The Scene named by the ``SCENE`` argument: a ``.blend`` file (by extension or its
    ``BLENDER`` magic bytes) through the Blender importer, a YAML file if it looks like a path,
    else a library name."""
    path = Path(scene)
    if _is_blend(path):
        from spectrinsic.scenes.blender import load_blend

        size = None if width is None and height is None else (width or 128, height or 128)
        return load_blend(path, resolution=size, data_dir=data_dir)
    if path.suffix.lower() in (".yaml", ".yml") or path.exists():
        from spectrinsic.scenes.io import load_scene

        loaded = load_scene(path, data_dir=data_dir)
        camera = loaded.camera
        camera = dataclasses.replace(camera, width=camera.width if width is None else width,
                                     height=camera.height if height is None else height)
        return dataclasses.replace(loaded, camera=camera)
    from spectrinsic.pipeline.presets import get_preset
    from spectrinsic.scenes import library

    default = get_preset("default")
    return library.build(scene, view=view, condition=condition, seed=seed,
                         width=default.width if width is None else width,
                         height=default.height if height is None else height)


def _default_spp() -> int:
    from spectrinsic.pipeline.presets import get_preset

    return get_preset("default").spp


def _is_blend(path: Path) -> bool:
    """True for a ``.blend`` name or a file starting with Blender's magic bytes."""
    if path.suffix.lower() == ".blend":
        return True
    try:
        with path.open("rb") as fh:
            return fh.read(len(BLEND_MAGIC)) == BLEND_MAGIC
    except OSError:
        return False


def _check_size_options(args: argparse.Namespace) -> None:
    """``--width``/``--height``/``--spp`` must be positive before anything is loaded."""
    for option, value in (("--width", args.width), ("--height", args.height), ("--spp", args.spp)):
        if value is not None and value < 1:
            raise RenderError(f"{option} {value}; expected a positive integer")


def write_render(out: Path, scene: Any, result: Any, *, data_dir: str | None = None) -> dict[str, Path]:
    """Write a :class:`~spectrinsic.render.RenderResult` as EXR files and ``meta.json`` into *out*."""
    from spectrinsic.gt_export.exr import write_exr
    from spectrinsic.scenes.model import scene_to_dict
    from spectrinsic.spectra import get_sensors

    out.mkdir(parents=True, exist_ok=True)
    paths: dict[str, Path] = {}
    for mode, raw in result.raw.items():
        labels = get_sensors(result.meta["sensors"][mode], data_dir=data_dir).channels
        layers = {"raw": raw, "xyz": result.images[mode]}
        names: dict[str, tuple[str, ...]] = {"raw": tuple(labels), "xyz": ("X", "Y", "Z")}
        if mode in result.direct:
            layers["direct"], names["direct"] = result.direct[mode], ("X", "Y", "Z")
        for i, light in enumerate(result.per_light):
            layers[f"light{i}"], names[f"light{i}"] = light[mode], ("X", "Y", "Z")
        paths[mode] = write_exr(out / f"{mode}.exr", layers, channel_names=names,
                                attributes={"spectrinsic.mode": mode, "spectrinsic.units": result.meta["units"]})
    if result.aovs:
        a = result.aovs
        paths["aovs"] = write_exr(
            out / "aovs.exr",
            {"coverage": a["coverage"], "material_id": a["material_id"], "object_id": a["object_id"],
             "depth": a["depth"], "normals": a["normals"], "mask": a["mask"].astype("float32")},
            channel_names={"coverage": tuple(f"m{i:02d}" for i in range(a["coverage"].shape[-1])),
                           "material_id": ("id",), "object_id": ("id",), "depth": ("Z",),
                           "normals": ("X", "Y", "Z"), "mask": ("A",)},
        )
    meta = {**result.meta, "scene": scene_to_dict(scene), "files": {k: v.name for k, v in paths.items()}}
    meta["scene"]["meshes"] = [{"name": m.name, "object_id": m.object_id, "faces": len(m.faces)} for m in scene.meshes]
    paths["meta"] = out / "meta.json"
    paths["meta"].write_text(json.dumps(meta, indent=2, default=str) + "\n", encoding="utf-8")
    return paths


def _ground_truth(args: argparse.Namespace) -> int:
    """``render --ground-truth``: a thin alias of ``dataset`` (one sample; library name or file)."""
    from spectrinsic.cli import dataset as cli_dataset
    from spectrinsic.scenes.sample_id import SampleId

    path = Path(args.scene)
    is_file = path.suffix.lower() in (".yaml", ".yml", ".blend") or path.exists()
    resolution = None
    if args.width is not None or args.height is not None:
        resolution = f"{args.width or 128}x{args.height or 128}"
    dataset_args = argparse.Namespace(
        out=str(args.out), preset=args.preset, seed=args.seed, workers=None, threads=None,
        scheduler=None, spp=args.spp, batches=None, noise_target=None, max_batches=None,
        no_denoise=False, direct=args.direct, resolution=resolution, rebuild=False,
        only=None if is_file else str(SampleId(args.scene, args.view, args.condition)),
        generator=None, scenes=[args.scene] if is_file else None, material_map=args.material_map,
        default_spectrum=None, count=1, views=1, value_range="2,9", chroma_range="0,16", sfu=False,
        data_dir=getattr(args, "data_dir", None), quiet=getattr(args, "quiet", False))
    return cli_dataset.run(dataset_args)


def run(args: argparse.Namespace) -> int:
    if args.ground_truth:
        return _ground_truth(args)
    from spectrinsic.gt_export.integrity import require_folder_path
    from spectrinsic.render import count_passes, get_mode, render_scene
    from spectrinsic.render.budget import check_render_size

    modes = [m.strip() for m in str(args.modes).split(",") if m.strip()]
    if not modes:
        raise SceneError(f"--modes {args.modes!r}: expected a comma-separated list such as {DEFAULT_MODES}")
    for mode in modes:
        get_mode(mode)
    _check_size_options(args)
    require_folder_path(Path(args.out))
    data_dir = getattr(args, "data_dir", None)
    scene = load_scene_argument(args.scene, condition=args.condition, view=args.view, seed=args.seed,
                                width=args.width, height=args.height, data_dir=data_dir)
    given = " ".join(f"--{k} {v}" for k, v in (("width", args.width), ("height", args.height)) if v is not None)
    check_render_size(scene.camera.width, scene.camera.height, what=given or f"scene {args.scene!r}",
                      modes=modes, n_lights=len(scene.lights), per_light=args.per_light,
                      direct=args.direct, data_dir=data_dir)
    options = dict(modes=modes, per_light=args.per_light, direct=args.direct, aovs=not args.no_aovs)
    total = count_passes(scene, data_dir=data_dir, variant=args.variant, **options)
    bar = None
    if not getattr(args, "quiet", False):
        from tqdm import tqdm

        bar = tqdm(total=total, desc=f"render {scene.name}", unit="pass", file=sys.stderr)
    try:
        result = render_scene(scene, spp=_default_spp() if args.spp is None else args.spp, seed=args.seed, max_depth=args.max_depth, variant=args.variant,
                              progress=None if bar is None else bar.update, data_dir=data_dir, **options)
    finally:
        if bar is not None:
            bar.close()
    paths = write_render(Path(args.out), scene, result, data_dir=data_dir)
    timings = result.meta["timings"]
    for mode in result.images:
        print(f"{mode:<9} {timings[mode]['passes']:>3} passes {timings[mode]['seconds']:7.2f} s  -> {paths[mode]}")
    if "single" in timings:  # every diagonal mode (and the AOVs) from one traversal
        print(f"{'traversal':<9} {timings['single']['passes']:>3} passes {timings['single']['seconds']:7.2f} s  "
              "(all diagonal modes and lights)")
    print(f"wrote {paths['meta']}")
    return 0
