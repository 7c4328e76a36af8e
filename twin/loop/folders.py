"""A replay output folder DIR: its lock, run folders replaced whole, orphans removed.

Several batches may write into one DIR at once, and a batch may be killed at any moment.
The rules that keep DIR consistent:
- every file is written atomically (temporary name `.name.PID.HEX.suffix`, then renamed);
- a run folder is built under a staging name and swapped in whole (`replaced_folder`);
- the swap and summary.json's rebuild happen under DIR's lock (`folder_lock`), whose
  file is removed at the end of each turn;
- the next batch into DIR removes what a killed one left (`remove_orphans`).
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from pathlib import Path

from filelock import FileLock

from twin.io.atomic import is_orphan, is_temporary, temporary_name

LOCK_FILE = ".twin.lock"


@contextmanager
def folder_lock(out_root: Path) -> Iterator[None]:
    """Hold the lock of an output folder: batches writing into one DIR take turns at the
    moments they change shared state (a run folder swapped in, summary.json rewritten).

    The lock is the kernel's `flock` on `DIR/.twin.lock`, so a killed holder's lock ends
    with its process.  The file is unlinked while still held, as the last act of the turn,
    so no stray file stays in DIR after a run: a waiter that locked the unlinked file sees
    it has no name left and takes the lock again on a new one (filelock checks `st_nlink`),
    and nothing shared is touched between the unlink and the release.  A killed run's file
    goes with the next turn taken in DIR.
    """
    out_root.mkdir(parents=True, exist_ok=True)
    path = out_root / LOCK_FILE
    with FileLock(path):
        try:
            yield
        finally:
            with suppress(OSError):  # (Windows refuses to unlink an open file: it stays)
                path.unlink()


@contextmanager
def replaced_folder(target: Path) -> Iterator[Path]:
    """Yield an empty staging folder beside `target`; on success it replaces `target` as a
    whole.  On failure the staging folder and any earlier `target` are removed: a failed
    rerun must not leave an older result standing as if it were current."""
    staging = target.with_name(temporary_name(target.name, ".partial"))
    staging.mkdir(parents=True)
    try:
        yield staging
    except BaseException:
        with folder_lock(target.parent):
            shutil.rmtree(staging, ignore_errors=True)
            shutil.rmtree(target, ignore_errors=True)
        raise
    old = target.with_name(temporary_name(target.name, ".old"))
    with folder_lock(target.parent):
        try:
            os.rename(target, old)
        except FileNotFoundError:
            old = None
        os.rename(staging, target)
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)


def remove_orphans(out_root: Path) -> list[Path]:
    """Remove temporary files and staging folders that a killed process left in `out_root`
    and its run folders (their process is gone); a live batch's are kept."""
    removed = []
    runs = [p for p in out_root.iterdir() if p.is_dir() and not is_temporary(p.name)]
    for folder in [out_root, *runs]:
        for entry in folder.iterdir():
            if not is_orphan(entry.name):
                continue
            if entry.is_dir() and not entry.is_symlink():
                shutil.rmtree(entry, ignore_errors=True)
            else:
                entry.unlink(missing_ok=True)
            removed.append(entry)
    return removed
