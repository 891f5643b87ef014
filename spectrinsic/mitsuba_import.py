"""Importing Mitsuba safely: the one place that imports Mitsuba and Dr.Jit (:func:`import_mitsuba`).

Dr.Jit's LLVM backend JIT-compiles through a system ``libLLVM``. The LLVM 14 and 15 libraries
that Debian ships crash it (``Cannot select: fminimum``); LLVM 16 or newer works. Dr.Jit loads
the library named by the environment variable ``DRJIT_LIBLLVM_PATH`` when ``drjit`` is first
imported, and has no other way to be told. So whatever first imports Mitsuba, the renderer
(:mod:`spectrinsic.render`) or the reader of Mitsuba XML scene files, which parses them with
Mitsuba's own parser (:mod:`spectrinsic.scenes.mitsuba_tree`), goes through
:func:`import_mitsuba`: a base module below both, so a scene read before any render still
leaves Dr.Jit on a suitable ``libLLVM``.
"""

from __future__ import annotations

import contextlib
import glob
import importlib
import logging
import os
import re
import sys
from collections.abc import Iterator, Sequence
from pathlib import Path
from types import ModuleType

from .errors import MissingDependencyError

__all__ = [
    "LLVM_ENV",
    "LLVM_MIN_VERSION",
    "llvm_version_from_name",
    "find_libllvm",
    "configure_llvm",
    "import_mitsuba",
    "loaded_libllvm",
]

logger = logging.getLogger(__name__)

#: Environment variable Dr.Jit reads for the path of ``libLLVM``.
LLVM_ENV = "DRJIT_LIBLLVM_PATH"
#: Oldest LLVM major version whose instruction selection handles Dr.Jit's ``fminimum``.
LLVM_MIN_VERSION = 16

#: Where distributions put ``libLLVM`` (globs allowed); searched in this order.
_LIB_DIRS: tuple[str, ...] = (
    "/usr/lib/x86_64-linux-gnu",
    "/usr/lib/aarch64-linux-gnu",
    "/usr/lib64",
    "/usr/lib",
    "/usr/local/lib",
    "/usr/lib/llvm-*/lib",
    "/usr/lib64/llvm*/lib",
    "/opt/homebrew/opt/llvm/lib",
    "/usr/local/opt/llvm/lib",
)
_NAME_DASH = re.compile(r"^libLLVM-(\d+)")  # libLLVM-19.so, libLLVM-14.0.6.so.1
_NAME_SOVERSION = re.compile(r"^libLLVM\.(?:so|dylib)\.(\d+)")  # libLLVM.so.19.1
_DIR_VERSION = re.compile(r"llvm-?(\d+)")  # /usr/lib/llvm-19/lib/libLLVM.so


def llvm_version_from_name(path: str | os.PathLike[str]) -> int | None:
    """Major LLVM version encoded in a ``libLLVM`` file name (or its folder), else ``None``.

    >>> llvm_version_from_name("/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1")
    19
    >>> llvm_version_from_name("libLLVM-14.0.6.so.1")
    14
    >>> llvm_version_from_name("/usr/lib/llvm-17/lib/libLLVM.so") is None
    False
    """
    p = Path(path)
    for pattern in (_NAME_DASH, _NAME_SOVERSION):
        m = pattern.match(p.name)
        if m:
            return int(m.group(1))
    m = _DIR_VERSION.search(str(p.parent))
    return int(m.group(1)) if m and p.name.startswith("libLLVM") else None


def find_libllvm(
    dirs: Sequence[str] | None = None, *, min_version: int = LLVM_MIN_VERSION
) -> Path | None:
    """The newest ``libLLVM`` shared library of version >= *min_version* in *dirs*, or ``None``.

    Parameters
    ----------
    dirs
        Folders (glob patterns allowed) to search; default: the usual system library folders.
    """
    best: tuple[int, Path] | None = None
    for pattern in dirs if dirs is not None else _LIB_DIRS:
        for folder in sorted(glob.glob(pattern)):
            for lib in sorted(Path(folder).glob("libLLVM*")):
                if not (lib.suffix in (".so", ".dylib") or ".so." in lib.name) or not lib.exists():
                    continue
                version = llvm_version_from_name(lib)
                if (
                    version is not None
                    and version >= min_version
                    and (best is None or version > best[0])
                ):
                    best = (version, lib)
    return None if best is None else best[1]


def configure_llvm() -> str | None:
    """The ``libLLVM`` Dr.Jit should load: ``DRJIT_LIBLLVM_PATH`` if the user set it, else the
    newest ``libLLVM`` >= :data:`LLVM_MIN_VERSION` found (``None`` if neither).

    Changes nothing: :func:`import_mitsuba` hands the path to Dr.Jit.
    """
    current = os.environ.get(LLVM_ENV, "").strip()
    if current:
        return current
    found = find_libllvm()
    return None if found is None else str(found)


#: The ``libLLVM`` Dr.Jit was pointed at when :func:`import_mitsuba` first imported it (None: no
#: suitable one, or Dr.Jit imported before without ``DRJIT_LIBLLVM_PATH``). Set once, by the
#: set-up step; a record of what this process loaded, not a setting.
_loaded_libllvm: str | None = None
_set_up = False


@contextlib.contextmanager
def _environment_variable(name: str, value: str | None) -> Iterator[None]:
    """Set *name* to *value* (unless None or already set) inside the block, then restore it."""
    if value is None or name in os.environ:
        yield
        return
    os.environ[name] = value
    try:
        yield
    finally:
        del os.environ[name]


def import_mitsuba() -> ModuleType:
    """Return the ``mitsuba`` module; the first call is spectrinsic's Mitsuba set-up step.

    That call imports Dr.Jit with ``DRJIT_LIBLLVM_PATH`` pointing at :func:`configure_llvm`'s
    library, for the duration of the import only (Dr.Jit loads ``libLLVM`` then), and records
    the library used. If ``drjit`` was imported before, by someone else, its library is the one
    ``DRJIT_LIBLLVM_PATH`` names now, if any.

    Raises
    ------
    MissingDependencyError
        If Mitsuba 3 is not installed.
    """
    global _loaded_libllvm, _set_up
    try:
        if not _set_up:
            if "drjit" in sys.modules:
                _loaded_libllvm = os.environ.get(LLVM_ENV, "").strip() or None
            else:
                _loaded_libllvm = configure_llvm()
                with _environment_variable(LLVM_ENV, _loaded_libllvm):
                    importlib.import_module("drjit")
                logger.debug("Dr.Jit's LLVM backend uses %s", _loaded_libllvm)
            _set_up = True
        return importlib.import_module("mitsuba")
    except ImportError as exc:  # pragma: no cover - mitsuba is a declared dependency
        raise MissingDependencyError(
            f"rendering needs Mitsuba 3 ('pip install mitsuba'): {exc}"
        ) from exc


def loaded_libllvm() -> str | None:
    """The ``libLLVM`` Dr.Jit was pointed at by the set-up step (None: none suitable, or Dr.Jit
    imported before without ``DRJIT_LIBLLVM_PATH``, or no set-up yet)."""
    return _loaded_libllvm
