"""No file is ever written in place or through a link: every writer renames a temporary over its
name (:mod:`spectrinsic.file_writes`).

The grep test lists every write call in the package and proves it writes a temporary of
:func:`~spectrinsic.file_writes.replacing`; the writer tests then prove each write primitive
against a hard link (the user's other name keeps its content) and a symbolic link planted after
the run began (refused in one line; the link's target is untouched).
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from spectrinsic.errors import WriteError
from spectrinsic.file_writes import replacing, write_bytes_file, write_text_file
from tests.conftest import USER_TEXT

PACKAGE = Path(__file__).resolve().parents[1] / "spectrinsic"
#: A call that writes a file's content: text, bytes, figures, PIL images, OpenEXR, opened files.
_WRITE_CALL = re.compile(
    r"\.(write_text|write_bytes|savefig|save)\((?P<arg>[^,)]*)"
    r"|open\((?P<opened>[^,)]*),\s*['\"][wax]b?['\"]"
    r"|\.(?P<opened2>\w+)\.open\(['\"][wax]"
    r"|OpenEXR\.File\([^)]*\)\.write\((?P<exr>[^)]*)\)"
)


def _write_calls() -> list[tuple[str, int, str]]:
    """``(module, line number, the call with the line after it)`` of every write call."""
    calls = []
    for path in sorted(PACKAGE.rglob("*.py")):
        lines = path.read_text(encoding="utf-8").splitlines() + [""]
        for number, line in enumerate(lines[:-1], 1):
            code = line.split("#", 1)[0]
            if code.lstrip().startswith((">>>", "...")):
                continue  # a doctest
            if _WRITE_CALL.search(code):  # the arguments may continue on the next line
                call = f"{line.strip()} {lines[number].strip()}"
                calls.append((path.relative_to(PACKAGE).as_posix(), number, call))
    return calls


def _in_memory(module: str, line: str) -> bool:
    """A save into ``buffer``, where the module makes ``buffer = io.BytesIO()``: no file."""
    source = (PACKAGE / module).read_text(encoding="utf-8")
    return bool(re.search(r"\.save\(buffer\b", line)) and "buffer = io.BytesIO()" in source


def test_every_write_call_in_the_package_writes_a_temporary_renamed_over_its_name():
    calls = _write_calls()
    assert len(calls) >= 15, "the pattern no longer finds the package's writers"
    in_place = [
        f"{module}:{number}: {line}"
        for module, number, line in calls
        if module != "file_writes.py"
        and not re.search(r"\btmp\b", line)
        and not _in_memory(module, line)
    ]
    assert not in_place, "written in place (use spectrinsic.file_writes.replacing):\n" + "\n".join(
        in_place
    )
    # and every such `tmp` is the one replacing() yields, in the same function
    for module, number, line in calls:
        if module == "file_writes.py" or _in_memory(module, line):
            continue
        lines = (PACKAGE / module).read_text(encoding="utf-8").splitlines()[:number]
        above = "\n".join(lines[-25:])
        assert re.search(r"replacing\([^)]*\) as tmp", above), f"{module}:{number}"


def _png(path: Path) -> None:
    from spectrinsic.gt_export.formats.png import write_png

    write_png(path, np.full((2, 3, 3), 7, np.uint8))


def _png16(path: Path) -> None:
    from spectrinsic.gt_export.formats.png import write_png16

    write_png16(path, np.full((2, 3), 700, np.uint16))


def _exr(path: Path) -> None:
    from spectrinsic.gt_export.formats.exr import write_exr

    write_exr(path, {"image": np.ones((2, 3, 3), np.float32)})


def _json(path: Path) -> None:
    from spectrinsic.results import write_json

    write_json(path, {"a": 1})


def _csv(path: Path) -> None:
    from spectrinsic.results import write_csv

    write_csv(path, [{"a": 1}])


def _scene(path: Path) -> None:
    from spectrinsic.scenes.library import build
    from spectrinsic.scenes.scene_writer import save_scene

    save_scene(build("obj-box", seed=1, width=8, height=8), path, inline_max_faces=0)


def _figure(path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(1, 1))
    with replacing(path) as tmp:
        fig.savefig(tmp, dpi=10)
    plt.close(fig)


#: One of each way the package writes a file, with a name of the suffix its format needs.
WRITERS: dict[str, tuple[str, Callable[[Path], object]]] = {
    "text": ("a.txt", lambda p: write_text_file(p, "new")),
    "bytes": ("a.bin", lambda p: write_bytes_file(p, b"new")),
    "png": ("a.png", _png),
    "png16": ("a.png", _png16),
    "exr": ("a.exr", _exr),
    "json": ("a.json", _json),
    "csv": ("a.csv", _csv),
    "scene yaml": ("a.yaml", _scene),
    "figure": ("a.png", _figure),
}


@pytest.mark.parametrize("kind", sorted(WRITERS))
def test_a_hard_link_in_the_output_folder_keeps_the_users_file(tmp_path, outside, kind):
    name, write = WRITERS[kind]
    target = tmp_path / "out" / name
    target.parent.mkdir()
    os.link(outside, target)
    write(target)
    assert outside.read_text() == USER_TEXT  # the user's name still holds the user's bytes
    assert target.stat().st_ino != outside.stat().st_ino
    assert target.read_bytes() != USER_TEXT.encode()
    assert [p.name for p in target.parent.iterdir() if p.name.startswith(".")] == []


@pytest.mark.parametrize("kind", sorted(WRITERS))
def test_a_symbolic_link_planted_in_the_output_folder_is_refused(tmp_path, outside, kind):
    name, write = WRITERS[kind]
    target = tmp_path / "out" / name
    target.parent.mkdir()
    target.symlink_to(outside)
    with pytest.raises(WriteError, match="symbolic link"):
        write(target)
    assert outside.read_text() == USER_TEXT and target.is_symlink()


@pytest.mark.parametrize("kind", sorted(WRITERS))
def test_a_folder_replaced_by_a_symbolic_link_is_refused(tmp_path, outside, kind):
    name, write = WRITERS[kind]
    (tmp_path / "out").symlink_to(outside.parent, target_is_directory=True)
    with pytest.raises(WriteError, match="symbolic link"):
        write(tmp_path / "out" / name)
    assert sorted(p.name for p in outside.parent.iterdir()) == ["precious.txt"]


def test_a_link_planted_while_the_file_is_written_is_refused_at_the_rename(tmp_path, outside):
    target = tmp_path / "a.txt"
    with pytest.raises(WriteError, match="made after the run began"):
        with replacing(target) as tmp:
            tmp.write_text("new")
            target.symlink_to(outside)  # planted between the start of the write and its end
    assert outside.read_text() == USER_TEXT
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt", "elsewhere"]  # no temporary
