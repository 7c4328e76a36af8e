"""Batch replay: many runs, local processes or a dask.distributed cluster, resumable.

One failing run never stops the others: its error is recorded in summary.json
("failed") and the batch goes on.  A finished run folder carries a `.done.json` token
(input and model digests, methods, the code's version and source digest), written last;
--resume skips runs whose token matches.
"""

from __future__ import annotations

import functools
import signal
import uuid
from collections.abc import Callable, Iterator, Sequence
from contextlib import closing, contextmanager
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING

from twin.errors import InputError
from twin.io.atomic import write_json
from twin.loop.folders import folder_lock, remove_orphans
from twin.loop.overlap import ForkedTask, held_interrupts
from twin.loop.runfiles import (
    add_snapshots,
    is_done,
    replay_run_to_dir,
    resume_token,
)
from twin.loop.runnames import named_runs, run_name
from twin.loop.summary import collect_summary, read_accuracy

if TYPE_CHECKING:
    from dask.distributed import Client

    from twin.spindle.model import SpindleModel


@dataclass(frozen=True)
class ReplayJob:
    run_path: str
    out_root: str
    methods: tuple[str, ...]
    model_path: str | None
    snapshots: str
    assimilate_drift: bool = True  # the estimator's (twin.estimation.method.EstimatorConfig)
    fields: str = "every"  # the window ends written as field files
    stop_event: str | None = None  # a dask batch's `Event`, set when the batch is stopped


class BatchStopped(Exception):  # noqa: N818 - a state, as KeyboardInterrupt
    """The batch this run belonged to was stopped (Ctrl-C) while a dask worker replayed it."""


def _stop_check(event_name: str | None) -> Callable[[], None] | None:
    """`replay_run_to_dir`'s stop: it ends the run (its staging folder removed, no earlier
    result left, as for a local Ctrl-C) once the batch's dask `Event` is set.  A cluster
    runs a started task to its end whatever its client does: the run folders appeared after
    the stopped batch had written its summary without them."""
    if event_name is None:
        return None
    from dask.distributed import Event

    event = Event(event_name)

    def check() -> None:
        if event.is_set():
            raise BatchStopped("the batch was stopped")

    return check


@dataclass
class BatchResult:
    accuracies: list[dict] = field(default_factory=list)
    failed: list[dict] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)

    @property
    def exit_code(self) -> int:
        if any(f["kind"] == "internal" for f in self.failed):
            return 1
        return 2 if self.failed else 0


def run_job(job: ReplayJob, spindle: SpindleModel | None = None, overlap: bool = False,
            plotter: ForkedTask | None = None,
            on_window: Callable[[str, int, int], None] | None = None) -> dict:
    """Replay one run on `spindle` (a loaded `SpindleModel`; None: load the reference
    spindle for this run), with forked helpers on the spare core if `overlap` (`plotter`,
    `on_window`: see `replay_run_to_dir`); never raises: returns {"ok": accuracy} or
    {"error": ...}."""
    try:
        acc = replay_run_to_dir(
            job.run_path, job.out_root, job.methods, job.model_path, job.snapshots,
            spindle=spindle, overlap=overlap, assimilate_drift=job.assimilate_drift,
            plotter=plotter, fields=job.fields, on_window=on_window,
            stop=_stop_check(job.stop_event),
        )
        return {"ok": acc}
    except InputError as exc:
        return {
            "error": str(exc),
            "kind": "input",
            "run": run_name(job.run_path),
            "path": job.run_path,
        }
    except Exception as exc:  # noqa: BLE001 - reported per run, the batch goes on
        return {
            "error": f"{type(exc).__name__}: {exc}",
            "kind": "internal",
            "run": run_name(job.run_path),
            "path": job.run_path,
        }


