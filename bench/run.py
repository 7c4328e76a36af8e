"""`make bench`: run every benchmark module and write one JSON file.

Each module in MODULES exposes `run() -> dict` of measured figures.  Modules that do not
exist yet are reported as missing rather than silently skipped.
"""

from __future__ import annotations

import argparse
import importlib
import json
import os
import platform
import tempfile
import time
from pathlib import Path

MODULES = [
    "bench.fem",
    "bench.spindle",
    "bench.apdl",
    "bench.synth",
    "bench.correction",
    "bench.loop",
    "bench.replay_cli",
    "bench.estimator",
    "bench.long_run",
    "bench.drift",
]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", default="bench/results.json")
    parser.add_argument("--only", nargs="*", help="module names (e.g. fem loop)")
    args = parser.parse_args()
    results: dict = {
        "machine": {
            "python": platform.python_version(),
            "cpus": os.cpu_count(),
            "node": platform.machine(),
        },
        "started": time.strftime("%Y-%m-%dT%H:%M:%S"),
    }
    for name in MODULES:
        short = name.split(".")[-1]
        if args.only and short not in args.only:
            continue
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError as exc:
            if exc.name != name:
                raise
            results[short] = {"missing": True}
            continue
        t0 = time.perf_counter()
        results[short] = module.run()
        results[short]["bench_wall_s"] = time.perf_counter() - t0
        print(f"{short}: {json.dumps(results[short])[:400]}")
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.NamedTemporaryFile("w", dir=out.parent, delete=False, suffix=".tmp") as fh:
        json.dump(results, fh, indent=2)
    os.replace(fh.name, out)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
