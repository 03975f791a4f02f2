"""Reading and atomically writing text files, with every failure turned into an :class:`InputError`.

These helpers are private to :mod:`mrmp.io`: the rest of the package never
opens a file.

Examples
--------
>>> import tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> atomic_write_text(folder / "note.txt", "hello\\n")
>>> read_text(folder / "note.txt")
'hello\\n'
>>> read_text(folder / "missing.txt")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
mrmp.core.errors.InputError: ...missing.txt: file not found
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from mrmp.core.errors import InputError, Problem

PathLike = str | os.PathLike[str]
"""Anything :class:`pathlib.Path` accepts."""


def read_text(path: PathLike) -> str:
    """Read a UTF-8 text file, turning every failure into an :class:`InputError` naming the file.

    Parameters
    ----------
    path:
        The file to read.

    Returns
    -------
    str
        The file's text (line endings untouched).

    Raises
    ------
    InputError
        If the file is missing, a folder, unreadable, or not UTF-8 text; the
        problem names the file (and the line of the first bad byte).
    """
    where = str(path)
    try:
        data = Path(path).read_bytes()
    except FileNotFoundError:
        raise InputError(Problem(where, "file not found")) from None
    except IsADirectoryError:
        raise InputError(Problem(where, "is a folder, not a file")) from None
    except OSError as error:
        raise InputError(Problem(where, f"cannot read the file: {error.strerror or error}")) from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as error:
        line = data.count(b"\n", 0, error.start) + 1
        raise InputError(
            Problem(
                f"{where}:{line}", f"not a UTF-8 text file (byte 0x{data[error.start]:02x} at offset {error.start})"
            )
        ) from None


def _current_umask() -> int:
    """The process's file-creation mask (read by setting and restoring it)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def atomic_write_text(path: PathLike, text: str) -> None:
    """Write ``text`` to ``path`` so that readers see the old file or the whole new one, never a part.

    The text goes to a temporary file in the same folder, is flushed to disk,
    and then replaces ``path`` with :func:`os.replace`. Missing parent folders
    are created.

    Parameters
    ----------
    path:
        The file to create or replace.
    text:
        Its new content, written as UTF-8 with ``\\n`` line endings.

    Raises
    ------
    InputError
        If the folder cannot be created or the file cannot be written.
    """
    target = Path(path)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        descriptor, name = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.", suffix=".tmp")
    except OSError as error:
        raise InputError(Problem(str(path), f"cannot write the file: {error.strerror or error}")) from None
    temporary = Path(name)
    try:
        with os.fdopen(descriptor, "w", encoding="utf-8", newline="\n") as handle:
            handle.write(text)
            handle.flush()
            os.fsync(handle.fileno())
        os.chmod(temporary, 0o666 & ~_current_umask())
        os.replace(temporary, target)
    except BaseException as error:
        temporary.unlink(missing_ok=True)
        if isinstance(error, OSError):
            raise InputError(Problem(str(path), f"cannot write the file: {error.strerror or error}")) from None
        raise
