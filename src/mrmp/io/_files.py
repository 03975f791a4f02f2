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
>>> read_text("/dev/zero")
Traceback (most recent call last):
...
mrmp.core.errors.InputError: /dev/zero: is a device, not a file
"""

from __future__ import annotations

import os
import stat
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import IO

from mrmp.core.errors import InputError, Problem
from mrmp.core.limits import MAX_INPUT_FILE_BYTES

PathLike = str | os.PathLike[str]
"""Anything :class:`pathlib.Path` accepts."""


def file_problem(path: PathLike) -> str | None:
    """Why ``path`` cannot be read as an input file (missing, a folder, a device), or None when it can.

    A regular file or a pipe (``<(...)`` in a shell) can be read; a device
    such as ``/dev/zero`` or ``/dev/urandom`` never ends, so it is refused.

    >>> file_problem("/dev/null"), file_problem("/"), file_problem("/no/such/file")
    ('is a device, not a file', 'is a folder, not a file', 'file not found')
    """
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return "file not found"
    except OSError as error:
        return f"cannot read the file: {error.strerror or error}"
    if stat.S_ISDIR(mode):
        return "is a folder, not a file"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "is a device, not a file"
    if stat.S_ISSOCK(mode):
        return "is a socket, not a file"
    return None


def read_bytes(path: PathLike, limit: int = MAX_INPUT_FILE_BYTES) -> bytes:
    """The bytes of a file of at most ``limit`` bytes, every failure an :class:`InputError` naming the file.

    Raises
    ------
    InputError
        If the file is missing, a folder, a device, unreadable, or longer than
        ``limit`` bytes (checked before reading a regular file, and by reading
        at most one byte more from a pipe).
    """
    where = str(path)
    problem = file_problem(path)
    if problem is not None:
        raise InputError(Problem(where, problem))
    too_long = f"longer than the bound of {limit} bytes"
    try:
        with open(path, "rb") as handle:
            status = os.fstat(handle.fileno())
            if stat.S_ISREG(status.st_mode) and status.st_size > limit:
                raise InputError(Problem(where, too_long))
            data = handle.read(limit + 1)
    except OSError as error:
        raise InputError(Problem(where, f"cannot read the file: {error.strerror or error}")) from None
    if len(data) > limit:
        raise InputError(Problem(where, too_long))
    return data


def read_text(path: PathLike, limit: int = MAX_INPUT_FILE_BYTES) -> str:
    """Read a UTF-8 text file of at most ``limit`` bytes, turning every failure into an :class:`InputError` naming the file.

    Parameters
    ----------
    path:
        The file to read.
    limit:
        The longest file accepted, in bytes (:mod:`mrmp.core.limits`).

    Returns
    -------
    str
        The file's text (line endings untouched).

    Raises
    ------
    InputError
        If the file is missing, a folder, a device, unreadable, too long, or not
        UTF-8 text; the problem names the file (and the line of the first bad byte).
    """
    where = str(path)
    data = read_bytes(path, limit)
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

    The text is written as UTF-8 with ``\\n`` line endings by :func:`atomic_write`.

    Raises
    ------
    InputError
        If the folder cannot be created or the file cannot be written.
    """
    atomic_write(path, lambda handle: handle.write(text.encode("utf-8")))


def atomic_write(path: PathLike, write: Callable[[IO[bytes]], object]) -> None:
    """Call ``write`` on a new file so that readers of ``path`` see the old file or the whole new one, never a part.

    ``write`` fills a temporary file in the same folder (opened for bytes), which
    is flushed to disk and then replaces ``path`` with :func:`os.replace`.
    Missing parent folders are created; on any failure, or an interrupt, the
    temporary file is removed and ``path`` is left as it was.

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
        with os.fdopen(descriptor, "wb") as handle:
            write(handle)
            handle.flush()
            os.fsync(handle.fileno())
        os.chmod(temporary, 0o666 & ~_current_umask())
        os.replace(temporary, target)
    except BaseException as error:
        temporary.unlink(missing_ok=True)
        if isinstance(error, OSError):
            raise InputError(Problem(str(path), f"cannot write the file: {error.strerror or error}")) from None
        raise
