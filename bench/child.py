"""A command's own wall time, CPU time and peak memory, measured in a fresh process.

Linux carries a process's peak resident set size across `execve` (the kernel keeps the old
image's high-water mark), and Python starts a child by fork or vfork of the calling
process.  Started straight from the bench, whose own peak grows with every benchmark it
has run, a child's `ru_maxrss` therefore starts at the bench's peak: `twin replay` of one
bundled run measured 468 MB there against 156–160 MB under `/usr/bin/time`.  So the
command is started from a minimal interpreter (about 10 MB) whose `os.wait4` of it gives
the figures; the command's own memory is far above that floor.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

SPAWNER = (
    "import json, os, sys, time\n"
    "t = time.perf_counter()\n"
    "pid = os.fork()\n"
    "if pid == 0:\n"
    "    os.execv(sys.argv[2], sys.argv[2:])\n"
    "_, status, usage = os.wait4(pid, 0)\n"
    "wall = time.perf_counter() - t\n"
    "with open(sys.argv[1], 'w') as f:\n"
    "    json.dump({'wall_s': wall, 'cpu_s': usage.ru_utime + usage.ru_stime,\n"
    "               'rss_MB': usage.ru_maxrss / 1024}, f)\n"
    "sys.exit(os.waitstatus_to_exitcode(status))\n"
)
"""Forks, execs argv[2:] (an absolute path first), waits, writes the usage to argv[1]."""

ROOT = Path(__file__).resolve().parent.parent


def fresh_env(pycache: Path) -> dict[str, str]:
    """A fresh process's environment: it imports the same tree as the bench (a worktree or
    the installed package), and keeps compiled bytecode, as a user's runs do, but in
    `pycache` (a temporary folder) rather than beside the sources.  Without it a sandbox's
    PYTHONDONTWRITEBYTECODE made every cold figure compile all it imports (0.25 s)."""
    path = os.pathsep.join(p for p in (str(ROOT), os.environ.get("PYTHONPATH", "")) if p)
    env = {**os.environ, "PYTHONPATH": path, "PYVISTA_OFF_SCREEN": "true",
           "PYTHONPYCACHEPREFIX": str(pycache)}
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


@dataclass(frozen=True)
class Usage:
    """What one child process cost: `os.wait4` of it by the spawner."""

    wall_s: float
    """Start of the process to its exit."""
    cpu_s: float
    """User + system CPU of the child and of the helpers it forks and reaps."""
    rss_MB: float
    """Peak resident set size of the child or of its largest reaped helper (not a sum)."""


def run_measured(command: list[str], env: dict[str, str]) -> tuple[str, Usage]:
    """Run `command` (its first item an absolute path) and return its stdout and usage;
    a non-zero exit raises RuntimeError with the end of its stderr."""
    with tempfile.TemporaryDirectory() as tmp:
        report = Path(tmp) / "usage.json"
        # stderr to a file, not a pipe: a full pipe would block the child
        with open(Path(tmp) / "stderr", "w+b") as stderr:
            done = subprocess.run([sys.executable, "-c", SPAWNER, str(report), *command],
                                  env=env, stdout=subprocess.PIPE, stderr=stderr)
            if done.returncode:
                stderr.seek(0)
                raise RuntimeError(f"{Path(command[0]).name} exited {done.returncode}: "
                                   f"{stderr.read().decode(errors='replace')[-2000:]}")
        usage = Usage(**json.loads(report.read_text()))
    return done.stdout.decode(errors="replace"), usage
