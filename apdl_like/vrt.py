"""The results table a MAPDL Verification Manual deck writes (`/OUT,vmNN,vrt`, *VWRITE).

Each row is a 16-character label (A8,A8 after one blank column), then the TARGET, the
computed value and their ratio; header, comment and rule lines carry fewer numbers.
"""

from __future__ import annotations

import re

_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[EeDd][-+]?\d+)?")
LABEL_END = 17  # 1X, A8, A8


def results_table(text: str) -> list[tuple[str, float, float]]:
    """(label, target, computed) of each row with at least three numbers after the label."""
    rows = []
    for line in text.splitlines():
        if len(line) <= LABEL_END or "|" in line:
            continue
        numbers = _NUMBER.findall(line[LABEL_END:])
        if len(numbers) < 3:
            continue
        target, computed = (float(x.replace("D", "E").replace("d", "e"))
                            for x in numbers[-3:-1])
        rows.append((line[1:LABEL_END].strip(), target, computed))
    return rows