def replay_batch(
    runs: Sequence[str | Path],
    out_root: str | Path,
    methods: Sequence[str],
    model_path: str | None,
    jobs: int = 1,
    dask_address: str | None = None,
    snapshots: str = "none",
    resume: bool = False,
    progress: Callable[[str, str], None] | None = None,  # (run name, status)
    assimilate_drift: bool = True,
    plotter: ForkedTask | None = None,
    fields: str = "every",
    on_window: Callable[[str, str, int, int], None] | None = None,
) -> BatchResult:
    """Replay `runs` into `out_root`; summary.json then lists every run folder in it.

    Batches may write into one folder at once: each run folder is swapped in whole and
    summary.json is rebuilt from the folders under the folder's lock, so no finished run
    goes missing from it.  Temporary files of killed earlier batches are removed first.
    plotter: a `twin.loop.report.run_plotter` forked earlier, for the first run replayed
    in this process (not used by worker processes or dask).
    on_window(run_name, method, done, total): told after each window a run replayed in
    this process has solved (`replay_run_to_dir`; none from --jobs workers or dask), so
    that a long run shows its progress before it is done.
    """
    out_root = Path(out_root)
    result = BatchResult()
    named, result.failed = named_runs(runs)  # two of one name: refused before any write
    names = [n for _, n in named]
    named = [(path, name) for path, name in named
             if not _refused_folder(out_root / name, path, result)]
    planned = False  # a Ctrl-C before the batch is planned has nothing to clean up
    try:
        # reached before anything is written: an unreachable scheduler (a 20 s wait) left
        # an empty DIR behind; closed on leaving, whatever happens inside
        with dask_session(dask_address) as client:
            todo = _plan(named, out_root, methods, model_path, snapshots, resume, progress,
                         assimilate_drift, fields, result)
            planned = True
            # closed on leaving: a Ctrl-C here ends the worker processes before they go on
            with closing(_execute(todo, jobs, client, progress, plotter,
                                  on_window)) as outcomes:
                for outcome in outcomes:
                    if "ok" in outcome:
                        result.accuracies.append(outcome["ok"])
                    else:
                        result.failed.append(outcome)
    except KeyboardInterrupt:
        if planned:
            remove_orphans(out_root)  # the staging folders of the runs the workers were on
            # A worker ended inside its turn of the folder lock left the lock's file (the
            # lock itself ended with it); the next turn removes it, so take one now.
            with folder_lock(out_root):
                pass
        raise
    order = {n: i for i, n in enumerate(names)}
    result.accuracies.sort(key=lambda a: order.get(a["run"], len(order)))
    write_summary(out_root, result.failed, attempted=names)
    return result


def _plan(named: list[tuple[str, str]], out_root: Path, methods: Sequence[str],
          model_path: str | None, snapshots: str, resume: bool,
          progress: Callable[[str, str], None] | None, assimilate_drift: bool, fields: str,
          result: BatchResult) -> list[ReplayJob]:
    """Make `out_root` (temporary files of killed batches removed) and the jobs to run:
    every (path, run name) of `named` but, with `resume`, the runs already finished,
    whose accuracy goes to `result` as skipped."""
    out_root.mkdir(parents=True, exist_ok=True)
    remove_orphans(out_root)
    todo: list[ReplayJob] = []
    for path, name in named:
        if resume:
            finished = _finished(out_root / name, path, methods, model_path,
                                 assimilate_drift, fields, snapshots)
            if finished is not None:
                result.accuracies.append(finished)
                result.skipped.append(name)
                if progress:
                    progress(name, "skipped")
                continue
        todo.append(ReplayJob(path, str(out_root), tuple(methods), model_path, snapshots,
                              assimilate_drift, fields))
    return todo


def _refused_folder(folder: Path, path: str, result: BatchResult) -> bool:
    """A run whose folder's name is taken by something that is not a folder (a user's
    file) is refused before any work: replacing the run folder as a whole renamed that
    file to a temporary name, which the next batch removed as a killed run's leftover."""
    if not (folder.is_symlink() or folder.exists()) or folder.is_dir():
        return False
    error = InputError("is not a folder, and this run's results go to a folder of that "
                       "name: move it away or choose another --out", file=str(folder))
    result.failed.append({"error": str(error), "kind": "input", "run": folder.name,
                          "path": path})
    return True


def _finished(out_dir: Path, path: str, methods: Sequence[str],
              model_path: str | None, assimilate_drift: bool = True,
              fields: str = "every", snapshots: str = "none") -> dict | None:
    """The accuracy of a run folder --resume may keep, or None: replay it (again) when its
    token does not match or its accuracy.json is missing or unreadable.  A run kept gets
    the snapshots `snapshots` asks for that it lacks, drawn from its field files; it is
    replayed if they cannot be (a field file missing or damaged)."""
    try:
        if not is_done(out_dir, resume_token(path, methods, model_path, assimilate_drift,
                                             fields)):
            return None
    except OSError:
        return None
    accuracy = read_accuracy(out_dir / "accuracy.json")
    if accuracy is None:
        return None
    try:
        add_snapshots(path, out_dir, methods, snapshots, accuracy["duration_s"])
    except (InputError, OSError):
        return None
    return accuracy


