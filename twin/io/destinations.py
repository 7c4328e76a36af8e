"""Where a command may write: the checks every `--out` passes before any work starts.

The atomic writer (`twin.io.atomic`) writes a temporary file beside the target and renames
it over the target.  That rename must never replace something that is not an output:

- one of the command's own inputs (`twin synth --profile P --out P`);
- a folder where a file is expected, or a file where a folder is expected;
- an existing non-regular file: a device (`--out /dev/null` run as root would replace the
  system's /dev/null by a regular file), a fifo or a socket, directly or through a symlink.

Nor may it write into the bundled example runs (`twin.data`'s runs/, examples/runs/ in the
repository), which every `twin replay` without RUN reads: `twin synth --out
examples/runs/spindle_9000rpm_30min.csv` replaced one without a word.  `twin synth
--replace-bundled-runs` writes there (`make examples`).

`check_out_file` and `check_out_dir` refuse such a target with an `InputError` (exit 2)
naming it; commands call them first, before reading or computing anything.  The writer
repeats the regular-file check right before its rename (`atomic_target`).
"""

from __future__ import annotations

import errno
import os
import re
import stat
import tempfile
from collections.abc import Iterable, Sequence
from pathlib import Path

from twin.data import bundled_path
from twin.errors import InputError
from twin.paths import regular_file_info

StrPath = str | os.PathLike[str]


def same_file(a: StrPath, b: StrPath) -> bool:
    """Whether `a` and `b` name one file (through links too); a path that names nothing,
    or a symlink loop, is no file."""
    a, b = Path(a), Path(b)
    try:
        return os.path.samefile(a, b)
    except OSError:
        try:
            return a.resolve() == b.resolve()
        except RuntimeError:  # a symlink loop names no file, so not this one (pathlib's
            return False      # RuntimeError was an internal error before the input check)


def _inside(path: Path, folder: Path) -> bool:
    try:
        path.resolve().relative_to(folder.resolve())
    except (ValueError, RuntimeError):  # RuntimeError: a symlink loop, inside nothing
        return False
    return True


def _check_ancestors(target: Path, option: str | None) -> None:
    """The nearest existing ancestor of `target` must be a folder (mkdir would fail) the
    command may write in."""
    for parent in target.absolute().parents:
        if parent.exists():
            if not parent.is_dir():
                raise InputError(f"{parent} is not a folder", file=str(target), column=option)
            _check_writable(parent, target, option)
            return


def _check_writable(folder: Path, target: Path, option: str | None) -> None:
    """InputError unless a file can be made in `folder`.  Tried, with an unnamed temporary
    file where the system has them (nothing to see or leave behind): `os.access` says yes
    to root on a mount that refuses it (/sys), and the write failed after all the work as
    an internal error."""
    try:
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as exc:
        raise InputError(f"cannot write in {folder}: {_why_unwritable(folder, exc)}",
                         file=str(target), column=option) from None


KERNEL_FILE_SYSTEMS = frozenset({
    "proc", "sysfs", "cgroup", "cgroup2", "debugfs", "tracefs", "securityfs", "configfs",
    "pstore", "bpf", "efivarfs", "binfmt_misc", "fusectl", "devpts", "mqueue", "hugetlbfs"})
"""File systems through which the kernel shows itself (Linux): no command makes files
there, whatever the permissions say."""


def _why_unwritable(folder: Path, exc: OSError) -> str:
    """Why no file can be made in `folder`, as a user can act on it.  The system's words
    alone misled: /proc said 'No such file or directory' of a folder that is there."""
    kind = file_system_type(folder)
    if kind in KERNEL_FILE_SYSTEMS:
        return (f"the kernel's {kind} file system, which holds no files a command can "
                "write (choose a folder on a disk)")
    if exc.errno == errno.EROFS:
        return "the file system is mounted read-only"
    if exc.errno in (errno.EACCES, errno.EPERM):
        return "permission denied (this user may not make files there)"
    if exc.errno == errno.ENOENT:  # the folder is there (it was found): the system said no
        return f"the file system refuses new files there ({exc.strerror})"
    return str(exc.strerror or exc)


def file_system_type(path: Path, mountinfo: str | None = None) -> str | None:
    """The type of the file system `path` is on (`proc`, `ext4`, ...) from Linux's
    /proc/self/mountinfo (or the text `mountinfo`); None where it cannot be told."""
    if mountinfo is None:
        try:
            mountinfo = Path("/proc/self/mountinfo").read_text()
        except OSError:  # not Linux, or no /proc
            return None
    where = os.path.realpath(path)
    best, kind = "", None
    for line in mountinfo.splitlines():
        fields = line.split()
        if "-" not in fields[6:] or len(fields) < 5:
            continue
        # the mount point, with the octal escapes of a space, tab, newline, backslash
        mount = re.sub(r"\\([0-7]{3})", lambda m: chr(int(m.group(1), 8)), fields[4])
        inside = where == mount or where.startswith(mount.rstrip("/") + "/")
        if inside and len(mount) >= len(best):  # the last of mounts stacked on one point
            best, kind = mount, fields[fields.index("-", 6) + 1]
    return kind


