"""`twin mesh`: regenerate the spindle mesh from a spec TOML."""

from __future__ import annotations

from pathlib import Path

import typer

from twin.cli.inputs import MAX_SIZE_FACTOR, MIN_SIZE_FACTOR, between, check_element_size


def mesh(
    out: Path = typer.Option(..., "--out", metavar="FILE.msh",
                             help="Mesh file to write (.msh, gmsh 2.2)."),
    spec: Path | None = typer.Option(
        None, "--spec", metavar="TOML",
        help="Spindle spec TOML (default: the bundled reference spindle)."
    ),
    size_factor: float = typer.Option(
        1.0, "--size-factor", metavar="F", callback=between(MIN_SIZE_FACTOR, MAX_SIZE_FACTOR),
        help="Element size multiplier (< 1 refines).",
    ),
    quiet: bool = typer.Option(False, "--quiet", help="Print nothing on success."),
) -> None:
    """Mesh the axisymmetric spindle (regions, boundaries, contact interfaces)."""
    from twin.io.destinations import check_out_file
    from twin.spindle.mesher import build_mesh, mesh_quality, write_msh
    from twin.spindle.spec import load_spec

    check_out_file(out, inputs=[spec], suffixes=(".msh",))
    _keep_the_bundled_mesh(out, spec, size_factor)
    the_spec = load_spec(spec, option="--spec")
    check_element_size(the_spec, size_factor)
    result = build_mesh(the_spec, size_factor)
    write_msh(result, out)
    if not quiet:
        q = mesh_quality(result.points, result.triangles)
        typer.echo(f"wrote {out}: {q['n_nodes']} nodes, {q['n_cells']} triangles, "
                   f"min angle {q['min_angle_deg']:.1f}°, max aspect {q['max_aspect']:.2f}")


def _keep_the_bundled_mesh(out: Path, spec: Path | None, size_factor: float) -> None:
    """The committed mesh is what every replay of the reference spindle reads: it may be
    regenerated (the bundled spec at size factor 1), never replaced by another mesh."""
    from twin.errors import InputError
    from twin.io.destinations import same_file
    from twin.spindle.model import DEFAULT_MESH_PATH
    from twin.spindle.spec import DEFAULT_SPEC_PATH

    if not same_file(out, DEFAULT_MESH_PATH):
        return
    other_spec = spec is not None and not same_file(spec, DEFAULT_SPEC_PATH)
    if other_spec or size_factor != 1.0:
        raise InputError("is the bundled mesh of the reference spindle at size factor 1, "
                         "which every replay of it reads; write this mesh elsewhere",
                         file=str(out), column="--out")
