"""Run a folder of MAPDL Verification Manual decks with `apdl-like` and tabulate pass/fail.

    python tools/vm_check.py DIR [DIR ...] [--tolerance 0.02] [--timeout 300] [--json FILE]

Each deck runs as written (`python -m apdl_like run DECK --out TMP`, a fresh process in a
scratch folder, so `apdl_like` comes from PYTHONPATH or the installed package, never from the
current directory).  The deck
writes its own results table (`/OUT,vmNN,vrt`): per row a label (A8,A8), the TARGET, the
computed value and their ratio.  A deck passes when it runs (exit 0), writes the table and
every computed value is within the tolerance of its target (relative; a zero target needs
|computed| ≤ tolerance × the table's largest |target|).  Otherwise the reason is one of:

    error        apdl-like exited non-zero (its one-line message)
    no table     ran but wrote no .vrt file (the first unknown commands are listed)
    wrong value  the rows outside the tolerance (label, target, computed)

Unknown or unsupported commands (warnings) are listed in every case: they are what a deck
that fails most likely needs.

The candidate set (issue 16, "2-D thermal and axisymmetric thermal-stress decks"): from the
Verification Manual decks of ansys-mapdl-core 0.74.1 (ansys/mapdl/core/examples/verif),
every deck whose ET commands name only 2-D thermal solids and the thermal elements a 2-D
model uses -- PLANE35, PLANE55, PLANE77, SURF151, SURF152, LINK31, LINK32, LINK33, LINK34,
MASS71 -- optionally switched to PLANE42/82/182/183 for a thermal-stress step.  26 decks:

    vm28 vm32 vm58 vm92 vm93 vm94 vm98 vm99 vm100 vm102 vm104 vm105 vm106 vm107 vm109
    vm110 vm111 vm112 vm113 vm114 vm115 vm116 vm163 vm164 vm227 vm228

(LINK33 is MAPDL's "3-D" conduction bar; the decks above use it for 1-D problems.  Left
out by the rule: vm159, whose COMBIN37 controller is not thermal-only, and decks with
SOLID70, SHELL131 or MATRIX50.)
"""

from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
import tempfile
from pathlib import Path

from apdl_like.vrt import results_table

_UNKNOWN = re.compile(r"^warning: [^:]+:(\d+): (\S+): unknown or unsupported command")


def judge(rows: list[tuple[str, float, float]], tolerance: float) -> list[str]:
    """The rows outside the tolerance, as 'label: target vs computed'."""
    scale = max((abs(t) for _, t, _ in rows), default=1.0)
    bad = []
    for label, target, computed in rows:
        allowed = tolerance * (abs(target) if target != 0.0 else scale)
        if not abs(computed - target) <= allowed:
            bad.append(f"{label}: {target:g} vs {computed:g}")
    return bad


def check_deck(deck: Path, tolerance: float, timeout: float) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "out"
        try:
            proc = subprocess.run([sys.executable, "-m", "apdl_like", "run", str(deck.resolve()),
                                   "--out", str(out)], capture_output=True, text=True,
                                  timeout=timeout, check=False, cwd=tmp)
        except subprocess.TimeoutExpired:
            return {"deck": deck.name, "status": "error", "detail": f"timeout {timeout:g} s",
                    "unknown": []}
        unknown = sorted({m.group(2) for m in map(_UNKNOWN.match, proc.stderr.splitlines())
                          if m})
        result = {"deck": deck.name, "unknown": unknown}
        if proc.returncode != 0:
            last = [ln for ln in proc.stderr.splitlines() if ln and
                    not ln.startswith("warning:")]
            return result | {"status": "error",
                             "detail": f"exit {proc.returncode}: " + (last[-1] if last else "")}
        tables = sorted(out.glob("*.vrt")) if out.is_dir() else []
        if not tables:
            return result | {"status": "no table", "detail": ""}
        rows = results_table(tables[0].read_text(errors="replace"))
        if not rows:
            return result | {"status": "no table", "detail": "no rows with target/computed"}
        bad = judge(rows, tolerance)
        worst = max((abs(c / t - 1.0) for _, t, c in rows if t != 0.0), default=0.0)
        return result | {"status": "wrong value" if bad else "pass",
                         "detail": "; ".join(bad), "rows": len(rows), "worst": worst}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folders", nargs="+", type=Path)
    parser.add_argument("--tolerance", type=float, default=0.02)
    parser.add_argument("--timeout", type=float, default=300.0)
    parser.add_argument("--json", type=Path, default=None, help="also write the table here")
    args = parser.parse_args(argv)
    decks = sorted(p for folder in args.folders for p in folder.glob("*.dat"))
    results = []
    for deck in decks:
        r = check_deck(deck, args.tolerance, args.timeout)
        results.append(r)
        worst = f"{100 * r['worst']:.1f} %" if "worst" in r else ""
        print(f"{r['deck']:<14} {r['status']:<12} {worst:>8}  {r['detail'][:150]}"
              + (f"  [unknown: {' '.join(r['unknown'])}]" if r["unknown"] else ""),
              flush=True)
    passed = sum(r["status"] == "pass" for r in results)
    print(f"{passed} of {len(results)} decks pass (tolerance {100 * args.tolerance:g} %)")
    if args.json is not None:
        args.json.write_text(json.dumps(results, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
