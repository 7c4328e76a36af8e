"""`python -m apdl_like` is the `apdl-like` console script."""

from twin.console import apdl_like_main

apdl_like_main()
