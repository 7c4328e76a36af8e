"""Cold-process `twin replay` of one bundled 30 min run with 3 methods (issue 11 item 9).

What a user waits for: `twin replay RUN --out DIR --snapshots none --quiet --methods
open_loop,ratio,bpnn` in a fresh interpreter, imports, model load, solve and every output
(fields, CSVs, plots, summary, report) included.  Each of `repeats` runs is a child process
whose own resource usage (`os.wait4`, from a minimal spawner: `bench.child`) gives

    wall_s    elapsed time, start of the process to its exit
    cpu_s     user + system CPU time of the child and of the helpers it forks (the
              figures' plotter, the second half of the methods: `twin.loop.overlap`),
              which it reaps, so `os.wait4` counts them
    rss_MB    peak resident set size of the child or of its largest helper (not a sum)

and the figures reported are the best (minimum) over the repeats: on a shared machine the
noise only ever adds time, so the minimum is the closest to the undisturbed cost.  CPU time
is the figure to compare between commits when the machine is loaded (wall time then includes
waiting for a core, and the replay's forked helpers need the second core to pay off);
`load_1min` records how busy the machine was.

One further run under `python -X importtime` gives the import breakdown: the top-level
imports by cumulative time and the self time summed per top-level package.  Import times
under `-X importtime` are wall times and include the tracing overhead: read them as shares,
not as absolute costs.  A module shared by several packages is charged to whichever imports
it first (scipy.ndimage was charged with scipy's array-API layer and numpy.f2py, which
scipy.sparse loads anyway): check a removal by the CPU time of the cold run, not by the
importer's cumulative figure.  The forked plotter inherits the tracing: matplotlib's imports
are listed too, although they run in the plotter, on the other core, while the replay
itself imports the solver.

`python -m bench.replay_cli [--repeats N]` prints the figures as JSON.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from collections import defaultdict
from pathlib import Path

from bench.child import fresh_env, run_measured

ROOT = Path(__file__).resolve().parent.parent
RUN = ROOT / "examples" / "runs" / "spindle_9000rpm_30min.csv"
METHODS = "open_loop,ratio,bpnn"
TARGET_S = 1.5


def _command(out: Path) -> list[str]:
    return [sys.executable, "-m", "twin", "replay", str(RUN), "--out", str(out),
            "--snapshots", "none", "--quiet", "--methods", METHODS]


def cold_replay(out: Path, env: dict[str, str]) -> dict[str, float]:
    """Wall and CPU seconds and peak RSS (MB) of one cold `twin replay` into `out`."""
    _, usage = run_measured(_command(out), env)
    return {"wall_s": usage.wall_s, "cpu_s": usage.cpu_s, "rss_MB": usage.rss_MB}


def parse_importtime(text: str) -> list[tuple[int, str, float, float]]:
    """(depth, module, self_s, cumulative_s) of each line of `-X importtime` output."""
    rows = []
    for line in text.splitlines():
        if not line.startswith("import time:") or "imported package" in line:
            continue
        self_us, cumulative_us, name = line[len("import time:"):].split("|")
        depth = (len(name) - len(name.lstrip())) // 2
        rows.append((depth, name.strip(), int(self_us) / 1e6, int(cumulative_us) / 1e6))
    return rows


def import_breakdown(out: Path, env: dict[str, str], top: int = 12) -> dict:
    """The heaviest imports of one cold replay under `-X importtime` (seconds, wall)."""
    command = _command(out)
    command[1:1] = ["-X", "importtime"]
    done = subprocess.run(command, env=env, capture_output=True, text=True, check=True)
    rows = parse_importtime(done.stderr)
    roots = sorted((r for r in rows if r[0] == 0), key=lambda r: -r[3])
    per_package: dict[str, float] = defaultdict(float)
    for _, name, self_s, _ in rows:
        per_package[name.split(".")[0]] += self_s
    return {
        "total_s": round(sum(r[2] for r in rows), 3),
        "modules": len(rows),
        "top_level_cumulative_s": {name: round(cum, 3) for _, name, _, cum in roots[:top]},
        "self_by_package_s": dict(
            sorted(((k, round(v, 3)) for k, v in per_package.items()), key=lambda kv: -kv[1])[
                :top]),
        "loaded": {name: name in {r[1] for r in rows}
                   for name in ("matplotlib.pyplot", "matplotlib", "torch", "scipy.ndimage",
                                "numpy.f2py", "skfem", "meshio", "jinja2", "rich", "typer")},
    }


def run(repeats: int = 5) -> dict:
    samples = []
    with tempfile.TemporaryDirectory() as tmp:
        env = fresh_env(Path(tmp) / "pycache")
        cold_replay(Path(tmp) / "warm-up", env)  # compiles the bytecode, fills OS caches
        for i in range(repeats):
            samples.append(cold_replay(Path(tmp) / f"out{i}", env))
        imports = import_breakdown(Path(tmp) / "importtime", env)
    best = {key: min(s[key] for s in samples) for key in ("wall_s", "cpu_s", "rss_MB")}
    return {
        "command": "twin replay spindle_9000rpm_30min.csv --snapshots none --quiet "
                   f"--methods {METHODS}",
        "repeats": repeats,
        "best_wall_s": round(best["wall_s"], 3),
        "best_cpu_s": round(best["cpu_s"], 3),
        "peak_rss_MB": round(best["rss_MB"], 1),
        "cpu_s_samples": [round(s["cpu_s"], 3) for s in samples],
        "wall_s_samples": [round(s["wall_s"], 3) for s in samples],
        "load_1min": round(os.getloadavg()[0], 2),
        "cpus": os.cpu_count(),
        "target_s": TARGET_S,
        "imports": imports,
    }


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    print(json.dumps(run(parser.parse_args().repeats), indent=2))