@contextmanager
def dask_session(address: str | None) -> Iterator[Client | None]:
    """The batch's dask client: connected to the scheduler at `address` on entering
    (InputError naming --dask if it cannot be), closed on leaving, after the runs or on
    whatever stopped them; None without an address (local runs)."""
    if address is None:
        yield None
        return
    with dask_client(address) as client:
        yield client


def dask_client(address: str) -> Client:
    """A client of the dask scheduler at `address`, or InputError naming --dask."""
    from dask.distributed import Client

    try:
        return Client(address, timeout="20s")
    except OSError as exc:  # nothing listens there: the address given is wrong
        raise InputError(f"cannot reach the dask scheduler at {address} ({exc})",
                         column="--dask") from None


def _execute(todo: list[ReplayJob], jobs: int, client: Client | None,
             progress: Callable[[str, str], None] | None,
             plotter: ForkedTask | None,
             on_window: Callable[[str, str, int, int], None] | None = None,
             ) -> Iterator[dict]:
    """Each job's outcome as it comes: on `client` (a connected dask client; its
    `dask_session` closes it), in `jobs` worker processes, or in this process."""
    if client is not None:
        from dask.distributed import Event
        from dask.distributed import as_completed as dask_completed

        stop = Event(f"twin-replay-stop-{uuid.uuid4().hex}", client=client)
        futures = client.map(run_job, [replace(j, stop_event=stop.name) for j in todo],
                             pure=False)
        try:
            for fut in dask_completed(futures):
                outcome = fut.result()
                _tell(progress, outcome)
                yield outcome
        except BaseException:  # Ctrl-C, or the caller stopped reading (GeneratorExit)
            client.cancel(futures)  # the queued runs; the started ones ask `stop`
            stop.set()
            raise
        return
    # a worker process or a dask task builds its own spindle per run (about 0.5 s of a
    # run's replay); in this process one model serves every run, and the run's forked
    # helpers use the other core (workers fill the cores themselves: none there)
    if jobs <= 1 or len(todo) <= 1:
        from twin.spindle.model import SpindleModel

        spindle = SpindleModel.load() if todo else None
        for job in todo:
            told = (None if on_window is None
                    else functools.partial(on_window, run_name(job.run_path)))
            outcome = run_job(job, spindle, overlap=True, plotter=plotter, on_window=told)
            _tell(progress, outcome)
            yield outcome
        return
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed  # --jobs only

    # the workers leave Ctrl-C (sent to the whole process group) to this process, which
    # ends them: interrupted on their own, a worker between runs died with a traceback, and
    # the others went on with the queued runs while the pool's shutdown waited for them
    earlier = set(multiprocessing.active_children())
    with ProcessPoolExecutor(max_workers=min(jobs, len(todo)),
                             initializer=_ignore_interrupts) as pool:
        try:
            with held_interrupts():  # the workers are forked here
                futures = [pool.submit(run_job, job) for job in todo]
            for fut in as_completed(futures):
                outcome = fut.result()
                _tell(progress, outcome)
                yield outcome
        except BaseException:  # Ctrl-C, or the caller stopped reading (GeneratorExit)
            # the pool's workers: the children started since it was made (it starts them
            # in `submit`, all at the first under fork, as needed otherwise; nothing else
            # here starts one).  ProcessPoolExecutor has no public way to end its workers
            # before Python 3.14 (`terminate_workers`); `multiprocessing.active_children`
            # is public and names them
            for worker in set(multiprocessing.active_children()) - earlier:
                worker.terminate()
            pool.shutdown(wait=True, cancel_futures=True)
            raise


def _ignore_interrupts() -> None:
    """A --jobs worker's start: Ctrl-C is the batch's to handle (see `_execute`)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


FAILED = "failed"
"""How a failed run's status begins, as `replay_batch` tells `progress` (`failed: ERROR`)."""


def _tell(progress: Callable[[str, str], None] | None, outcome: dict) -> None:
    if progress is None:
        return
    if "ok" in outcome:
        progress(outcome["ok"]["run"], "done")
    else:
        progress(outcome["run"], f"{FAILED}: {outcome['error']}")


def write_summary(out_root: Path, failed: list[dict], attempted: Sequence[str] = ()) -> dict:
    """Rebuild DIR/summary.json under the folder's lock from every run folder (see
    `collect_summary`), with this batch's failures."""
    with folder_lock(Path(out_root)):
        summary = collect_summary(Path(out_root), failed, attempted)
        write_json(Path(out_root) / "summary.json", summary)
    return summary
