"""Adversarial probes of round 5's new inputs against the command line (task r5-probe).

Each case writes its inputs into a fresh folder, runs ``python -P -m spectrinsic ...`` there in
a fresh subprocess (tiny sizes: 16x16 pixels, 1 spp) and is classified:

* ``OK``: a case that must be refused ended with rc 2, exactly one line on stderr that starts
  ``spectrinsic: error:`` and names the input (``expect`` text), no ``Traceback``, nothing
  written under ``--out`` (refused before work) and no file outside it touched;
* ``OK`` also for a case marked ``either`` (valid but odd input) that ends rc 0 or as above;
* ``FAIL``: anything else (a traceback, rc 1, several lines, silent acceptance of something
  invalid, files under ``--out`` after a refusal, a file outside ``--out`` changed, a hang).

Usage (from a worktree; a few minutes on 2 cores)::

    PYTHONPATH=$PWD SPECTRINSIC_DATA=/work/shared/data \\
        /work/main/.venv/bin/python -P scripts/probes_round5.py [--only SUBSTR] [--jobs 2]

The summary of the last run is in docs/probes-round5.md.
"""

from __future__ import annotations

import argparse
import base64
import hashlib
import json
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

TINY = ["--resolution", "16x16", "--spp", "1", "--modes", "rgb3", "-q"]

CAMERA = (
    '<sensor type="perspective"><transform name="to_world"><lookat origin="0,0,3" '
    'target="0,0,0" up="0,1,0"/></transform><film type="hdrfilm"><integer name="width" '
    'value="16"/><integer name="height" value="16"/></film></sensor>'
)
LIGHT = '<emitter type="point"><point name="position" value="0,0,2"/><rgb name="intensity" value="5"/></emitter>'
RECT = '<shape type="rectangle"><bsdf type="diffuse"/></shape>'

QUAD_YAML = """\
name: quad
materials: {grey: "flat:0.5"}
meshes:
  - name: ground
    vertices: [[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0]]
    faces: [[0, 1, 2], [0, 2, 3]]
    material: grey
lights:
  - {kind: point, spectrum: "cie:D65", power: 4, position: [0, 0, 2]}
camera: {origin: [0, -3, 2], target: [0, 0, 0], width: 16, height: 16}
"""


@dataclass(frozen=True)
class Case:
    """One probe: files to write (name -> text or bytes, or a callable of the folder), the
    command line (``{d}`` is the case folder) and what a correct run does."""

    name: str
    argv: tuple[str, ...]
    files: dict[str, str | bytes] = field(default_factory=dict)
    setup: Callable[[Path], None] | None = None
    expect: str = ""  # text the one error line must hold ("" = any)
    either: bool = False  # valid-but-odd input: rc 0 is fine too


def xml(body: str, head: str = "") -> str:
    return f'<?xml version="1.0"?>{head}<scene version="3.0.0">{CAMERA}{LIGHT}{body}</scene>'


def png_bytes(w: int, h: int, channels: int = 3) -> bytes:
    import numpy as np
    from PIL import Image

    mode = {1: "L", 3: "RGB", 4: "RGBA"}[channels]
    arr = np.full((h, w, channels), 128, np.uint8)
    arr = arr[..., 0] if channels == 1 else arr
    import io

    buf = io.BytesIO()
    Image.fromarray(arr, mode).save(buf, format="PNG")
    return buf.getvalue()


def png_declared(w: int, h: int) -> bytes:
    """A PNG whose IHDR declares w x h and holds almost no data (a decompression bomb)."""
    import zlib

    def chunk(kind: bytes, data: bytes) -> bytes:
        return (
            struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
        )

    ihdr = struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", ihdr)
        + chunk(b"IDAT", zlib.compress(b""))
        + chunk(b"IEND", b"")
    )


def render(scene: str, *extra: str) -> tuple[str, ...]:
    return ("render", scene, "--out", "out", *TINY, *extra)


def textured(filename: str, kind: str = "bitmap", extra: str = "") -> str:
    return xml(
        '<shape type="rectangle"><bsdf type="diffuse"><texture type="'
        + kind
        + '" name="reflectance">'
        f'<string name="filename" value="{filename}"/>{extra}</texture></bsdf></shape>'
    )


def envmap(filename: str) -> str:
    return xml(
        RECT + f'<emitter type="envmap"><string name="filename" value="{filename}"/></emitter>'
    )


def normalmap(filename: str, scale: str = "") -> str:
    return xml(
        '<shape type="rectangle"><bsdf type="normalmap"><texture type="bitmap" name="normalmap">'
        f'<string name="filename" value="{filename}"/><boolean name="raw" value="true"/></texture>'
        '<bsdf type="diffuse"/></bsdf></shape>'
    )


def bumpmap(scale: str) -> str:
    return xml(
        '<shape type="rectangle"><bsdf type="bumpmap"><texture type="bitmap" name="arbitrary">'
        '<string name="filename" value="h.png"/><boolean name="raw" value="true"/></texture>'
        f'<float name="scale" value="{scale}"/><bsdf type="diffuse"/></bsdf></shape>'
    )


