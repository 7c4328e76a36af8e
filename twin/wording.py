"""How a message says a count: `1 run`, `2 runs`, `0 runs`.

One place for it: `twin model-info` of a model trained on one run said "1 runs", and
`twin synth`, `train` and `replay` wrote their counts the same way ("run(s)" elsewhere).
"""

from __future__ import annotations


def counted(n: int, noun: str, plural: str | None = None) -> str:
    """`n` and the noun, singular for exactly one: `counted(1, "run")` → "1 run",
    `counted(3, "run file")` → "3 run files" (`plural` for nouns not made with an s)."""
    return f"{n} {noun if n == 1 else plural or noun + 's'}"
