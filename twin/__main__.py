"""`python -m twin` is the `twin` console script."""

from twin.console import twin_main

twin_main()