def xml_cases() -> list[Case]:
    laughs = (
        '<?xml version="1.0"?><!DOCTYPE lolz [<!ENTITY lol "lol">'
        '<!ENTITY lol2 "&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;">'
        '<!ENTITY lol3 "&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;">'
        '<!ENTITY lol4 "&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;">'
        '<!ENTITY lol5 "&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;">'
        '<!ENTITY lol6 "&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;">'
        '<!ENTITY lol7 "&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;">'
        '<!ENTITY lol8 "&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;">'
        ']><scene version="3.0.0"><string name="x" value="&lol8;"/></scene>'
    )
    glass = lambda bsdf: xml(f'<shape type="sphere">{bsdf}</shape>' + RECT)  # noqa: E731
    c: list[Case] = [
        Case("xml/billion-laughs", render("s.xml"), {"s.xml": laughs}, expect="s.xml"),
        Case(
            "xml/external-entity",
            render("s.xml"),
            {
                "s.xml": '<?xml version="1.0"?><!DOCTYPE s [<!ENTITY x SYSTEM "file:///etc/passwd">]><scene version="3.0.0"><string name="a" value="&x;"/></scene>'
            },
            expect="s.xml",
        ),
        Case(
            "xml/doctype-plain",
            render("s.xml"),
            {
                "s.xml": xml(RECT).replace(
                    '<?xml version="1.0"?>', '<?xml version="1.0"?><!DOCTYPE scene>'
                )
            },
            expect="s.xml",
            either=True,
        ),
        Case("xml/not-xml", render("s.xml"), {"s.xml": "this is not xml <<<"}, expect="s.xml"),
        Case("xml/empty", render("s.xml"), {"s.xml": ""}, expect="s.xml"),
        Case("xml/binary", render("s.xml"), {"s.xml": os.urandom(256)}, expect="s.xml"),
        Case(
            "xml/huge-width",
            render("s.xml", "--resolution", "16x16"),
            {"s.xml": xml(RECT).replace('value="16"', 'value="99999999999"', 1)},
            either=True,
        ),
        Case(
            "xml/huge-width-own",
            ("render", "s.xml", "--out", "out", "--spp", "1", "--modes", "rgb3", "-q"),
            {"s.xml": xml(RECT).replace('value="16"', 'value="99999999999"', 1)},
            expect="width",
        ),
        Case(
            "xml/negative-width-own",
            ("render", "s.xml", "--out", "out", "--spp", "1", "--modes", "rgb3", "-q"),
            {"s.xml": xml(RECT).replace('value="16"', 'value="-4"', 1)},
            expect="width",
        ),
        Case(
            "xml/huge-max-depth",
            render("s.xml"),
            {
                "s.xml": xml(
                    RECT
                    + '<integrator type="path"><integer name="max_depth" value="99999999999999999999"/></integrator>'
                )
            },
            expect="integer",
        ),
        Case(
            "xml/float-1e999-radius",
            render("s.xml"),
            {
                "s.xml": xml(
                    '<shape type="sphere"><float name="radius" value="1e999"/><bsdf type="diffuse"/></shape>'
                )
            },
            expect="s.xml",
        ),
        Case(
            "xml/float-nan-radius",
            render("s.xml"),
            {
                "s.xml": xml(
                    '<shape type="sphere"><float name="radius" value="nan"/><bsdf type="diffuse"/></shape>'
                )
            },
            expect="s.xml",
        ),
        Case(
            "xml/float-negative-radius",
            render("s.xml"),
            {
                "s.xml": xml(
                    '<shape type="sphere"><float name="radius" value="-1"/><bsdf type="diffuse"/></shape>'
                )
            },
            expect="sphere radius -1; expected > 0",
        ),
        Case(
            "xml/sphere-light-negative-radius",
            render("s.xml"),
            {
                "s.xml": xml(
                    RECT + '<shape type="sphere"><float name="radius" value="-0.2"/>'
                    '<emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>'
                )
            },
            expect="sphere radius -0.2; expected > 0",
        ),
        Case(
            "xml/reflectance-nan",
            render("s.xml"),
            {
                "s.xml": xml(
                    '<shape type="rectangle"><bsdf type="diffuse"><rgb name="reflectance" value="nan,0.5,0.5"/></bsdf></shape>'
                )
            },
            expect="s.xml",
        ),
        Case(
            "xml/reflectance-inf",
            render("s.xml"),
            {
                "s.xml": xml(
                    '<shape type="rectangle"><bsdf type="diffuse"><float name="reflectance" value="inf"/></bsdf></shape>'
                )
            },
            expect="s.xml",
        ),
        Case(
            "xml/reflectance-negative",
            render("s.xml"),
            {
                "s.xml": xml(
                    '<shape type="rectangle"><bsdf type="diffuse"><float name="reflectance" value="-0.5"/></bsdf></shape>'
                )
            },
            expect="s.xml",
        ),
        Case(
            "xml/reflectance-above-1",
            render("s.xml"),
            {
                "s.xml": xml(
                    '<shape type="rectangle"><bsdf type="diffuse"><float name="reflectance" value="3"/></bsdf></shape>'
                )
            },
            expect="s.xml",
        ),
        Case(
            "xml/light-nan",
            render("s.xml"),
            {"s.xml": xml(RECT).replace('value="5"', 'value="nan"')},
            expect="s.xml",
        ),
        Case(
            "xml/light-negative",
            render("s.xml"),
            {"s.xml": xml(RECT).replace('value="5"', 'value="-5"')},
            expect="s.xml",
        ),
        Case(
            "xml/light-1e999",
            render("s.xml"),
            {"s.xml": xml(RECT).replace('value="5"', 'value="1e999"')},
            expect="s.xml",
        ),
        Case(
            "xml/eta-nan",
            render("s.xml", "--approximate"),
            {"s.xml": glass('<bsdf type="dielectric"><float name="int_ior" value="nan"/></bsdf>')},
            expect="s.xml",
        ),
        Case(
            "xml/eta-negative",
            render("s.xml", "--approximate"),
            {"s.xml": glass('<bsdf type="dielectric"><float name="int_ior" value="-1.5"/></bsdf>')},
            expect="s.xml",
        ),
        Case(
            "xml/eta-zero",
            render("s.xml", "--approximate"),
            {"s.xml": glass('<bsdf type="dielectric"><float name="int_ior" value="0"/></bsdf>')},
            expect="s.xml",
        ),
        Case(
            "xml/eta-inf",
            render("s.xml", "--approximate"),
            {
                "s.xml": glass(
                    '<bsdf type="thindielectric"><float name="int_ior" value="inf"/></bsdf>'
                )
            },
            expect="s.xml",
        ),
        Case(
            "xml/eta-unknown-name",
            render("s.xml", "--approximate"),
            {
                "s.xml": glass(
                    '<bsdf type="dielectric"><string name="int_ior" value="unobtainium"/></bsdf>'
                )
            },
            expect="s.xml",
        ),
        Case(
            "xml/rough-alpha-nan",
            render("s.xml", "--approximate"),
            {
                "s.xml": glass(
                    '<bsdf type="roughdielectric"><float name="alpha" value="nan"/></bsdf>'
                )
            },
            expect="s.xml",
        ),
        Case(
            "xml/rough-alpha-negative",
            render("s.xml", "--approximate"),
            {
                "s.xml": glass(
                    '<bsdf type="roughdielectric"><float name="alpha" value="-0.2"/></bsdf>'
                )
            },
            expect="s.xml",
        ),
        Case(
            "xml/tint-transmittance-2",
            render("s.xml", "--approximate"),
            {
                "s.xml": glass(
                    '<bsdf type="dielectric"><rgb name="specular_transmittance" value="2,0.5,0.5"/></bsdf>'
                )
            },
            expect="s.xml",
        ),
        Case(
            "xml/tint-reflectance-nan",
            render("s.xml", "--approximate"),
            {
                "s.xml": glass(
                    '<bsdf type="dielectric"><rgb name="specular_reflectance" value="nan,0.5,0.5"/></bsdf>'
                )
            },
            expect="s.xml",
        ),
        Case(
            "xml/conductor-unknown-material",
            render("s.xml"),
            {"s.xml": glass('<bsdf type="conductor"><string name="material" value="Xx"/></bsdf>')},
            expect="s.xml",
        ),
        Case(
            "xml/conductor-eta-nan",
            render("s.xml"),
            {
                "s.xml": glass(
                    '<bsdf type="conductor"><rgb name="eta" value="nan,1,1"/><rgb name="k" value="1,1,1"/></bsdf>'
                )
            },
            expect="s.xml",
        ),
        Case(
            "xml/glass-ground-truth-exact",
            ("render", "s.xml", "--ground-truth", "--out", "out", *TINY, "--spp", "2"),
            {"s.xml": glass('<bsdf type="dielectric"/>')},
            either=True,  # clear glass has exact ground truth (mitsuba_bsdfs.GLASS)
        ),
        Case(
            "xml/unknown-plugin",
            render("s.xml"),
            {"s.xml": xml('<shape type="teapot9000"><bsdf type="diffuse"/></shape>')},
            expect="teapot9000",
        ),
        Case(
            "xml/unknown-bsdf",
            render("s.xml"),
            {"s.xml": xml('<shape type="rectangle"><bsdf type="glitter"/></shape>')},
            expect="glitter",
        ),
        Case(
            "xml/unknown-tag", render("s.xml"), {"s.xml": xml("<banana/>" + RECT)}, expect="banana"
        ),
        Case(
            "xml/missing-ref",
            render("s.xml"),
            {"s.xml": xml('<shape type="rectangle"><ref id="nope"/></shape>')},
            expect="nope",
        ),
        Case(
            "xml/duplicate-id",
            render("s.xml"),
            {
                "s.xml": xml(
                    '<bsdf type="diffuse" id="a"/><bsdf type="diffuse" id="a"/><shape type="rectangle"><ref id="a"/></shape>'
                )
            },
            expect="s.xml",
        ),
        Case(
            "xml/self-ref",
            render("s.xml"),
            {
                "s.xml": xml(
                    '<bsdf type="twosided" id="a"><ref id="a"/></bsdf><shape type="rectangle"><ref id="a"/></shape>'
                )
            },
            expect="s.xml",
        ),
        Case(
            "xml/cyclic-ref",
            render("s.xml"),
            {
                "s.xml": xml(
                    '<bsdf type="twosided" id="a"><ref id="b"/></bsdf><bsdf type="twosided" id="b"><ref id="a"/></bsdf><shape type="rectangle"><ref id="a"/></shape>'
                )
            },
            expect="s.xml",
        ),
        Case(
            "xml/missing-default",
            render("s.xml"),
            {
                "s.xml": xml(
                    '<shape type="rectangle"><bsdf type="diffuse"><float name="reflectance" value="$r"/></bsdf></shape>'
                )
            },
            expect="$r",
        ),
        Case(
            "xml/default-nan",
            render("s.xml"),
            {
                "s.xml": xml(
                    '<shape type="rectangle"><bsdf type="diffuse"><float name="reflectance" value="$r"/></bsdf></shape>',
                    "<!-- -->",
                ).replace(CAMERA, '<default name="r" value="nan"/>' + CAMERA)
            },
            expect="s.xml",
        ),
        Case(
            "xml/default-recursive",
            render("s.xml"),
            {
                "s.xml": xml(RECT).replace(
                    CAMERA, '<default name="a" value="$a"/><default name="b" value="$a"/>' + CAMERA
                )
            },
            either=True,
        ),
        Case(
            "xml/include-loop",
            render("s.xml"),
            {"s.xml": xml('<include filename="s.xml"/>' + RECT)},
            expect="include",
        ),
        Case(
            "xml/include-mutual-loop",
            render("s.xml"),
            {
                "s.xml": xml('<include filename="b.xml"/>' + RECT),
                "b.xml": '<scene version="3.0.0"><include filename="s.xml"/></scene>',
            },
            expect="include",
        ),
        Case(
            "xml/include-dotdot",
            render("in/s.xml"),
            {
                "in/s.xml": xml('<include filename="../b.xml"/>' + RECT),
                "b.xml": '<scene version="3.0.0"/>',
            },
            expect="b.xml",
        ),
        Case(
            "xml/include-absolute",
            render("s.xml"),
            {"s.xml": xml('<include filename="/etc/hostname"/>' + RECT)},
            expect="/etc/hostname",
        ),
        Case(
            "xml/include-missing",
            render("s.xml"),
            {"s.xml": xml('<include filename="gone.xml"/>' + RECT)},
            expect="gone.xml",
        ),
        Case("xml/include-deep", render("s.xml"), setup=_deep_includes, expect="include"),
        Case(
            "xml/include-symlink-out",
            render("in/s.xml"),
            {
                "in/s.xml": xml('<include filename="b.xml"/>' + RECT),
                "b_real.xml": '<scene version="3.0.0"/>',
            },
            setup=lambda d: (d / "in/b.xml").symlink_to(d / "b_real.xml"),
            expect="b.xml",
        ),
        Case(
            "xml/bitmap-dotdot",
            render("in/s.xml"),
            {"in/s.xml": textured("../t.png"), "t.png": png_bytes(4, 4)},
            expect="t.png",
        ),
        Case(
            "xml/bitmap-absolute",
            render("s.xml"),
            {
                "s.xml": textured("/usr/share/pixmaps/debian-logo.png"),
            },
            expect="png",
        ),
        Case(
            "xml/bitmap-symlink-out",
            render("in/s.xml"),
            {"in/s.xml": textured("t.png"), "real.png": png_bytes(4, 4)},
            setup=lambda d: (d / "in/t.png").symlink_to(d / "real.png"),
            expect="t.png",
        ),
        Case(
            "xml/bitmap-missing",
            render("s.xml"),
            {"s.xml": textured("gone.png")},
            expect="gone.png",
        ),
        Case(
            "xml/bitmap-not-image-png",
            render("s.xml"),
            {"s.xml": textured("t.png"), "t.png": b"hello, not a png"},
            expect="t.png",
        ),
        Case(
            "xml/bitmap-not-image-exr",
            render("s.xml"),
            {"s.xml": textured("t.exr"), "t.exr": b"hello, not an exr"},
            expect="t.exr",
        ),
        Case(
            "xml/bitmap-truncated-png",
            render("s.xml"),
            {"s.xml": textured("t.png"), "t.png": png_bytes(64, 64)[:80]},
            expect="t.png",
        ),
        Case(
            "xml/bitmap-bomb",
            render("s.xml"),
            {"s.xml": textured("t.png"), "t.png": png_declared(100000, 100000)},
            expect="t.png",
        ),
        Case(
            "xml/bitmap-directory",
            render("s.xml"),
            {"s.xml": textured("d.png"), "d.png/x": "x"},
            expect="d.png",
        ),
        Case("xml/bitmap-empty-name", render("s.xml"), {"s.xml": textured("")}, expect="s.xml"),
        Case(
            "xml/envmap-0x0",
            render("s.xml", "--approximate"),
            {"s.xml": envmap("e.png"), "e.png": png_declared(0, 0)},
            expect="e.png",
        ),
        Case(
            "xml/envmap-bomb",
            render("s.xml", "--approximate"),
            {"s.xml": envmap("e.png"), "e.png": png_declared(1000000, 1000000)},
            expect="e.png",
        ),
        Case(
            "xml/envmap-not-image",
            render("s.xml", "--approximate"),
            {"s.xml": envmap("e.exr"), "e.exr": b"nope"},
            expect="e.exr",
        ),
        Case(
            "xml/envmap-dotdot",
            render("in/s.xml", "--approximate"),
            {"in/s.xml": envmap("../e.png"), "e.png": png_bytes(8, 4)},
            expect="e.png",
        ),
        Case(
            "xml/envmap-scale-nan",
            render("s.xml", "--approximate"),
            {
                "s.xml": envmap("e.png").replace(
                    "</emitter>", '<float name="scale" value="nan"/></emitter>'
                ),
                "e.png": png_bytes(8, 4),
            },
            expect="s.xml",
        ),
        Case(
            "xml/normalmap-wrong-size",
            render("s.xml", "--approximate"),
            {"s.xml": normalmap("n.png"), "n.png": png_bytes(3, 1)},
            either=True,
        ),
        Case(
            "xml/normalmap-1-channel",
            render("s.xml", "--approximate"),
            {"s.xml": normalmap("n.png"), "n.png": png_bytes(4, 4, 1)},
            either=True,
        ),  # grey: Mitsuba reads it too
        Case(
            "xml/normalmap-not-image",
            render("s.xml", "--approximate"),
            {"s.xml": normalmap("n.png"), "n.png": b"garbage"},
            expect="n.png",
        ),
        Case(
            "xml/bumpmap-scale-nan",
            render("s.xml", "--approximate"),
            {"s.xml": bumpmap("nan"), "h.png": png_bytes(4, 4, 1)},
            expect="scale",
        ),
        Case(
            "xml/bumpmap-scale-inf",
            render("s.xml", "--approximate"),
            {"s.xml": bumpmap("inf"), "h.png": png_bytes(4, 4, 1)},
            expect="scale",
        ),
        Case(
            "xml/mask-opacity-nan",
            render("s.xml", "--approximate"),
            {
                "s.xml": xml(
                    '<shape type="rectangle"><bsdf type="mask"><float name="opacity" value="nan"/><bsdf type="diffuse"/></bsdf></shape>'
                )
            },
            expect="s.xml",
        ),
        Case(
            "xml/sunsky-nan-turbidity",
            render("s.xml", "--approximate"),
            {
                "s.xml": xml(
                    RECT + '<emitter type="sunsky"><float name="turbidity" value="nan"/></emitter>'
                )
            },
            expect="s.xml",
        ),
        Case(
            "xml/sunsky-turbidity-99",
            render("s.xml", "--approximate"),
            {
                "s.xml": xml(
                    RECT + '<emitter type="sunsky"><float name="turbidity" value="99"/></emitter>'
                )
            },
            expect="turbidity",
        ),
        Case(
            "xml/obj-dotdot",
            render("in/s.xml"),
            {
                "in/s.xml": xml(
                    '<shape type="obj"><string name="filename" value="../m.obj"/></shape>'
                ),
                "m.obj": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
            },
            expect="m.obj",
        ),
        Case(
            "xml/obj-symlink-out",
            render("in/s.xml"),
            {
                "in/s.xml": xml(
                    '<shape type="obj"><string name="filename" value="m.obj"/></shape>'
                ),
                "real.obj": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
            },
            setup=lambda d: (d / "in/m.obj").symlink_to(d / "real.obj"),
            expect="m.obj",
        ),
        Case(
            "xml/obj-garbage",
            render("s.xml"),
            {
                "s.xml": xml('<shape type="obj"><string name="filename" value="m.obj"/></shape>'),
                "m.obj": "v a b c\nf 1 2 9\n",
            },
            expect="m.obj",
        ),
        Case(
            "xml/obj-nan-vertex",
            render("s.xml"),
            {
                "s.xml": xml(
                    '<shape type="obj"><string name="filename" value="sub/m.obj"/></shape>'
                ),
                "sub/m.obj": "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
            },
            expect="mesh file 'sub/m.obj': 1 vertices are NaN",
        ),
        Case(
            "xml/obj-nan-vertex-textured",
            render("s.xml"),
            {
                "s.xml": xml(
                    '<shape type="obj"><string name="filename" value="sub/m.obj"/>'
                    '<bsdf type="diffuse"><texture type="bitmap" name="reflectance">'
                    '<string name="filename" value="t.png"/></texture></bsdf></shape>'
                ),
                "sub/m.obj": "v nan 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n",
                "t.png": png_bytes(2, 2),
            },
            expect="mesh file 'sub/m.obj'",
        ),
        Case(
            "xml/obj-index-out-of-range",
            render("s.xml"),
            {
                "s.xml": xml('<shape type="obj"><string name="filename" value="m.obj"/></shape>'),
                "m.obj": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n",
            },
            expect="m.obj",
        ),
        Case(
            "xml/ply-garbage",
            render("s.xml"),
            {
                "s.xml": xml('<shape type="ply"><string name="filename" value="m.ply"/></shape>'),
                "m.ply": b"ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\nproperty float x\nend_header\n",
            },
            expect="ply",
        ),
        Case(
            "xml/serialized-garbage",
            render("s.xml"),
            {
                "s.xml": xml(
                    '<shape type="serialized"><string name="filename" value="m.serialized"/></shape>'
                ),
                "m.serialized": b"\x1c\x04" + os.urandom(64),
            },
            expect="m.serialized",
        ),
        Case(
            "xml/transform-nan",
            render("s.xml"),
            {
                "s.xml": xml(
                    '<shape type="rectangle"><transform name="to_world"><scale value="nan"/></transform><bsdf type="diffuse"/></shape>'
                )
            },
            expect="s.xml",
        ),
        Case(
            "xml/transform-singular",
            render("s.xml"),
            {
                "s.xml": xml(
                    '<shape type="rectangle"><transform name="to_world"><scale value="0"/></transform><bsdf type="diffuse"/></shape>'
                )
            },
            either=True,
        ),
        Case(
            "xml/no-camera", render("s.xml"), {"s.xml": xml(RECT).replace(CAMERA, "")}, either=True
        ),
        Case("xml/no-shapes", render("s.xml"), {"s.xml": xml("")}, expect="s.xml"),
        Case(
            "xml/version-bogus",
            render("s.xml"),
            {"s.xml": xml(RECT).replace('version="3.0.0"', 'version="banana"')},
            expect="version",
        ),
        Case(
            "xml/bitmap-wrong-type-texture",
            render("s.xml"),
            {"s.xml": textured("t.png", kind="checkerboard")},
            either=True,
            expect="s.xml",
        ),
    ]
    return c


