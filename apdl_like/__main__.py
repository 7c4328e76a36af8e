"""`python -m apdl_like` is the `apdl-like` console script."""

from apdl_like.cli import main

main()
