"""Variant selection and LLVM discovery."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from spectrinsic import mitsuba_import
from spectrinsic.errors import RenderError, SpectrinsicError, SpectrinsicWarning
from spectrinsic.render import RenderSettings
from spectrinsic.render.base import variants


@pytest.mark.parametrize(
    ("name", "version"),
    [
        ("/usr/lib/x86_64-linux-gnu/libLLVM-19.so", 19),
        ("/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1", 19),
        ("libLLVM-14.0.6.so.1", 14),
        ("libLLVM-15.so", 15),
        ("/usr/lib/llvm-17/lib/libLLVM.so", 17),
        ("/opt/lib/libLLVM.so", None),
        ("/usr/lib/libfoo-19.so", None),
    ],
)
def test_llvm_version_from_name(name, version):
    assert mitsuba_import.llvm_version_from_name(name) == version


def test_find_libllvm_prefers_newest_suitable(tmp_path):
    for name in (
        "libLLVM-14.so.1",
        "libLLVM-15.so",
        "libLLVM.so.19.1",
        "libLLVM-17.so",
        "libLLVM-20.a",
    ):
        (tmp_path / name).write_bytes(b"")
    assert mitsuba_import.find_libllvm([str(tmp_path)]).name == "libLLVM.so.19.1"


def test_find_libllvm_rejects_old_versions(tmp_path):
    for name in ("libLLVM-14.so.1", "libLLVM-15.so"):
        (tmp_path / name).write_bytes(b"")
    assert mitsuba_import.find_libllvm([str(tmp_path)]) is None


def test_configure_llvm_keeps_user_setting(monkeypatch):
    monkeypatch.setenv(mitsuba_import.LLVM_ENV, "/somewhere/libLLVM-18.so")
    assert mitsuba_import.configure_llvm() == "/somewhere/libLLVM-18.so"


def test_importing_render_does_not_import_mitsuba():
    code = (
        "import sys, spectrinsic.render; print('mitsuba' in sys.modules or 'drjit' in sys.modules)"
    )
    out = subprocess.run(
        [sys.executable, "-P", "-c", code], capture_output=True, text=True, check=True
    )
    assert out.stdout.strip() == "False"


@pytest.mark.parametrize("kind", ["rgb", "spectral"])
def test_choose_variant_matches_kind(kind):
    chosen = variants.choose_variant(kind)
    assert chosen.endswith("_" + kind)
    assert chosen.split("_")[0] in variants.usable_backends()


def test_choose_variant_honours_backend_of_a_variant_name():
    assert variants.choose_variant("spectral", "scalar_rgb") == "scalar_spectral"


def test_choose_variant_rejects_unknown_backend():
    with pytest.raises(SpectrinsicError, match="did you mean 'llvm'"):
        variants.choose_variant("rgb", "llvn")


def test_unusable_backend_is_an_error():
    if "cuda" in variants.usable_backends():
        pytest.skip("a CUDA device is present, so the cuda backend is usable")
    with pytest.raises(RenderError, match="not usable"):
        variants.choose_variant("rgb", "cuda")


def test_available_variants_lists_usable_variants():
    usable = variants.available_variants()
    assert usable[-2:] == ["scalar_rgb", "scalar_spectral"]
    report = variants.variant_report()
    assert report["rgb"] == usable[0] and report["spectral"] == usable[1]
    assert set(usable) <= set(report["compiled"])
    if "llvm" in report["backends"]:
        assert mitsuba_import.llvm_version_from_name(report["libllvm"]) in (
            None,
            *range(mitsuba_import.LLVM_MIN_VERSION, 100),
        )


def test_variant_scope_restores_previous_variant():
    with variants.variant_scope("scalar_rgb") as mi:
        with variants.variant_scope("scalar_spectral"):
            assert mi.variant() == "scalar_spectral"
        assert mi.variant() == "scalar_rgb"


def test_without_suitable_llvm_falls_back_to_scalar_with_one_warning(monkeypatch):
    monkeypatch.setattr(variants, "_llvm_suitable", lambda: False)
    if "cuda" in variants.usable_backends():
        pytest.skip("a CUDA device is present: cuda is chosen before llvm or scalar")
    with pytest.warns(SpectrinsicWarning, match="scalar") as record:
        assert variants.choose_variant("rgb") == "scalar_rgb"
    assert len(record) == 1


def test_scalar_variant_renders_the_same_deterministic_plane(make_plane):
    from spectrinsic.render import render_scene

    scene = make_plane("munsell:5R 5/12", "planck:2800K", tilt_deg=30.0, size=4)
    scalar = render_scene(
        scene, RenderSettings(2, modes=("rgb3",), variant="scalar", aovs=False), seed=0
    )
    best = render_scene(scene, RenderSettings(2, modes=("rgb3",), aovs=False), seed=0)
    assert scalar.meta["variants"]["rgb3"] == "scalar_rgb"
    np.testing.assert_allclose(scalar.images["rgb3"], best.images["rgb3"], rtol=1e-5)


def _fresh(code: str, **env: str) -> list[str]:
    """stdout lines of *code* run in a new interpreter (a process whose Mitsuba is not set up)."""
    environ = {k: v for k, v in os.environ.items() if k != mitsuba_import.LLVM_ENV} | env
    out = subprocess.run(
        [sys.executable, "-P", "-c", code], capture_output=True, text=True, check=True, env=environ
    )
    return out.stdout.strip().splitlines()


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc/self/maps (Linux)")
def test_set_up_leaves_the_environment_as_it_was():
    """Dr.Jit gets the chosen libLLVM while it is imported; the environment is not changed."""
    code = (
        "import os, sys\n"
        "from spectrinsic import mitsuba_import\n"
        "from spectrinsic.render.base import variants\n"
        "variants.import_mitsuba()\n"
        "print(repr(os.environ.get(mitsuba_import.LLVM_ENV)))\n"
        "print(repr(variants.llvm_library()))\n"
        "print(repr(mitsuba_import.configure_llvm()))\n"
        "print(sorted({l.split()[-1] for l in open('/proc/self/maps') if 'libLLVM' in l}))\n"
    )
    env_after, used, chosen, mapped = _fresh(code)
    assert env_after == "None"
    if chosen == "None":
        pytest.skip(f"no libLLVM >= {mitsuba_import.LLVM_MIN_VERSION} on this machine")
    assert used == chosen
    # the library Dr.Jit actually loaded is the chosen one, not another libLLVM on the system
    assert mapped == repr([os.path.realpath(eval(chosen))])


def test_set_up_keeps_the_users_libllvm_setting():
    code = (
        "import os\n"
        "from spectrinsic import mitsuba_import\n"
        "from spectrinsic.render.base import variants\n"
        "variants.import_mitsuba()\n"
        "print(os.environ[mitsuba_import.LLVM_ENV])\n"
    )
    assert _fresh(code, **{mitsuba_import.LLVM_ENV: "/nowhere/libLLVM-18.so"}) == [
        "/nowhere/libLLVM-18.so"
    ]


def test_variant_scope_restores_on_errors_and_documents_the_first_scope():
    code = (
        "from spectrinsic.render.base import variants\n"
        "mi = variants.import_mitsuba()\n"
        "print(mi.variant())\n"
        "with variants.variant_scope('scalar_spectral'):\n"
        "    print(mi.variant())\n"
        "print(mi.variant())  # no way back to None: the first variant stays\n"
        "with variants.variant_scope('scalar_rgb'):\n"
        "    try:\n"
        "        with variants.variant_scope('scalar_spectral'):\n"
        "            raise KeyError\n"
        "    except KeyError:\n"
        "        print(mi.variant())\n"
        "print(mi.variant())\n"
    )
    assert _fresh(code) == [
        "None",
        "scalar_spectral",
        "scalar_spectral",
        "scalar_rgb",
        "scalar_spectral",
    ]


def test_batches_switch_variants_once_each(monkeypatch, make_room):
    """Every switch between the RGB and the spectral variant reloads Mitsuba's Python modules
    (0.25 s on 2 cores), so the render pipeline runs the variant already active first and
    leaves the last one active: two batches of a room in both kinds of mode switch twice
    (four times before: each scope switched back on leaving)."""
    from spectrinsic.render import render_batches

    mi = variants.import_mitsuba()
    mi.set_variant(variants.choose_variant("rgb"))  # as after any earlier render
    switches: list[str] = []
    real = mi.set_variant

    def counted(name: str, *args: object) -> None:
        if mi.variant() != name:
            switches.append(name)
        real(name, *args)

    monkeypatch.setattr(mi, "set_variant", counted)
    settings = RenderSettings(spp=2, modes=("spectral", "rgb3"), batches=2, max_depth=2)
    result = render_batches(make_room(size=4), settings, seed=1)
    assert len(switches) <= 2, switches
    assert set(result.images) == {"spectral", "rgb3"}
    assert result.meta["batches"] == 2