def _deep_includes(d: Path) -> None:
    (d / "s.xml").write_text(xml('<include filename="i0.xml"/>' + RECT))
    for i in range(300):
        (d / f"i{i}.xml").write_text(
            f'<scene version="3.0.0"><include filename="i{i + 1}.xml"/></scene>'
        )
    (d / "i300.xml").write_text('<scene version="3.0.0"/>')


def gltf(doc: dict, bin_data: bytes | None = None) -> dict[str, str | bytes]:
    files: dict[str, str | bytes] = {"s.gltf": json.dumps(doc)}
    if bin_data is not None:
        files["b.bin"] = bin_data
    return files


def _tri_doc(uri: str | None = None, byte_length: int = 42, **over: object) -> dict:
    pos = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
    idx = struct.pack("<3H", 0, 1, 2)
    data = pos + idx
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
        "materials": [
            {"name": "m", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}}
        ],
        "buffers": [
            {
                "uri": uri
                or "data:application/octet-stream;base64," + base64.b64encode(data).decode(),
                "byteLength": byte_length,
            }
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 6},
        ],
        "accessors": [
            {
                "bufferView": 0,
                "componentType": 5126,
                "count": 3,
                "type": "VEC3",
                "min": [0, 0, 0],
                "max": [1, 1, 0],
            },
            {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"},
        ],
    }
    doc.update(over)
    return doc


