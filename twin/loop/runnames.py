"""A run's name: the file name that names its folder under DIR, its row in the reports and
its place in a training split.  Light (no numerical library): `twin replay` checks the
names before it shows any progress, and before its first run's plotter is forked.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from twin.errors import InputError


def run_name(path: str | Path) -> str:
    """The run's folder name under DIR: the file name without its suffix.  A name that is
    not one plain folder name (`..csv`, a leading dot) is refused: it would point at DIR
    itself or hide among the temporary files."""
    name = Path(path).stem
    if not name or name.startswith(".") or name != Path(name).name:
        raise InputError(f"{name!r} cannot name a run folder (a leading dot or a path)",
                         file=str(path))
    try:
        name.encode()
    except UnicodeEncodeError:  # bytes that are not UTF-8: no report could hold the name
        raise InputError("the file name is not UTF-8 text, and it names the run's folder "
                         "and reports: rename the file", file=str(path)) from None
    return name


def check_distinct_names(named: Sequence[tuple[str, str]]) -> None:
    """Refuse two runs of one name ((path, `run_name`) pairs), naming both files: a run is
    known by its file name (its folder under DIR, its place in a training split), not by
    a `# name:` line, which a logger may write alike into every file."""
    names = [name for _, name in named]
    shared = sorted({name for name in names if names.count(name) > 1})
    if shared:
        raise InputError(f"two runs share the name {shared[0]!r} (their file name)",
                         file=", ".join(path for path, name in named if name == shared[0]))


def named_runs(runs: Sequence[str | Path]) -> tuple[list[tuple[str, str]], list[dict]]:
    """(path, run name) of each run whose file name can name its folder, and the failures
    (as `BatchResult.failed` holds them) of the others; InputError if two runs share a
    name.  The command calls it before it shows any progress too: a name clash was told
    below a row per run, drawn for a batch that never started."""
    named: list[tuple[str, str]] = []
    failed: list[dict] = []
    for path in runs:
        try:
            named.append((str(path), run_name(path)))
        except InputError as exc:
            failed.append({"error": str(exc), "kind": "input", "run": Path(path).stem,
                           "path": str(path)})
    check_distinct_names(named)
    return named, failed
