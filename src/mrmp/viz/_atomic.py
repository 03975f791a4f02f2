"""Writing a picture atomically: into a temporary file beside the target, then renamed over it.

An interrupted or failed write leaves the target as it was (absent or the
previous picture), never half a file.

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
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path


@contextmanager
def replacing(target: str | os.PathLike[str]) -> Iterator[Path]:
    """A temporary path next to ``target``, renamed to ``target`` when the block ends without error.

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
            os.replace(temporary, target)
    finally:
        temporary.unlink(missing_ok=True)
