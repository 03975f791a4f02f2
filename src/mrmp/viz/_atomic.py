"""Writing a file atomically: into a temporary file beside the target, then renamed over it.

An interrupted or failed write leaves the target as it was (absent or the
previous file), never half a file. :func:`replacing` serves writers that
need a path (Pillow, ffmpeg, ElementTree); :func:`write_bytes_atomically`
writes bytes already in memory (plots, report pages).

Examples
--------
>>> import tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> with replacing(folder / "run.svg") as temporary:
...     _ = temporary.write_text("<svg/>")
...     print(temporary.parent == folder, (folder / "run.svg").exists())
True False
>>> (folder / "run.svg").read_text(), sorted(path.name for path in folder.iterdir())
('<svg/>', ['run.svg'])
>>> write_bytes_atomically(folder / "plots" / "a.png", b"png")
>>> (folder / "plots" / "a.png").read_bytes(), sorted(path.name for path in (folder / "plots").iterdir())
(b'png', ['a.png'])
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path


@contextmanager
def replacing(target: str | os.PathLike[str]) -> Iterator[Path]:
    """A temporary path next to ``target``, flushed to disk and renamed to ``target`` when the block ends without error.

    If the block raises (or is interrupted), or deletes the temporary file,
    ``target`` is left untouched and the temporary file is removed.
    """
    target = Path(target)
    handle, name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part", dir=target.parent)
    os.close(handle)
    temporary = Path(name)
    mask = os.umask(0)
    os.umask(mask)
    os.chmod(temporary, 0o666 & ~mask)  # as an ordinary new file, not mkstemp's private one
    try:
        yield temporary
        if temporary.exists():
            with open(temporary, "rb") as written:
                os.fsync(written.fileno())  # the new content is on disk before the name points to it
            os.replace(temporary, target)
    finally:
        temporary.unlink(missing_ok=True)


def write_bytes_atomically(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through :func:`replacing`; missing parent folders are created."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with replacing(path) as temporary:
        temporary.write_bytes(data)
