"""Data bundled with the twin, found through `importlib.resources` in every kind of install.

    meshes/reference_spindle.toml   the reference spindle's spec (geometry, materials, ...)
    meshes/reference_spindle.msh    its committed mesh (`twin mesh` rebuilds it byte for byte)
    runs/*.csv                      the example recorded runs (`twin replay` without RUN)
    correction_model.safetensors    the default correction model (bpnn)

In the repository the files live where shared DESIGN.md puts them, in the top-level
`meshes/` and `examples/` folders; the entries here are relative symbolic links to them.
setuptools follows the links when it builds a wheel, so a non-editable install carries the
files themselves, and a source checkout or an editable install reads them in place.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path


def bundled_path(*parts: str) -> Path:
    """File-system path of a bundled file or folder, e.g. `bundled_path("runs")`."""
    resource = resources.files(__name__).joinpath(*parts)
    if not isinstance(resource, Path):  # a zipped install: nothing here can be opened as a file
        raise RuntimeError(f"bundled data must be installed unpacked, got {resource!r}")
    return resource
