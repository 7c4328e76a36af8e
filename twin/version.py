"""What version of the twin runs: `--version` of the console scripts (`twin`, `apdl-like`),
the installed distribution's; and `code_identity`, what a replay's resume token records of
the code that replayed it."""

from __future__ import annotations

import functools
import os
from collections.abc import Callable
from pathlib import Path

PACKAGE = "spindle-twin"
"""The distribution whose metadata `--version` reads (pyproject.toml's name)."""

SOURCE_PACKAGES = ("twin", "apdl_like")
"""The packages whose sources `code_identity` digests: the twin and the deck interpreter
that solves a replay's windows."""


def installed_version() -> str | None:
    """The installed distribution's version, or None where the code runs from a checkout
    that was never installed."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(PACKAGE)
    except PackageNotFoundError:
        return None


def version_option(program: str) -> Callable[[bool], None]:
    """A typer callback for `program --version`: prints `program X.Y.Z` and exits 0, or,
    run from a checkout that was never installed, says so and exits 1."""

    def print_version(value: bool) -> None:
        if not value:
            return
        import typer  # a command line's: this module is also the library's

        known = installed_version()
        if known is None:
            typer.echo(f"{program}: the {PACKAGE} package is not installed; no version to tell",
                       err=True)
            raise typer.Exit(1)
        typer.echo(f"{program} {known}")
        raise typer.Exit(0)

    return print_version


@functools.cache
def code_identity() -> dict[str, str | None]:
    """The code a replay runs: `twin_version`, the installed distribution's version (None
    from an uninstalled checkout), and `sources_sha256`, a digest of the Python sources of
    `SOURCE_PACKAGES` and the bundled spindle (`twin/data/meshes`), as they are installed.

    Why both: the version is a static string that stays 0.1.0 from one change of a
    method to the next, so it alone would let a folder replayed by older code pass for a
    current one; the sources say what ran, wherever the package is installed (a wheel,
    an editable install, a checkout on PYTHONPATH).  Every source counts, not a guessed
    list of the ones that shape a result: a change to a command's help text replays a
    resumed batch once more, a missed module would keep a stale result silently.  The
    digest reads the files once a process (about 2 MB, a few ms) and depends on their
    bytes and relative paths only (sorted), not on times or the install's location.
    """
    from importlib.util import find_spec

    roots = {}
    for package in SOURCE_PACKAGES:
        spec = find_spec(package)
        if spec is not None and spec.submodule_search_locations:
            roots[package] = Path(list(spec.submodule_search_locations)[0])
    return {"twin_version": installed_version(), "sources_sha256": sources_digest(roots)}


def sources_digest(roots: dict[str, Path]) -> str:
    """SHA-256 over the `.py` files under each package folder of `roots` ({package name:
    folder}; `__pycache__` left out) and, for `twin`, the files of its `data/meshes`: each
    file's path relative to its package's parent and its bytes, in sorted order."""
    import hashlib  # here, not at the top: `twin --help` imports this module (--version)
    digest = hashlib.sha256()
    for package, root in sorted(roots.items()):
        files = [path for path in _files(root) if path.suffix == ".py"]
        if package == "twin":  # the spindle every replay solves on
            files += sorted(p for p in (root / "data" / "meshes").glob("*") if p.is_file())
        for path in files:
            name = f"{package}/{path.relative_to(root).as_posix()}".encode()
            data = path.read_bytes()
            digest.update(b"%d:%s%d:" % (len(name), name, len(data)))
            digest.update(data)
    return digest.hexdigest()


def _files(root: Path) -> list[Path]:
    """Every file under `root`, in a fixed order, not entering symbolic links to folders
    (the bundled data's links to the repository's top-level folders)."""
    found = []
    for folder, subfolders, names in os.walk(root):
        subfolders[:] = sorted(d for d in subfolders if d != "__pycache__")
        found += [Path(folder) / name for name in sorted(names)]
    return found
