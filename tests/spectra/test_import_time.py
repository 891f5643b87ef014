"""No import-time side effects in spectrinsic.spectra, no import cycles, read-only caches."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from spectrinsic.spectra import colorimetry, illuminants, io, reflectances, registry, sensors
from spectrinsic.spectra.colourspace import srgb_matrices

SPECTRA = Path(__file__).resolve().parents[2] / "spectrinsic" / "spectra"


def _run(code: str) -> str:
    """Run *code* in a fresh interpreter (``-P``, so only the installed package is importable)."""
    out = subprocess.run(
        [sys.executable, "-P", "-c", code], capture_output=True, text=True, check=True
    )
    return out.stdout.strip()


def test_importing_spectra_computes_no_colour_science_constants():
    code = (
        "import sys\n"
        "import spectrinsic.spectra\n"
        "from spectrinsic.spectra.colourspace import srgb_matrices\n"
        "print(srgb_matrices.cache_info().currsize, 'colour' in sys.modules)\n"
        "from spectrinsic.spectra import XYZ_TO_LINEAR_SRGB\n"
        "print(srgb_matrices.cache_info().currsize, XYZ_TO_LINEAR_SRGB.shape)\n"
    )
    before, after = _run(code).splitlines()
    assert before == "0 False"  # nothing computed, colour-science not even imported
    assert after == "1 (3, 3)"  # the public names still work, computed on first access


def test_the_lazy_matrices_are_the_colour_science_ones_and_read_only():
    import colour

    cs = colour.RGB_COLOURSPACES["sRGB"]
    np.testing.assert_array_equal(colorimetry.XYZ_TO_LINEAR_SRGB, cs.matrix_XYZ_to_RGB)
    np.testing.assert_array_equal(colorimetry.LINEAR_SRGB_TO_XYZ, cs.matrix_RGB_to_XYZ)
    assert colorimetry.XYZ_TO_LINEAR_SRGB is srgb_matrices()[0]
    with pytest.raises(ValueError, match="read-only"):
        colorimetry.XYZ_TO_LINEAR_SRGB[0, 0] = 0.0
    with pytest.raises(AttributeError, match="no attribute 'XYZ_TO_SRGB'"):
        colorimetry.XYZ_TO_SRGB  # noqa: B018


def _spectra_imports(path: Path) -> set[str]:
    """The ``spectrinsic.spectra.*`` modules *path* imports, at module level or in a function."""
    names: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text())):
        module = node.module if isinstance(node, ast.ImportFrom) else None
        if isinstance(node, ast.ImportFrom) and node.level:  # from .io import / from . import io
            anchor = ["spectrinsic", "spectra"][: 3 - node.level]
            module = ".".join([*anchor, node.module] if node.module else anchor)
        if isinstance(node, ast.ImportFrom) and module and module.startswith("spectrinsic.spectra"):
            if module == "spectrinsic.spectra":  # from . import io, ...
                names.update(
                    f"spectrinsic.spectra.{a.name}"
                    for a in node.names
                    if (SPECTRA / f"{a.name}.py").is_file()
                )
            else:
                names.add(module)
        elif isinstance(node, ast.Import):
            names.update(a.name for a in node.names if a.name.startswith("spectrinsic.spectra."))
    return names


def test_spectra_modules_import_each_other_without_cycles():
    """Lazy imports included: a cycle (colorimetry -> registry -> sensors -> colorimetry) is what
    forces imports into functions in the first place."""
    graph = {
        f"spectrinsic.spectra.{p.stem}": _spectra_imports(p)
        for p in SPECTRA.glob("*.py")
        if p.stem != "__init__"
    }
    done: set[str] = set()

    def visit(node: str, path: tuple[str, ...]) -> None:
        assert node not in path, "import cycle: " + " -> ".join((*path[path.index(node) :], node))
        if node in done:
            return
        for dep in graph.get(node, ()):
            visit(dep, (*path, node))
        done.add(node)

    for module in graph:
        visit(module, ())
    # the checker sees the edges that used to close the cycle
    assert "spectrinsic.spectra.registry" in graph["spectrinsic.spectra.colorimetry"]
    assert "spectrinsic.spectra.sensors" in graph["spectrinsic.spectra.registry"]


def _frozen(*arrays: np.ndarray) -> None:
    for array in arrays:
        assert isinstance(array, np.ndarray)
        with pytest.raises(ValueError, match="read-only"):
            array.flat[0] = 0.5


def test_cached_spectral_tables_are_read_only():
    table, _ = io.read_munsell()
    _frozen(table.wavelengths, table.values)
    cmf = sensors.cie1931()
    _frozen(cmf.wavelengths, cmf.curves)
    _frozen(sensors.srgb().curves)
    _frozen(*illuminants._ybar())
    _frozen(registry.family_values("munsell", np.arange(400.0, 701.0, 10.0)))
    # spectra handed out by the registry are views of the cached table
    _frozen(registry.get_spectrum("munsell:5R 4/14").values)
    with pytest.raises(TypeError):
        reflectances._munsell_index()["5R 4/14"] = 0  # type: ignore[index]


def test_cached_data_directory_tables_are_read_only(data_dir: Path):
    table, _ = io.read_sfu_reflectances(str(data_dir))
    _frozen(table.wavelengths, table.values)
    table = io.read_sfu_illuminants(str(data_dir))
    _frozen(table.wavelengths, table.values)
    relative, _ = sensors.CAMERA_TABLES["jiang2013"]
    cams = io.read_camera_table(str(data_dir), relative)
    wl, curves = next(iter(cams.values()))
    _frozen(wl, curves)
    with pytest.raises(TypeError):
        cams["new"] = (wl, curves)  # type: ignore[index]