def _with_texture(doc: dict, image: dict, tex_index: int = 0) -> dict:
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": tex_index}
    doc["textures"] = [{"source": 0}]
    doc["images"] = [image]
    # texture coordinates
    return doc


def gltf_cases() -> list[Case]:
    tri = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<3H", 0, 1, 2)
    c = [
        Case("gltf/valid-control", render("s.gltf"), gltf(_tri_doc()), either=True),
        Case(
            "gltf/data-uri-short",
            render("s.gltf"),
            gltf(_tri_doc(byte_length=4200)),
            expect="s.gltf",
        ),
        Case(
            "gltf/data-uri-bad-base64",
            render("s.gltf"),
            gltf(_tri_doc(uri="data:application/octet-stream;base64,@@@@")),
            expect="s.gltf",
        ),
        Case(
            "gltf/accessor-count-too-big",
            render("s.gltf"),
            gltf(
                _tri_doc(
                    accessors=[
                        {"bufferView": 0, "componentType": 5126, "count": 300000, "type": "VEC3"},
                        {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"},
                    ]
                )
            ),
            expect="s.gltf",
        ),
        Case(
            "gltf/index-out-of-range",
            render("s.gltf"),
            gltf(
                _tri_doc(
                    uri="data:application/octet-stream;base64,"
                    + base64.b64encode(tri[:36] + struct.pack("<3H", 0, 1, 999)).decode()
                )
            ),
            expect="s.gltf",
        ),
        Case(
            "gltf/accessor-ref-missing",
            render("s.gltf"),
            gltf(
                _tri_doc(meshes=[{"primitives": [{"attributes": {"POSITION": 7}, "indices": 1}]}])
            ),
            expect="s.gltf",
        ),
        Case(
            "gltf/bufferview-past-buffer",
            render("s.gltf"),
            gltf(
                _tri_doc(
                    bufferViews=[
                        {"buffer": 0, "byteOffset": 0, "byteLength": 36},
                        {"buffer": 0, "byteOffset": 4000, "byteLength": 6},
                    ]
                )
            ),
            expect="s.gltf",
        ),
        Case(
            "gltf/buffer-2GB-declared",
            render("s.gltf"),
            gltf(_tri_doc(uri="b.bin", byte_length=2_000_000_000), tri),
            expect="s.gltf",
        ),
        Case(
            "gltf/buffer-uri-dotdot",
            render("in/s.gltf"),
            {"in/s.gltf": json.dumps(_tri_doc(uri="../b.bin")), "b.bin": tri},
            expect="b.bin",
        ),
        Case(
            "gltf/buffer-uri-absolute",
            render("s.gltf"),
            gltf(_tri_doc(uri="/etc/hostname")),
            expect="hostname",
        ),
        Case(
            "gltf/buffer-uri-missing",
            render("s.gltf"),
            gltf(_tri_doc(uri="gone.bin")),
            expect="gone.bin",
        ),
        Case(
            "gltf/texture-index-out-of-range",
            render("s.gltf"),
            gltf(_with_texture(_tri_doc(), {"uri": "t.png"}, 5)) | {"t.png": png_bytes(4, 4)},
            expect="s.gltf",
        ),
        Case(
            "gltf/image-uri-dotdot",
            render("in/s.gltf"),
            {
                "in/s.gltf": json.dumps(_with_texture(_tri_doc(), {"uri": "../t.png"})),
                "t.png": png_bytes(4, 4),
            },
            expect="t.png",
        ),
        Case(
            "gltf/image-uri-absolute",
            render("s.gltf"),
            gltf(_with_texture(_tri_doc(), {"uri": "/usr/share/pixmaps/x.png"})),
            expect="x.png",
        ),
        Case(
            "gltf/image-not-image",
            render("s.gltf"),
            gltf(_with_texture(_tri_doc(), {"uri": "t.png"})) | {"t.png": b"not a png"},
            expect="s.gltf",
        ),
        Case(
            "gltf/image-bomb",
            render("s.gltf"),
            gltf(_with_texture(_tri_doc(), {"uri": "t.png"}))
            | {"t.png": png_declared(100000, 100000)},
            expect="s.gltf",
        ),
        Case(
            "gltf/transmission-nan",
            render("s.gltf"),
            gltf(
                _tri_doc(
                    materials=[
                        {
                            "name": "m",
                            "extensions": {
                                "KHR_materials_transmission": {"transmissionFactor": "nan"}
                            },
                        }
                    ]
                )
            ),
            expect="s.gltf",
        ),
        Case(
            "gltf/transmission-2",
            render("s.gltf"),
            gltf(
                _tri_doc(
                    materials=[
                        {
                            "name": "m",
                            "extensions": {"KHR_materials_transmission": {"transmissionFactor": 2}},
                        }
                    ]
                )
            ),
            expect="s.gltf",
        ),
        Case(
            "gltf/specular-negative",
            render("s.gltf"),
            gltf(
                _tri_doc(
                    materials=[
                        {
                            "name": "m",
                            "extensions": {"KHR_materials_specular": {"specularFactor": -1}},
                        }
                    ]
                )
            ),
            expect="s.gltf",
        ),
        Case("gltf/not-json", render("s.gltf"), {"s.gltf": "{not json"}, expect="s.gltf"),
        Case("gltf/json-array", render("s.gltf"), {"s.gltf": "[1,2,3]"}, expect="s.gltf"),
        Case(
            "gltf/glb-garbage", render("s.glb"), {"s.glb": b"glTF" + os.urandom(40)}, expect="s.glb"
        ),
        Case(
            "gltf/glb-huge-chunk",
            render("s.glb"),
            {
                "s.glb": b"glTF"
                + struct.pack("<II", 2, 0xFFFFFFF0)
                + struct.pack("<I", 0xFFFFFF00)
                + b"JSON"
            },
            expect="s.glb",
        ),
        Case(
            "gltf/basecolor-nan",
            render("s.gltf"),
            gltf(
                _tri_doc(
                    materials=[
                        {
                            "name": "m",
                            "pbrMetallicRoughness": {
                                "baseColorFactor": [float("nan"), 0.5, 0.5, 1]
                            },
                        }
                    ]
                )
            ),
            expect="s.gltf",
        ),
    ]
    return c


def blend_cases() -> list[Case]:
    return [
        Case("blend/not-a-blend", render("s.blend"), {"s.blend": "hello"}, expect="s.blend"),
        Case(
            "blend/truncated",
            render("s.blend"),
            {"s.blend": b"BLENDER-v400" + b"\0" * 40},
            expect="s.blend",
        ),
        Case("blend/empty", render("s.blend"), {"s.blend": b""}, expect="s.blend"),
    ]


def csv_light(csv: str, col: str = "lamp") -> tuple[str, ...]:
    return ("relight", SAMPLE, "--light", f"0=csv:{csv}#{col}", "--out", "out", "-q")


def csv_cases() -> list[Case]:
    good = "wavelength,lamp [W/m2/nm]\n" + "".join(f"{w},{1.0}\n" for w in range(380, 790, 10))
    rows = lambda f: "wavelength,lamp [W/m2/nm]\n" + "".join(f(w) for w in range(380, 790, 10))  # noqa: E731
    # relight's light spectrum from l.csv: every such case names the file in its refusal
    light_csv = {
        "not-increasing": "wavelength,lamp [W/m2/nm]\n500,1\n400,1\n600,1\n",
        "duplicate-wavelength": "wavelength,lamp [W/m2/nm]\n400,1\n400,1\n600,1\n",
        "nan": rows(lambda w: f"{w},{'nan' if w == 500 else 1}\n"),
        "inf": rows(lambda w: f"{w},{'inf' if w == 500 else 1}\n"),
        "negative": rows(lambda w: f"{w},{-1 if w == 500 else 1}\n"),
        "all-zero": rows(lambda w: f"{w},0\n"),
        "negative-wavelength": "wavelength,lamp [W/m2/nm]\n-5,1\n400,1\n700,1\n",
        "bom": ("\ufeff" + good).encode(),
        "semicolons": good.replace(",", ";"),
        "decimal-comma": good.replace(",", ";").replace("1.0", "1,0"),
    }
    odd_but_valid = {"bom", "semicolons", "decimal-comma"}
    c = [Case("csv/control", csv_light("l.csv"), {"l.csv": good}, setup=_sample, either=True)]
    c += [
        Case(
            f"csv/{name}",
            csv_light("l.csv"),
            {"l.csv": text},
            setup=_sample,
            either=name in odd_but_valid,
            expect="l.csv",
        )
        for name, text in light_csv.items()
    ]
    c += [
        Case(
            "csv/huge-file",
            csv_light("l.csv"),
            setup=lambda d: (_sample(d), _sparse(d / "l.csv", 2_000_000_000)),
            expect="l.csv",
        ),
        Case(
            "csv/missing-column",
            csv_light("l.csv", "nope"),
            {"l.csv": good},
            setup=_sample,
            expect="nope",
        ),
        Case("csv/missing-file", csv_light("gone.csv"), setup=_sample, expect="gone.csv"),
        Case(
            "csv/binary",
            csv_light("l.csv"),
            {"l.csv": os.urandom(300)},
            setup=_sample,
            expect="l.csv",
        ),
        Case(
            "csv/one-row",
            csv_light("l.csv"),
            {"l.csv": "wavelength,lamp [W/m2/nm]\n500,1\n"},
            setup=_sample,
            expect="l.csv",
        ),
        Case(
            "csv/out-of-visible",
            csv_light("l.csv"),
            {"l.csv": "wavelength,lamp [W/m2/nm]\n1000,1\n2000,1\n"},
            setup=_sample,
            expect="l.csv",
        ),
        Case(
            "csv/camera-bad",
            (
                "render",
                "quad.yaml",
                "--ground-truth",
                "--out",
                "out",
                "--resolution",
                "16x16",
                "--spp",
                "2",
                "--modes",
                "bands31",
                "-q",
                "--camera",
                "csv:cam.csv",
            ),
            {"quad.yaml": QUAD_YAML, "cam.csv": "wavelength,r,g,b\n500,1,nan,1\n400,1,1,1\n"},
            expect="cam.csv",
        ),
        Case(
            "csv/scene-yaml-spectrum-nan",
            render("q.yaml"),
            {
                "q.yaml": QUAD_YAML.replace('"flat:0.5"', '"csv:p.csv#paint"'),
                "p.csv": rows(lambda w: f"{w},{'nan' if w == 500 else 0.5}\n").replace(
                    "lamp [W/m2/nm]", "paint [1]"
                ),
            },
            expect="p.csv",
        ),
        Case(
            "csv/scene-yaml-spectrum-dotdot",
            render("in/q.yaml"),
            {
                "in/q.yaml": QUAD_YAML.replace('"flat:0.5"', '"csv:../p.csv#paint"'),
                "p.csv": good.replace("lamp [W/m2/nm]", "paint [1]").replace("1.0", "0.5"),
            },
            expect="p.csv",
        ),
        Case(
            "csv/scene-yaml-spectrum-absolute",
            render("q.yaml"),
            {"q.yaml": QUAD_YAML.replace('"flat:0.5"', '"csv:/etc/passwd#paint"')},
            expect="passwd",
        ),
    ]
    return c


def _sparse(path: Path, size: int) -> None:
    with open(path, "wb") as f:
        f.write(b"wavelength,lamp [W/m2/nm]\n")
        f.truncate(size)


#: The ids (folder names) of the two samples built once, as the build names them.
SAMPLE = CSAMPLE = "quad__v0__file"  # both scenes are named quad
#: A relightable sample built once (render --ground-truth --store-transport) and copied.
_SAMPLE_CACHE: list[Path] = []


def _sample(d: Path) -> None:
    if not _SAMPLE_CACHE:
        raise RuntimeError("sample not built")
    shutil.copytree(_SAMPLE_CACHE[0], d / SAMPLE, symlinks=True)


def _edit_meta(d: Path, edit: Callable[[dict], None]) -> None:
    _sample(d)
    meta = json.loads((d / SAMPLE / "meta.json").read_text())
    edit(meta)
    (d / SAMPLE / "meta.json").write_text(json.dumps(meta))


def _set(path: str, value: object) -> Callable[[dict], None]:
    def edit(meta: dict) -> None:
        keys = path.split(".")
        node = meta
        for k in keys[:-1]:
            node = node[int(k)] if isinstance(node, list) else node[k]
        last = keys[-1]
        if isinstance(node, list):
            node[int(last)] = value
        else:
            node[last] = value

    return edit


def relight_cases() -> list[Case]:
    rl = ("relight", SAMPLE, "--light", "0=planck:3000K", "--out", "out", "-q")
    c = [
        Case("relight/control", rl, setup=_sample, either=True),
        Case(
            "relight/no-transport",
            rl,
            setup=lambda d: (_sample(d), (d / SAMPLE / "transport.exr").unlink()),
            expect="transport",
        ),
        Case(
            "relight/transport-garbage",
            rl,
            setup=lambda d: (_sample(d), (d / SAMPLE / "transport.exr").write_bytes(b"junk")),
            expect="transport.exr",
        ),
        Case(
            "relight/meta-not-json",
            rl,
            setup=lambda d: (_sample(d), (d / SAMPLE / "meta.json").write_text("{")),
            expect="meta.json",
        ),
        Case(
            "relight/meta-missing",
            rl,
            setup=lambda d: (_sample(d), (d / SAMPLE / "meta.json").unlink()),
            expect="meta.json",
        ),
        Case(
            "relight/meta-lights-empty",
            rl,
            setup=lambda d: _edit_meta(d, _set("lights", [])),
            expect="meta.json",
        ),
        Case(
            "relight/meta-nan",
            rl,
            setup=lambda d: _edit_meta(d, _set("seed", float("nan"))),
            expect="meta.json",
        ),
        Case(
            "relight/meta-light-power-string",
            rl,
            setup=lambda d: _edit_meta(d, lambda m: m["lights"][0].update(power="lots")),
            expect="meta.json",
        ),
        Case(
            "relight/meta-working-space-bogus",
            rl,
            setup=lambda d: _edit_meta(d, _set("working_space", "bogus")),
            expect="bogus",
        ),
        Case(
            "relight/light-index-out-of-range",
            ("relight", SAMPLE, "--light", "7=planck:3000K", "--out", "out", "-q"),
            setup=_sample,
            expect="7",
        ),
        Case(
            "relight/light-index-negative",
            ("relight", SAMPLE, "--light=-1=planck:3000K", "--out", "out", "-q"),
            setup=_sample,
            expect="-1",
        ),
        Case(
            "relight/light-unknown-spectrum",
            ("relight", SAMPLE, "--light", "0=planck:banana", "--out", "out", "-q"),
            setup=_sample,
            expect="banana",
        ),
        Case(
            "relight/light-planck-0K",
            ("relight", SAMPLE, "--light", "0=planck:0K", "--out", "out", "-q"),
            setup=_sample,
            expect="0K",
        ),
        Case("relight/power-nan", (*rl, "--power", "0=nan"), setup=_sample, expect="nan"),
        Case("relight/power-negative", (*rl, "--power", "0=-3"), setup=_sample, expect="-3"),
        Case("relight/power-1e999", (*rl, "--power", "0=1e999"), setup=_sample, expect="power"),
        Case("relight/light-twice", (*rl, "--light", "0=planck:5000K"), setup=_sample, expect="0"),
        Case(
            "relight/out-is-sample",
            ("relight", SAMPLE, "--light", "0=planck:3000K", "--out", SAMPLE, "-q"),
            setup=_sample,
            expect=SAMPLE,
        ),
        Case(
            "relight/out-is-user-file",
            ("relight", SAMPLE, "--light", "0=planck:3000K", "--out", "user.txt", "-q"),
            {"user.txt": "mine\n"},
            setup=_sample,
            expect="user.txt",
        ),
        Case(
            "relight/out-nonempty-user-folder",
            ("relight", SAMPLE, "--light", "0=planck:3000K", "--out", "mine", "-q"),
            {"mine/a.txt": "mine\n"},
            setup=_sample,
            expect="mine",
        ),
        Case(
            "relight/sample-is-file",
            ("relight", "user.txt", "--light", "0=planck:3000K", "--out", "out", "-q"),
            {"user.txt": "x"},
            expect="user.txt",
        ),
        Case(
            "relight/scene-dir-missing", (*rl, "--scene-dir", "gone"), setup=_sample, expect="gone"
        ),
        Case(
            "relight/csv-edited-after-build",
            (
                "relight",
                CSAMPLE,
                "--light",
                "0=planck:3000K",
                "--out",
                "out",
                "-q",
                "--scene-dir",
                ".",
            ),
            setup=_csv_sample_edited,
            expect="csv",
        ),
    ]
    return c


def _csv_sample_edited(d: Path) -> None:
    if len(_SAMPLE_CACHE) < 2:
        raise RuntimeError("csv sample not built")
    shutil.copytree(_SAMPLE_CACHE[1], d / CSAMPLE, symlinks=True)
    base = next(p for p in _SAMPLE_CACHE[1].parents if p.name == "_samples")
    shutil.copy(base / "p.csv", d / "p.csv")
    text = (d / "p.csv").read_text().replace("0.5", "0.6")
    (d / "p.csv").write_text(text)


def list_cases() -> list[Case]:
    ds = ("dataset", "--scenes")
    tail = ("--out", "out", "--preset", "preview", "--resolution", "16x16", "--spp", "2", "-q")
    return [
        Case(
            "scenes/missing-entry",
            (*ds, "quad.yaml", "gone.yaml", *tail),
            {"quad.yaml": QUAD_YAML},
            expect="gone.yaml",
        ),
        Case(
            "scenes/duplicate",
            (*ds, "quad.yaml", "quad.yaml", *tail),
            {"quad.yaml": QUAD_YAML},
            expect="quad",
        ),
        Case(
            "scenes/same-via-dotslash",
            (*ds, "quad.yaml", "./quad.yaml", *tail),
            {"quad.yaml": QUAD_YAML},
            expect="quad",
        ),
        Case(
            "scenes/same-stem-two-folders",
            (*ds, "a/quad.yaml", "b/quad.yaml", *tail),
            {"a/quad.yaml": QUAD_YAML, "b/quad.yaml": QUAD_YAML},
            either=True,
            expect="quad",
        ),
        Case(
            "scenes/directory",
            (*ds, "d", *tail),
            {"d/x.txt": "x"},
            expect="--scenes 'd' is a folder; expected scene files",
        ),
        Case(
            "scenes/list-file-itself",
            (*ds, "list.txt", *tail),
            {"list.txt": "list.txt\n"},
            expect="list.txt",
        ),
        Case(
            "scenes/list-file-missing-entry",
            (*ds, "list.txt", *tail),
            {"list.txt": "gone.yaml\n"},
            expect="list.txt",
        ),
        Case(
            "scenes/list-file-duplicate",
            (*ds, "list.txt", *tail),
            {"list.txt": "quad.yaml\nquad.yaml\n", "quad.yaml": QUAD_YAML},
            expect="list.txt",
        ),
        Case(
            "scenes/list-file-dotdot",
            (*ds, "in/list.txt", *tail),
            {"in/list.txt": "../quad.yaml\n", "quad.yaml": QUAD_YAML},
            expect="list.txt",
        ),
        Case("scenes/unknown-extension", (*ds, "a.txt2", *tail), {"a.txt2": "x"}, expect="a.txt2"),
        Case(
            "scenes/out-inside-scene-list",
            (*ds, "quad.yaml", "--out", "quad.yaml", "--preset", "preview", "-q"),
            {"quad.yaml": QUAD_YAML},
            expect="quad.yaml",
        ),
        Case(
            "scenes/with-generator",
            (*ds, "quad.yaml", "--generator", "rooms", *tail),
            {"quad.yaml": QUAD_YAML},
            expect="--generator",
        ),
        Case(
            "scenes/generator-option-ignored",
            (*ds, "quad.yaml", "--glass", "0.5", *tail),
            {"quad.yaml": QUAD_YAML},
            expect="--glass",
        ),
        Case(
            "scenes/daylight-share-ignored",
            (*ds, "quad.yaml", "--daylight-share", "0.5", *tail),
            {"quad.yaml": QUAD_YAML},
            expect="--daylight-share",
        ),
    ]


def option_cases() -> list[Case]:
    q = {"quad.yaml": QUAD_YAML}
    gt = ("render", "quad.yaml", "--ground-truth", "--out", "out", *TINY)
    return [
        Case("opt/gt-per-light", (*gt, "--per-light"), q, expect="--per-light"),
        Case("opt/gt-no-aovs", (*gt, "--no-aovs"), q, expect="--no-aovs"),
        Case(
            "opt/raw-store-transport",
            (*render("quad.yaml"), "--store-transport"),
            q,
            expect="--store-transport",
        ),
        Case(
            "opt/raw-camera",
            (*render("quad.yaml"), "--camera", "canon-eos-5d"),
            q,
            expect="--camera",
        ),
        Case(
            "opt/raw-working-space",
            (*render("quad.yaml"), "--working-space", "srgb"),
            q,
            expect="--working-space",
        ),
        Case(
            "opt/raw-spectral-layers",
            (*render("quad.yaml"), "--spectral-layers"),
            q,
            expect="--spectral-layers",
        ),
        Case("opt/raw-preset", (*render("quad.yaml"), "--preset", "preview"), q, expect="--preset"),
        Case(
            "opt/raw-new-sample", (*render("quad.yaml"), "--new-sample"), q, expect="--new-sample"
        ),
        Case(
            "opt/yaml-approximate",
            (*render("quad.yaml"), "--approximate"),
            q,
            expect="--approximate",
        ),
        Case(
            "opt/yaml-material-map",
            (*render("quad.yaml"), "--material-map", "m.yaml"),
            q | {"m.yaml": "a: flat:0.5\n"},
            expect="--material-map",
        ),
        Case(
            "opt/library-approximate",
            (*render("room-living"), "--approximate"),
            expect="--approximate",
        ),
        Case(
            "opt/library-condition-on-file",
            (*render("quad.yaml"), "--condition", "warm"),
            q,
            expect="--condition",
        ),
        Case("opt/yaml-view-on-file", (*render("quad.yaml"), "--view", "2"), q, expect="--view"),
        Case(
            "opt/store-transport-direct-rgb3",
            (
                "render",
                "quad.yaml",
                "--ground-truth",
                "--store-transport",
                "--direct",
                "--out",
                "out",
                *TINY,
                "--spp",
                "2",
            ),
            q,
            expect="direct",
        ),
        Case(
            "opt/dataset-relight-without-transport",
            (
                "dataset",
                "--scenes",
                "quad.yaml",
                "--relight",
                "2",
                "--out",
                "out",
                "--preset",
                "preview",
                "--resolution",
                "16x16",
                "--spp",
                "2",
                "-q",
            ),
            q,
            expect="--relight",
        ),
        Case(
            "opt/max-batches-without-noise-target",
            (
                "dataset",
                "--scenes",
                "quad.yaml",
                "--max-batches",
                "3",
                "--out",
                "out",
                "--preset",
                "preview",
                "--resolution",
                "16x16",
                "--spp",
                "2",
                "-q",
            ),
            q,
            expect="--max-batches",
        ),
        Case("opt/spp-zero", (*render("quad.yaml"), "--spp", "0"), q, expect="--spp"),
        Case(
            "opt/resolution-0x0",
            (*render("quad.yaml"), "--resolution", "0x0"),
            q,
            expect="--resolution",
        ),
        Case(
            "opt/resolution-huge",
            (*render("quad.yaml"), "--resolution", "100000x100000"),
            q,
            expect="--resolution",
        ),
        Case(
            "opt/max-depth-0", (*render("quad.yaml"), "--max-depth", "0"), q, expect="--max-depth"
        ),
        Case(
            "opt/out-is-user-file",
            ("render", "quad.yaml", "--out", "quad.yaml", *TINY),
            q,
            expect="quad.yaml",
        ),
        Case(
            "opt/semantic-map-bad-regex",
            (
                "render",
                "quad.yaml",
                "--ground-truth",
                "--semantic-map",
                "m.yaml",
                "--out",
                "out",
                *TINY,
            ),
            q | {"m.yaml": "'([': wall\n"},
            expect="m.yaml",
        ),
        Case(
            "opt/colours-from-asset-yaml",
            (*render("quad.yaml"), "--colours-from-asset"),
            q,
            expect="--colours-from-asset",
        ),
    ]


def user_cases() -> list[Case]:
    """A new researcher's first day (task r5-probe2): mistyped verbs, options and choices, a
    file where a folder is expected, an --out that is a file, a scenes folder or a dataset."""
    q = {"quad.yaml": QUAD_YAML}
    f = {"f.txt": "notes\n"}
    ds = {"ds/.spectrinsic-dataset": json.dumps({"spectrinsic_dataset": 1})}
    r = ("render", "quad.yaml")
    gt = ("--ground-truth", "--out", "out", "--preset", "preview", "-q")
    ts = ("dataset", "--out", "out", "--preset", "preview", "-q")
    return [
        Case("user/no-verb", (), expect="COMMAND"),
        Case("user/mistyped-verb", ("rendr", "quad.yaml"), q, expect="did you mean 'render'"),
        Case(
            "user/mistyped-option",
            (*render("quad.yaml"), "--resolutoin", "16x16"),
            q,
            expect="did you mean '--resolution'",
        ),
        Case(
            "user/mistyped-flag",
            (*render("quad.yaml"), "--ground-truht"),
            q,
            expect="did you mean '--ground-truth'",
        ),
        Case("user/mistyped-preset", (*ts, "--preset", "previw"), expect="'preview'"),
        Case("user/mistyped-study", ("study", "photometrc"), expect="'photometric'"),
        Case("user/mistyped-list", ("list", "scnes"), expect="did you mean 'scenes'"),
        Case("user/mistyped-mode", (*render("quad.yaml"), "--modes", "rgb4"), q, expect="rgb4"),
        Case("user/out-is-a-file", (*r, "--out", "f.txt", *TINY), q | f, expect="is a file"),
        Case(
            "user/out-below-a-file",
            (*r, "--out", "f.txt/o", *TINY),
            q | f,
            expect="lies below the file",
        ),
        Case(
            "user/out-is-the-scenes-folder",
            ("render", "sc/quad.yaml", "--out", "sc", *TINY),
            {"sc/quad.yaml": QUAD_YAML},
            expect="is not empty",
        ),
        Case(
            "user/out-not-writable",
            (*r, "--out", "/proc/spectrinsic-probe", *TINY),
            q,
            expect="not writable",
        ),
        Case(
            "user/out-is-a-dataset",
            (*r, "--out", "ds", *TINY),
            q | ds,
            expect="'ds' is a spectrinsic dataset, not",
        ),
        Case(
            "user/scene-is-a-folder",
            ("render", "sc", "--out", "out", *TINY),
            {"sc/quad.yaml": QUAD_YAML},
            expect="is a folder",
        ),
        Case("user/scene-empty", ("render", "", "--out", "out", *TINY), expect="scene ''"),
        Case("user/scenes-entry-empty", (*ts, "--scenes", ""), expect="an empty path"),
        Case("user/scenes-no-files", (*ts, "--scenes"), expect="--scenes"),
        Case(
            "user/library-typo-ground-truth",
            ("render", "room-cornr", *gt),
            expect="did you mean 'room-corner'",
        ),
        Case(
            "user/library-view-ground-truth",
            ("render", "room-corner", "--view", "7", *gt),
            expect="view 7",
        ),
        Case(
            "user/resolution-one-number",
            (*r, "--out", "out", "--resolution", "16"),
            q,
            expect="--resolution",
        ),
        Case(
            "user/resolution-and-width",
            (*render("quad.yaml"), "--width", "32"),
            q,
            expect="give one",
        ),
        Case("user/spp-fraction", (*r, "--out", "out", "--spp", "1.5"), q, expect="--spp"),
        Case("user/seed-negative", (*render("quad.yaml"), "--seed", "-1"), q, expect="--seed"),
        Case("user/workers-zero", (*ts, "--workers", "0"), expect="--workers"),
        Case(
            "user/split-two-shares",
            (*ts, "--split-fractions", "0.5,0.5"),
            expect="--split-fractions",
        ),
        Case("user/check-a-file", ("check", "f.txt"), f, expect="is a file, not a folder"),
        Case("user/check-missing", ("check", "gone"), expect="'gone' does not exist"),
        Case(
            "user/data-dir-a-file",
            ("--data-dir", "f.txt", "info"),
            f,
            expect="is a file, not a folder",
        ),
        Case(
            "user/evaluate-dataset-a-file",
            ("evaluate", "--dataset", "f.txt", "--out", "out"),
            f,
            expect="is a file, not a folder",
        ),
        Case(
            "user/evaluate-dataset-missing",
            ("evaluate", "--dataset", "gone", "--out", "out"),
            expect="does not exist",
        ),
        Case(
            "user/export-not-a-dataset",
            ("export", "d", "--out", "out"),
            {"d/x.txt": "x"},
            expect="no manifest.json",
        ),
        Case(
            "user/train-not-a-dataset",
            ("train", "d", "--out", "out"),
            {"d/x.txt": "x"},
            expect="no manifest.json",
        ),
        Case(
            "user/relight-no-light",
            ("relight", "d", "--out", "out"),
            {"d/x.txt": "x"},
            expect="--light",
        ),
        Case(
            "user/modes-twice",
            (*r, "--out", "out", "--modes", "rgb3,rgb3"),
            q,
            expect="rgb3 given twice",
        ),
        Case(
            "user/modes-capitals",
            (*r, "--out", "out", "--modes", "RGB3"),
            q,
            expect="did you mean 'rgb3'",
        ),
        Case("user/data-dir-empty", ("--data-dir", "", "info"), expect="an empty path"),
        Case(
            "user/mit-a-file",
            ("evaluate", "--mit", "f.txt", "--out", "out"),
            f,
            expect="'f.txt' is a file, not a folder",
        ),
    ]


def all_cases() -> list[Case]:
    return [
        *xml_cases(),
        *gltf_cases(),
        *blend_cases(),
        *csv_cases(),
        *relight_cases(),
        *list_cases(),
        *option_cases(),
        *user_cases(),
    ]


def _snapshot(d: Path) -> dict[str, str]:
    out: dict[str, str] = {}
    for p in sorted(d.rglob("*")):
        rel = p.relative_to(d).as_posix()
        if rel == "out" or rel.startswith("out/"):
            continue
        if p.is_symlink():
            out[rel] = "link:" + os.readlink(p)
        elif p.is_file():
            st = p.stat()
            out[rel] = (
                f"{st.st_size}:{st.st_mtime_ns}"
                if st.st_size > 10_000_000
                else hashlib.sha256(p.read_bytes()).hexdigest()
            )
    return out


def _cmd(argv: tuple[str, ...]) -> list[str]:
    return [sys.executable, "-P", "-m", "spectrinsic", *argv]


def run_case(case: Case, root: Path, timeout: float) -> tuple[str, str]:
    d = root / case.name.replace("/", "__")
    d.mkdir(parents=True)
    for name, content in case.files.items():
        p = d / name
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_bytes(content) if isinstance(content, bytes) else p.write_text(content)
    if case.setup is not None:
        try:
            case.setup(d)
        except Exception as exc:  # noqa: BLE001 - a probe's own set-up failed: report it
            return "FAIL", f"set-up of the probe failed: {exc!r}"
    before = _snapshot(d)
    t0 = time.monotonic()
    try:
        proc = subprocess.run(
            _cmd(case.argv), cwd=d, capture_output=True, text=True, timeout=timeout
        )
    except subprocess.TimeoutExpired:
        return "FAIL", f"timeout after {timeout:.0f} s"
    secs = time.monotonic() - t0
    err = proc.stderr.strip()
    lines = [ln for ln in err.splitlines() if ln.strip()]
    touched = sorted(
        k for k in set(before) | set(_snapshot(d)) if before.get(k) != _snapshot(d).get(k)
    )
    out = d / "out"
    written = (
        [p.relative_to(d).as_posix() for p in out.rglob("*") if p.is_file()] if out.is_dir() else []
    )
    head = f"rc {proc.returncode} {secs:.1f}s"
    if "Traceback" in err:
        return "FAIL", f"{head} traceback: {lines[-1] if lines else ''}"
    if touched:
        return "FAIL", f"{head} touched outside --out: {touched[:3]}"
    if proc.returncode == 0:
        return (
            ("OK", f"{head} accepted")
            if case.either
            else ("FAIL", f"{head} accepted silently; stderr: {' | '.join(lines)[:200]}")
        )
    if proc.returncode != 2:
        return "FAIL", f"{head} {' | '.join(lines)[-300:]}"
    if len(lines) != 1 or not lines[0].startswith("spectrinsic: error:"):
        return "FAIL", f"{head} {len(lines)} lines: {' | '.join(lines)[:300]}"
    if written:
        return "FAIL", f"{head} refused after writing {written[:3]}: {lines[0]}"
    if case.expect and case.expect.lower() not in lines[0].lower():
        return "FAIL", f"{head} does not name {case.expect!r}: {lines[0]}"
    return "OK", f"{head} {lines[0]}"


def build_samples(root: Path) -> None:
    """A relightable sample of the quad scene, and one whose material is a csv: spectrum."""
    base = root / "_samples"
    base.mkdir()
    (base / "quad.yaml").write_text(QUAD_YAML)
    rows = "wavelength,paint [1]\n" + "".join(f"{w},0.5\n" for w in range(380, 790, 10))
    (base / "p.csv").write_text(rows)
    (base / "cq.yaml").write_text(QUAD_YAML.replace('"flat:0.5"', '"csv:p.csv#paint"'))
    for scene, out in (("quad.yaml", "s1"), ("cq.yaml", "s2")):
        argv = (
            "render",
            scene,
            "--ground-truth",
            "--store-transport",
            "--out",
            out,
            "--resolution",
            "16x16",
            "--spp",
            "2",
            "--preset",
            "preview",
            "--modes",
            "rgb3",
            "-q",
        )
        proc = subprocess.run(_cmd(argv), cwd=base, capture_output=True, text=True)
        if proc.returncode != 0:
            raise SystemExit(f"could not build the relight sample: {proc.stderr}")
        metas = list((base / out).rglob("meta.json"))
        _SAMPLE_CACHE.append(metas[0].parent)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", default="", help="run only cases whose name holds this")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--timeout", type=float, default=240.0)
    parser.add_argument("--keep", action="store_true", help="keep the case folders")
    args = parser.parse_args()
    cases = [c for c in all_cases() if args.only in c.name]
    root = Path(tempfile.mkdtemp(prefix="probes-r5-"))
    try:
        if any(c.name.startswith(("relight/", "csv/")) for c in cases):
            build_samples(root)
        with ThreadPoolExecutor(args.jobs) as pool:
            results = []
            for case, (verdict, note) in zip(
                cases, pool.map(lambda c: run_case(c, root, args.timeout), cases)
            ):
                print(f"{verdict:4} {case.name:42} {note}", flush=True)
                results.append((verdict, note))
        fails = sum(v == "FAIL" for v, _ in results)
        print(f"\n{len(cases)} cases: {len(cases) - fails} OK, {fails} FAIL")
        return 1 if fails else 0
    finally:
        if args.keep:
            print(f"case folders kept in {root}")
        else:
            shutil.rmtree(root, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