REPLACE_BUNDLED_RUNS = "--replace-bundled-runs"
"""The `twin synth` option that lets --out lie in the bundled runs (`make examples`)."""


def check_not_bundled_runs(target: StrPath, option: str | None = "--out",
                           replace: bool | None = None) -> None:
    """InputError if `target` is the bundled runs' folder or lies in it (through the
    package's link too).  `replace`: the value of REPLACE_BUNDLED_RUNS (None: a command
    that has none), which lets `twin synth` write there and is refused for a target
    elsewhere, whose writer may think it updates the bundled runs."""
    try:
        bundled = bundled_path("runs")
    except RuntimeError:  # a zipped install: no runs folder to write into
        return
    inside = _inside(Path(target), bundled)
    if replace and not inside:
        raise InputError(f"is for an --out in the bundled runs ({bundled.resolve()}); this "
                         "--out is elsewhere: leave the option out", column=REPLACE_BUNDLED_RUNS)
    if inside and not replace:
        hint = "" if replace is None else f", or pass {REPLACE_BUNDLED_RUNS} to replace them " \
            "(as `make examples` does)"
        raise InputError(f"lies in the bundled runs ({bundled.resolve()}), which every "
                         f"`twin replay` without RUN reads: write elsewhere{hint}",
                         file=str(target), column=option)


def refuse_special(target: Path, option: str | None = "--out") -> None:
    """InputError if `target` exists (through any symlink) and is not a regular file."""
    # nothing there (or a dangling symlink, which the rename replaces) is fine
    regular_file_info(target, use="use as output", column=option, missing_ok=True)


def check_out_file(out: StrPath, inputs: Iterable[StrPath | None] = (),
                   option: str | None = "--out", also: Iterable[StrPath] = (),
                   suffixes: Sequence[str] = (), replace_bundled_runs: bool | None = None
                   ) -> Path:
    """`out` as a Path if a command may write the file there (see the module doc).

    `inputs` are the files the command reads; `also` are further files it writes beside
    `out` (`RUN.truth.csv`, `MODEL.report.json`), checked the same way.  `suffixes`, if
    given, are the ones `out` may end in, in any case (`S.PNG` too): another name was
    written in a format it does not name, or refused by the writer after the work.
    `replace_bundled_runs`: `check_not_bundled_runs`' `replace`.
    """
    target = Path(out)
    check_not_bundled_runs(target, option, replace_bundled_runs)
    _check_ancestors(target, option)
    read = [Path(p) for p in inputs if p is not None]
    for written in (target, *(Path(p) for p in also)):
        refuse_special(written, option)
        for source in read:
            if same_file(written, source):
                raise InputError(f"is also an input of this command ({source}); refusing to "
                                 "overwrite it", file=str(written), column=option)
    if suffixes and target.suffix.lower() not in suffixes:
        raise InputError(f"must end in {' or '.join(suffixes)}", file=str(target),
                         column=option)
    return target


def check_out_dir(out: StrPath, inputs: Iterable[StrPath | None] = (),
                  option: str | None = "--out", owned: Iterable[str] = (),
                  files: Iterable[str] = (), replace_bundled_runs: bool | None = None
                  ) -> Path:
    """`out` as a Path if a command may write its output folder there.

    The folder may exist (its other contents stay) or not (it is created).  `owned` are
    the names inside it the command replaces (files or whole folders): no input may lie
    there.  `files` are owned names the command writes as files: a folder (or device,
    fifo) there is refused now, not once the work is done.
    `replace_bundled_runs`: `check_not_bundled_runs`' `replace`.
    """
    target = Path(out)
    check_not_bundled_runs(target, option, replace_bundled_runs)
    files = list(files)
    owned = [*owned, *files]
    if not (target.exists() or target.is_symlink()):
        _check_ancestors(target, option)
    else:
        try:
            info = target.stat()
        except OSError as exc:
            raise InputError(f"cannot use as output folder: {exc.strerror or exc}",
                             file=str(target), column=option) from None
        if not stat.S_ISDIR(info.st_mode):
            kind = "a file" if stat.S_ISREG(info.st_mode) else "not a folder"
            raise InputError(f"is {kind}; a folder is expected", file=str(target),
                             column=option)
        _check_writable(target, target, option)  # not its parent: the files go inside
        for name in files:
            refuse_special(target / name, option)
    for source in (Path(p) for p in inputs if p is not None):
        for name in owned:
            place = target / name
            if same_file(place, source) or (place.is_dir() and _inside(source, place)):
                raise InputError(f"the input {source} lies where this command writes "
                                 f"{place}; refusing to replace it", file=str(target),
                                 column=option)
    return target
