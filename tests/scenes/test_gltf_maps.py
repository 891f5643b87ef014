"""glTF ``alphaMode`` and ``normalTexture`` as a mesh's mask and normal map (issue 42, item 1).

A hand-written ``.gltf`` (buffers and images as ``data:`` URIs) of one quad facing the camera:
the checker alpha of its base-colour image must cut the quad where the image says (row 0 the
image's top, glTF's v = 0), and a constant normal texture with ``scale`` must give the
analytic world normal ``normalize((2 t − 1) ⊙ (s, s, 1))`` in the normal layer.
"""

from __future__ import annotations

import base64
import io
import json
import math
import struct
import warnings
from dataclasses import replace

import numpy as np
from PIL import Image

from spectrinsic.render import RenderSettings, render_scene
from spectrinsic.scenes.meshes import load_mesh_scene
from spectrinsic.scenes.model import Camera, Light

SIZE, FOV, DISTANCE, TEXELS = 32, 30.0, 3.0, 4


def _png(pixels: np.ndarray, mode: str) -> str:
    buffer = io.BytesIO()
    Image.fromarray(pixels, mode).save(buffer, format="PNG")
    return "data:image/png;base64," + base64.b64encode(buffer.getvalue()).decode()


def _alpha() -> np.ndarray:
    """A TEXELS² checker of alpha 0/255 (row 0 the image's top), symmetry broken."""
    index = np.add.outer(np.arange(TEXELS), np.arange(TEXELS)) % 2
    index[0, 0] = 1 - index[0, 0]
    return (index * 255).astype(np.uint8)


def _gltf(folder, material: dict) -> str:
    """One quad over [-1, 1]² at z = 0, u along +x and glTF v = 0 at the top (y = 1)."""
    xy = [(-1, -1), (1, -1), (1, 1), (-1, 1)]
    positions = b"".join(struct.pack("<3f", x, y, 0.0) for x, y in xy)
    uvs = b"".join(struct.pack("<2f", (x + 1) / 2, 1 - (y + 1) / 2) for x, y in xy)
    indices = struct.pack("<6H", 0, 1, 2, 0, 2, 3)
    blob = positions + uvs + indices
    rgba = np.zeros((TEXELS, TEXELS, 4), np.uint8)
    rgba[..., 0], rgba[..., 3] = 200, _alpha()
    tilt = np.broadcast_to(np.array([200, 90, 230], np.uint8), (2, 2, 3))
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "leaf"}],
        "meshes": [
            {
                "primitives": [
                    {"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}
                ]
            }
        ],
        "materials": [{"name": "leafy", **material}],
        "textures": [{"source": 0, "sampler": 0}, {"source": 1, "sampler": 0}],
        "samplers": [{"magFilter": 9728, "wrapS": 33071, "wrapT": 33071}],
        "images": [{"uri": _png(rgba, "RGBA")}, {"uri": _png(np.ascontiguousarray(tilt), "RGB")}],
        "buffers": [
            {
                "byteLength": len(blob),
                "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode(),
            }
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 32},
            {"buffer": 0, "byteOffset": 80, "byteLength": 12},
        ],
        "accessors": [
            {
                "bufferView": 0,
                "componentType": 5126,
                "count": 4,
                "type": "VEC3",
                "min": [-1, -1, 0],
                "max": [1, 1, 0],
            },
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"},
        ],
    }
    path = folder / "leaf.gltf"
    path.write_text(json.dumps(doc))
    return str(path)


def _render(path: str):
    scene = load_mesh_scene(
        path, materials={}, width=SIZE, height=SIZE, default_spectrum="flat:0.5"
    )
    scene = replace(
        scene,
        camera=Camera((0, 0, DISTANCE), (0, 0, 0), (0, 1, 0), FOV, SIZE, SIZE),
        lights=(Light("directional", "cie:D65", 1.0, direction=(0.0, 0.0, -1.0)),),
    )
    return scene, render_scene(scene, RenderSettings(4, max_depth=2, modes=("bands31",)), seed=1)


def test_alpha_mask_cuts_the_quad_where_the_image_says(tmp_path):
    material = {
        "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}},
        "alphaMode": "MASK",
        "alphaCutoff": 0.5,
    }
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        scene, result = _render(_gltf(tmp_path, material))
    assert not [w for w in said if "alpha below 1" in str(w.message)]  # the alpha is read
    maps = scene.meshes[0].maps
    assert maps is not None and maps.opacity_image is not None and maps.normal_image is None
    half = DISTANCE * math.tan(math.radians(FOV / 2))
    edges = np.linspace(-half, half, SIZE + 1)
    texel = np.floor((edges + 1.0) / 2.0 * TEXELS).astype(int)
    inside = (texel[:-1] == texel[1:])[:, None] & (texel[:-1] == texel[1:])[None, :]
    rows = np.broadcast_to(
        (TEXELS - 1 - texel[::-1][1:])[:, None], (SIZE, SIZE)
    )  # image rows from the top
    cols = np.broadcast_to(texel[:-1][None, :], (SIZE, SIZE))
    expected = (_alpha()[rows, cols] == 255).astype(float)
    cover = result.aovs["mask"].reshape(SIZE, SIZE)  # the leaf alone: any surface's coverage
    assert inside.sum() > 600
    np.testing.assert_array_equal(cover[inside], expected[inside])


def test_blend_factor_is_a_constant_opacity(tmp_path):
    material = {
        "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.2, 0.1, 0.25]},
        "alphaMode": "BLEND",
    }
    maps = (
        load_mesh_scene(_gltf(tmp_path, material), materials={}, width=8, height=8).meshes[0].maps
    )
    assert maps.opacity == 0.25 and maps.opacity_image is None


def test_normal_texture_with_scale_gives_the_analytic_normal(tmp_path):
    material = {"normalTexture": {"index": 1, "scale": 0.5}}
    scene, result = _render(_gltf(tmp_path, material))
    assert scene.meshes[0].maps.normal_scale == 0.5
    t = np.array([200, 90, 230]) / 255.0
    n = (2 * t - 1) * np.array([0.5, 0.5, 1.0])
    n /= np.linalg.norm(n)  # tangent frame: s = +x (∂p/∂u), t = n × s = +y, n = +z
    normals = result.aovs["normals"].reshape(-1, 3)
    np.testing.assert_allclose(normals, np.broadcast_to(n, normals.shape), atol=1e-4)
