"""`twin mesh`: regenerate the spindle mesh from a spec TOML."""

from __future__ import annotations

from pathlib import Path

import typer

from twin.cli.inputs import MAX_SIZE_FACTOR, MIN_SIZE_FACTOR, between


def mesh(
    out: Path = typer.Option(..., "--out", help="Mesh file to write (.msh, gmsh 2.2)."),
    spec: Path | None = typer.Option(
        None, "--spec", help="Spindle spec TOML (default: the bundled reference spindle)."
    ),
    size_factor: float = typer.Option(
        1.0, "--size-factor", callback=between(MIN_SIZE_FACTOR, MAX_SIZE_FACTOR),
        help="Element size multiplier (< 1 refines).",
    ),
    quiet: bool = typer.Option(False, "--quiet", help="Print nothing on success."),
) -> None:
    """Mesh the axisymmetric spindle (regions, boundaries, contact interfaces)."""
    from twin.io.destinations import check_out_file
    from twin.spindle.mesher import build_mesh, mesh_quality, write_msh
    from twin.spindle.spec import load_spec

    check_out_file(out, inputs=[spec], suffixes=(".msh",))
    the_spec = load_spec(spec)
    result = build_mesh(the_spec, size_factor)
    write_msh(result, out)
    if not quiet:
        q = mesh_quality(result.points, result.triangles)
        typer.echo(f"wrote {out}: {q['n_nodes']} nodes, {q['n_cells']} triangles, "
                   f"min angle {q['min_angle_deg']:.1f}°, max aspect {q['max_aspect']:.2f}")
