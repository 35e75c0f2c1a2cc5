"""Atomic file writing: readers never see half a file, an interruption leaves the old one or none.

Every file and folder is written into a hidden sibling, ``.<name>.partial-<machine>-<pid>-<random>``,
and renamed into place when complete. A writer that is killed cannot remove its partial sibling;
a later write to the same folder does (:func:`remove_abandoned_writes`), and the name says whose
it was: the machine (a hash of its host name) and the id of the writing process.
"""

from __future__ import annotations

import errno
import hashlib
import os
import re
import secrets
import shutil
import socket
import tempfile
from collections.abc import Mapping
from pathlib import Path


class StorageError(Exception):
    """A run folder cannot be written to, or read from, the given path (raised by :mod:`shakermill.storage`)."""


PARTIAL = "partial"
# An old folder set aside while its replacement is moved into place (:func:`shakermill.storage.write_folder`).
SET_ASIDE = "old"
WRITER_PATTERN = re.compile(
    rf"\.(?P<target>.+)\.(?P<purpose>{PARTIAL}|{SET_ASIDE})-(?P<machine>[0-9a-f]{{8}})-(?P<pid>[0-9]+)-[0-9a-f]{{8}}"
)


def this_machine() -> str:
    return hashlib.sha256(socket.gethostname().encode()).hexdigest()[:8]


def partial_path(path: Path, purpose: str = PARTIAL) -> Path:
    """A hidden, unique sibling of ``path`` to write into before the rename, named after this process."""
    return path.with_name(f".{path.name}.{purpose}-{this_machine()}-{os.getpid()}-{secrets.token_hex(4)}")


def remove_abandoned_writes(folder: Path) -> None:
    """Delete what killed writers left in ``folder``: partial files and folders, and old folders they
    had set aside once their replacement is in place.

    Only what was written on this machine by a process that no longer exists is abandoned. That
    process cannot come back to finish it, so this never breaks a write in progress: not one of a
    concurrent command (its process is alive), nor one on another machine sharing the folder (whose
    process ids mean nothing here; its leftovers wait for a write from that machine). A process id
    reused by an unrelated process only delays the cleanup. A folder set aside is the only copy of a
    run while its replacement is missing, so it is kept until the replacement exists.
    """
    machine = this_machine()
    try:
        entries = [entry for entry in os.scandir(folder) if entry.name.startswith(".")]
    except OSError:  # a folder that does not exist yet, or cannot be listed, holds nothing to clean
        return
    for entry in entries:
        writer = WRITER_PATTERN.fullmatch(entry.name)
        if writer is None or writer["machine"] != machine or _process_exists(int(writer["pid"])):
            continue
        if writer["purpose"] == SET_ASIDE and not (folder / writer["target"]).exists():
            continue
        if entry.is_dir(follow_symlinks=False):
            shutil.rmtree(entry.path, ignore_errors=True)
        else:
            Path(entry.path).unlink(missing_ok=True)


def _process_exists(pid: int) -> bool:
    # psutil, not os.kill(pid, 0): on Windows that call sends Ctrl-C instead of asking. Imported
    # here, where a leftover was found, so that a write with nothing to clean does not pay for it.
    import psutil

    return psutil.pid_exists(pid)


def write_files_atomically(files: Mapping[Path, bytes | memoryview]) -> list[Path]:
    """Write every file to its partial sibling, then rename them all: a full disk leaves none of them new.

    Libraries (HDF5, Arrow, Matplotlib) build their files in memory and only Python's own file
    writing touches the disk, so a full or read-only disk raises one :class:`OSError` with its
    reason, and no library is left holding a half-closed file.
    """
    partials = {path: partial_path(path) for path in files}
    try:
        for path, partial in partials.items():
            partial.write_bytes(files[path])
        for path, partial in partials.items():
            os.replace(partial, path)
    finally:
        for partial in partials.values():
            partial.unlink(missing_ok=True)
    return list(files)


def write_bytes_atomically(path: Path | str, data: bytes | memoryview) -> Path:
    """Write ``data`` through a temporary sibling and a rename; return ``path``."""
    return write_files_atomically({Path(path): data})[0]


def write_text_atomically(path: Path | str, text: str) -> Path:
    """Write ``text`` as UTF-8 through a temporary sibling and a rename; return ``path``."""
    return write_bytes_atomically(path, text.encode("utf-8"))


def create_exclusively(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` complete or not at all; :class:`FileExistsError` if ``path`` exists.

    The file is written to a partial sibling and hard-linked to ``path``: a link, unlike a rename,
    never replaces, so of two processes creating ``path`` at once exactly one succeeds.
    """
    data = text.encode("utf-8")
    partial = partial_path(path)
    try:
        partial.write_bytes(data)
        try:
            os.link(partial, path)
        except FileExistsError:
            raise
        except OSError:  # a file system without hard links (FAT, some network shares)
            _create_in_place(path, data)
    finally:
        partial.unlink(missing_ok=True)


def _create_in_place(path: Path, data: bytes) -> None:
    """Create ``path`` exclusively (O_EXCL) and write it there; a failed write removes it again.

    A reader may see the file before it is complete, which is why :func:`create_exclusively` links instead
    where it can.
    """
    descriptor = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
    try:
        with os.fdopen(descriptor, "wb") as stream:
            stream.write(data)
    except BaseException:
        path.unlink(missing_ok=True)
        raise


def check_writable_place(path: Path, option: str = "--out") -> None:
    """Raise :class:`StorageError` where ``path`` surely cannot be created: under a file, or in a
    read-only or forbidden folder. Checked before long work, so that the work is not lost at the end; the message
    names the ``option`` that gave the path."""
    ancestor = path.absolute().parent
    while not ancestor.exists() and ancestor != ancestor.parent:
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise StorageError(f"{path}: cannot be created, {ancestor} is not a folder; choose another {option}")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        reason = os.strerror(errno.EROFS if _read_only(ancestor) else errno.EACCES)
        raise StorageError(f"{path}: cannot write in {ancestor} ({reason}); choose another {option}")
    # Permissions say nothing to root, nor of a filesystem such as /proc that refuses files: a file is made there.
    try:
        with tempfile.NamedTemporaryFile(dir=ancestor, prefix=".shakermill-probe-"):
            pass
    except OSError as exc:
        raise StorageError(
            f"{path}: cannot write in {ancestor} ({exc.strerror or exc}); choose another {option}"
        ) from None


def _read_only(folder: Path) -> bool:
    return hasattr(os, "statvfs") and bool(os.statvfs(folder).f_flag & os.ST_RDONLY)
