"""summary.json of a replay folder, rebuilt from the run folders themselves.

A run is listed when its folder holds a readable accuracy.json; the folder's name is the
run's name (the `run` field inside the file is never used as a path).  An unreadable
accuracy.json is listed under "failed" instead of stopping the summary, and failures
recorded earlier stay listed until that run is replayed again.  Per method, the summary
holds the mean, median and worst run of each metric (`twin.loop.metrics.batch_summary`).
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from pathlib import Path

from twin.loop.metrics import batch_summary


def read_accuracy(path: Path) -> dict | None:
    """A run's accuracy.json if it is readable and has the documented shape, else None."""
    try:
        acc = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(acc, dict) or not isinstance(acc.get("methods"), dict):
        return None
    if not all(_is_number(acc.get(key)) for key in ("speed_rpm", "ambient_C", "duration_s")):
        return None
    for metrics in acc["methods"].values():
        if not isinstance(metrics, dict) or not all(
                _is_metric(v) or isinstance(v, dict) and all(map(_is_metric, v.values()))
                for v in metrics.values()):
            return None
    acc["run"] = path.parent.name
    return acc


def _is_number(value: object) -> bool:
    return (isinstance(value, int | float) and not isinstance(value, bool)
            and math.isfinite(value))


def _is_metric(value: object) -> bool:
    """A metric as accuracy.json holds it: a number, or null where it does not apply (a
    run without drift, a method without a band)."""
    return value is None or _is_number(value)


def is_replay_folder(folder: Path) -> bool:
    """True for a `twin replay` output folder: one holding a <run>/accuracy.json."""
    return any(Path(folder).glob("*/accuracy.json"))


def run_folder(out_root: Path, name: object) -> Path | None:
    """DIR/<name> when `name` is one plain folder name of a run folder in DIR, else None."""
    if not isinstance(name, str) or not name or name.startswith(".") or name != Path(name).name:
        return None
    folder = Path(out_root) / name
    return folder if folder.is_dir() else None


def _previous_failures(out_root: Path) -> list[dict]:
    try:
        old = json.loads((Path(out_root) / "summary.json").read_text(encoding="utf-8"))
        failed = old.get("failed", []) if isinstance(old, dict) else []
    except (OSError, ValueError):
        return []
    if not isinstance(failed, list):
        return []
    return [f for f in failed if isinstance(f, dict) and isinstance(f.get("run"), str)]


def collect_summary(out_root: Path, failed: Sequence[dict] = (),
                    attempted: Sequence[str] = ()) -> dict:
    """summary.json of DIR: every run folder's accuracy, this batch's failures (`failed`),
    unreadable accuracy files, and earlier failures of runs not `attempted` since."""
    runs, unreadable = [], []
    for acc_path in sorted(Path(out_root).glob("*/accuracy.json")):
        if acc_path.parent.name.startswith("."):
            continue  # a batch's staging folder
        acc = read_accuracy(acc_path)
        if acc is None:
            unreadable.append({"run": acc_path.parent.name, "kind": "input",
                               "error": f"{acc_path}: unreadable accuracy.json (replay the "
                                        "run again)"})
        else:
            runs.append(acc)
    done = {r["run"] for r in runs}
    now = list(failed) + unreadable
    seen = {f["run"] for f in now} | set(attempted) | done
    earlier = [f for f in _previous_failures(out_root) if f["run"] not in seen]
    return batch_summary(runs, now + earlier)
