"""A sample's files written, and hashed, by a few threads while the next ones are computed.

Encoding is most of writing a sample's files: OpenEXR's compressors (ZIP, PIZ) and Pillow's
zlib run mostly without the GIL, and so does hashing the bytes written. So the writer hands each EXR
file and PNG preview to :class:`FileWrites`, whose threads encode, write and hash it while the
main thread computes the next preview, the scene record and ``meta.json``. Each file's bytes are
those the same call makes in the main thread: the writers are deterministic, each task writes
only its own file from arrays no one changes afterwards, and the hashes are joined
(:meth:`FileWrites.hashes`) before ``meta.json``, which lists them, is written. (Drawing the
previews in the threads too was measured slower: the writing phase of a 256² relight took
0.62-0.64 s against 0.44-0.47 s, load average 4.5, 5 December 2026; the threads then contend
for the GIL and the two cores among themselves.)

Failures keep the serial writer's order: the error raised is the first one in the order the
files were handed over, and a computation of the main thread that fails after a write that
failed before it yields to that write's error (the serial writer would not have got that far).
Every thread has finished before the block ends, so the caller's clean-up (the temporary
sample folder removed) never races a write.
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path
from types import TracebackType

from . import file_sha256

__all__ = ["WRITE_THREADS", "FileWrites"]

#: Threads writing a sample's files: two keep a 2-core machine's second core busy with zlib
#: while the first computes; more only queue behind the main thread's GIL-bound Python.
WRITE_THREADS = 2


class FileWrites:
    """Files of one folder written and hashed in *threads* threads (default
    :data:`WRITE_THREADS`; 0: each at once, in the calling thread, as a serial writer). Use as a
    context manager; see the module notes.

    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> with FileWrites(folder) as writes:
    ...     writes.submit("a.txt", lambda path: path.write_text("a"))
    ...     hashes = writes.hashes()
    >>> hashes["a.txt"] == file_sha256(folder / "a.txt")
    True
    """

    def __init__(self, folder: Path, threads: int | None = None) -> None:
        self._folder = folder
        threads = WRITE_THREADS if threads is None else threads
        self._pool = (
            ThreadPoolExecutor(max_workers=threads, thread_name_prefix="spectrinsic-write")
            if threads > 0
            else None
        )
        self._futures: dict[str, Future[str]] = {}

    def _write_and_hash(self, rel: str, write: Callable[[Path], object]) -> str:
        write(self._folder / rel)
        return file_sha256(self._folder / rel)

    def submit(self, rel: str, write: Callable[[Path], object]) -> None:
        """Have ``write(folder / rel)`` write the file *rel*, then hash it. Raises the error of
        an earlier file that failed already (the first, in the order handed over)."""
        self._raise_first_failure(finished_only=True)
        future: Future[str] = Future()
        if self._pool is None:
            future.set_result(self._write_and_hash(rel, write))
        else:
            future = self._pool.submit(self._write_and_hash, rel, write)
        self._futures[rel] = future

    def _raise_first_failure(self, *, finished_only: bool) -> None:
        """Raise the error of the first failed file, looking no further than the first file
        still being written if *finished_only*."""
        for future in self._futures.values():
            if finished_only and not future.done():
                return
            error = None if future.cancelled() else future.exception()
            if error is not None:
                raise error

    def hashes(self) -> dict[str, str]:
        """``{rel: SHA-256}`` of every file handed over, once all are written; the first
        failure's error otherwise."""
        self._raise_first_failure(finished_only=False)  # waits for each file in turn
        return {rel: future.result() for rel, future in self._futures.items()}

    def __enter__(self) -> FileWrites:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        exc: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        """Wait for every thread (files not begun are dropped after an error); an ``Exception``
        of the block yields to a write that failed before it (module notes)."""
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=exc is not None)
        if isinstance(exc, Exception):
            self._raise_first_failure(finished_only=False)
