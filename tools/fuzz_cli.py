"""Try the `twin` and `apdl-like` command lines as a new user and an attacker would.

Every case runs in its own scratch folder and is judged on the issue-14 contract:
expected exit code (0 for valid input, 2 for bad input), no traceback, a bad input's
message names the file, done within 60 s, no input or special file changed and nothing
written outside the outputs the case names.

    PYTHONPATH=$PWD python tools/fuzz_cli.py [--only SUBSTRING] [--keep DIR] [--json F]

Prints one line per case and a table of outcomes per category (issue 14's closing note
lists them).  It runs ~170 command lines (10-20 min); not part of the test suite.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import shutil
import stat
import subprocess
import sys
import tempfile
import time
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING

from tests.test_apdl_language import VALID_DECK
from tests.test_fuzz_inputs import BUNDLED_MODEL, model_with_metadata

if TYPE_CHECKING:
    import numpy as np
    import pyarrow as pa

BIN = Path(sys.executable).parent
TWIN = [str(BIN / "twin")]
APDL = [str(BIN / "apdl-like")]
LIMIT_S = 60.0
REPLAY = ["--methods", "open_loop", "--snapshots", "none", "--quiet"]


@dataclass
class Case:
    name: str
    category: str
    expect: str  # "ok" | "bad"
    setup: Callable[[Path], list[str]]
    outs: tuple[str, ...] = ()  # paths (relative) that may be written
    names: str | None = None  # a bad input's message must contain this
    check: Callable[[Path], str | None] | None = None
    env: dict = field(default_factory=dict)


CASES: list[Case] = []
Setup = Callable[[Path], list[str]]
"""A case's command line, built in its scratch folder."""


def case(name: str, category: str, expect: str, outs: Sequence[str] = (),
         names: str | None = None,
         check: Callable[[Path], str | None] | None = None) -> Callable[[Setup], Setup]:
    def wrap(fn: Setup) -> Setup:
        CASES.append(Case(name, category, expect, fn, tuple(outs), names, check))
        return fn
    return wrap


# ------------------------------------------------------------------ fixtures
BASE: dict[str, str] = {}


def base_run() -> str:
    """A valid 3-minute 1 Hz run (synth), made once."""
    if "run" not in BASE:
        d = Path(tempfile.mkdtemp(prefix="fuzz_base_"))
        subprocess.run([*TWIN, "synth", "--speed", "9000", "--minutes", "3", "--ambient", "25",
                        "--seed", "1", "--out", str(d / "good.csv"), "--quiet"], check=True)
        BASE["run"] = (d / "good.csv").read_text()
        BASE["dir"] = str(d)
    return BASE["run"]


def lines() -> list[str]:
    return base_run().rstrip("\n").split("\n")


def header_index() -> int:
    return next(i for i, ln in enumerate(lines()) if ln.startswith("time_s"))


def columns() -> list[str]:
    return lines()[header_index()].split(",")


def edit_cell(row: int, column: str, value: str) -> str:
    ls = lines()
    h = header_index()
    cols = columns()
    fields = ls[h + 1 + row].split(",")
    fields[cols.index(column)] = value
    ls[h + 1 + row] = ",".join(fields)
    return "\n".join(ls) + "\n"


def edit_column(column: str, fn: Callable[[int, str], str]) -> str:
    ls = lines()
    h = header_index()
    j = columns().index(column)
    for i in range(h + 1, len(ls)):
        f = ls[i].split(",")
        f[j] = fn(i - h - 1, f[j])
        ls[i] = ",".join(f)
    return "\n".join(ls) + "\n"


def put(d: Path, name: str, text: str | bytes) -> str:
    p = d / name
    p.parent.mkdir(parents=True, exist_ok=True)
    if isinstance(text, bytes):
        p.write_bytes(text)
    else:
        p.write_text(text)
    return str(p)


def replay(d: Path, *runs: str, out: str = "out", extra: tuple[str, ...] = ()) -> list[str]:
    return [*TWIN, "replay", *runs, "--out", str(d / out), *REPLAY, *extra]


def run_case(text: str | bytes, name: str = "run.csv") -> Setup:
    return lambda d: replay(d, put(d, name, text))


# ------------------------------------------------------------------ recorded runs
R = "run"
case("valid run", R, "ok", outs=["out"])(run_case(base_run()))
case("valid run, CRLF line ends", R, "ok", outs=["out"])(
    run_case(base_run().replace("\n", "\r\n")))
case("valid run, UTF-8 BOM", R, "ok", outs=["out"])(run_case("\ufeff" + base_run()))
case("valid run, extra text column", R, "ok", outs=["out"])(run_case("\n".join(
    [ln + (",note" if ln.startswith("time_s") else ",hello, world" if i > header_index()
           else "") if not ln.startswith("#") else ln for i, ln in enumerate(lines())]
    ).replace("hello, world", '"hello, world"') + "\n"))
LAST = len(lines()) - header_index() - 2
for label, row, column, value in [
    ("cell longer than 131072 chars", 5, "T1_C", "1" * 140_000),
    ("number cell of 100 digits", 5, "T1_C", "9" * 100),
    ("9_000 in speed", 5, "speed_rpm", "9_000"),
    ("quoted cell over two lines", 5, "speed_rpm", '"9\n000"'),
    ("inf cell", 5, "T2_C", "inf"),
    ("-Infinity cell", 5, "T2_C", "-Infinity"),
    ("hex cell", 5, "T2_C", "0x1A"),
    ("NaN time", 5, "time_s", "nan"),
    ("last time 1e6", LAST, "time_s", "1e6"),
    ("last time 1e9", LAST, "time_s", "1e9"),
    ("last time 1e300", LAST, "time_s", "1e300"),
]:
    case(label, R, "bad", outs=["out"], names="run.csv")(
        run_case(edit_cell(row, column, value)))
case("time goes back, other values", R, "bad", outs=["out"], names="run.csv")(
    run_case(edit_cell(50, "time_s", "10")))


def _repeat_block(d: Path) -> list[str]:
    ls = lines()
    h = header_index()
    text = "\n".join(ls[: h + 101] + ls[h + 91: h + 101] + ls[h + 101:]) + "\n"
    return replay(d, put(d, "run.csv", text))


case("block of 10 rows repeated verbatim", R, "ok", outs=["out"],
     check=lambda d: None if "repeated_rows" in (d / "out/run/quality.json").read_text()
     else "no repeated_rows finding")(_repeat_block)
case("speed over spindle limit", R, "bad", outs=["out"], names="run.csv")(
    run_case(edit_column("speed_rpm", lambda i, v: "20000" if i > 60 else v)))
case("ambient -50", R, "bad", outs=["out"], names="run.csv")(
    run_case(edit_column("ambient_C", lambda i, v: "-50" if i > 60 else v)))
case("coolant 150", R, "bad", outs=["out"], names="run.csv")(
    run_case(edit_column("coolant_C", lambda i, v: "150" if i > 60 else v)
             if "coolant_C" in columns() else
             base_run().replace("T5_C", "T5_C,coolant_C", 1)))
case("negative speed", R, "bad", outs=["out"], names="run.csv")(
    run_case(edit_cell(20, "speed_rpm", "-5")))
case("Kelvin temperatures", R, "bad", outs=["out"], names="run.csv")(
    run_case(edit_column("T1_C", lambda i, v: f"{float(v) + 273.15:.3f}")))
case("all T1 empty (a dead channel, excluded and reported)", R, "ok", outs=["out"])(
    run_case(edit_column("T1_C", lambda i, v: "")))
def _shifted(delta: float) -> str:
    text = base_run()
    for col in ("ambient_C", "coolant_C", "T1_C", "T2_C", "T3_C", "T4_C", "T5_C"):
        if col in columns():
            global BASE
            BASE["run"], keep = text, BASE["run"]
            text = edit_column(col, lambda i, v: f"{float(v) + delta:.4f}" if v not in
                               ("", "nan") else v)
            BASE["run"] = keep
    return text


case("run shifted to about 0 °C", R, "ok", outs=["out"],
     check=lambda d: _finite_acc(d))(run_case(_shifted(-25.0)))
case("run shifted to -20 °C", R, "ok", outs=["out"],
     check=lambda d: _finite_acc(d))(run_case(_shifted(-45.0)))
case("stop: 0 rpm for a minute", R, "ok", outs=["out"])(run_case(
    edit_column("speed_rpm", lambda i, v: "0" if 60 <= i < 120 else v)))
case("empty file", R, "bad", outs=["out"], names="run.csv")(run_case(""))
case("header only", R, "bad", outs=["out"], names="run.csv")(run_case(lines()[header_index()]))
case("binary garbage", R, "bad", outs=["out"], names="run.csv")(
    run_case(os.urandom(4096)))
case("NUL byte in a line", R, "bad", outs=["out"], names="run.csv")(
    run_case(edit_cell(5, "T1_C", "25\x00")))
case("Latin-1 byte", R, "bad", outs=["out"], names="run.csv")(
    run_case(base_run().encode() .replace(b"time_s", b"time_s\xe9", 1)))
case("duplicate header column", R, "bad", outs=["out"], names="run.csv")(
    run_case(base_run().replace("T5_C", "T4_C", 1)))
case("missing column", R, "bad", outs=["out"], names="run.csv")(
    run_case(base_run().replace("T5_C", "T6_C", 1)))
case("too short (1 minute)", R, "bad", outs=["out"], names="run.csv")(
    run_case("\n".join(lines()[: header_index() + 61]) + "\n"))
case("wrong field count", R, "bad", outs=["out"], names="run.csv")(
    run_case(edit_cell(7, "T1_C", "1,2")))
case("unknown suffix", R, "bad", outs=["out"], names="run.txt")(run_case(base_run(), "run.txt"))


def _fifo_run(d: Path) -> list[str]:
    os.mkfifo(d / "run.csv")
    return replay(d, str(d / "run.csv"))


def _dir_run(d: Path) -> list[str]:
    (d / "run.csv").mkdir()
    return replay(d, str(d / "run.csv"))


def _symlink_fifo_run(d: Path) -> list[str]:
    os.mkfifo(d / "pipe")
    os.symlink(d / "pipe", d / "run.csv")
    return replay(d, str(d / "run.csv"))


case("fifo as run", R, "bad", outs=["out"], names="run.csv")(_fifo_run)
case("folder as run", R, "bad", outs=["out"], names="run.csv")(_dir_run)
case("symlink to fifo as run", R, "bad", outs=["out"], names="run.csv")(_symlink_fifo_run)
case("missing run file", R, "bad", outs=["out"], names="nope.csv")(
    lambda d: replay(d, str(d / "nope.csv")))


def _parquet(
    d: Path, mutate: Callable[[dict[str, pa.Array], np.ndarray, list[str]], None]
) -> list[str]:
    import numpy as np
    import pyarrow as pa
    import pyarrow.parquet as pq

    ls = lines()
    h = header_index()
    cols = columns()
    data = np.array([[float(x) for x in ln.split(",")] for ln in ls[h + 1:]])
    table = {c: pa.array(data[:, j]) for j, c in enumerate(cols)}
    mutate(table, data, cols)
    pq.write_table(pa.table(table), d / "run.parquet")
    return replay(d, str(d / "run.parquet"))


def _pa() -> ModuleType:
    import pyarrow as pa
    return pa


case("parquet valid", R, "ok", outs=["out"])(lambda d: _parquet(d, lambda t, x, c: None))
case("parquet text cell ' 31.9 '", R, "ok", outs=["out"])(lambda d: _parquet(
    d, lambda t, x, c: t.__setitem__("T1_C", _pa().array([f" {v:.3f} " for v in x[:, 3]]))))
case("parquet huge uint64 speed", R, "bad", outs=["out"], names="run.parquet")(
    lambda d: _parquet(d, lambda t, x, c: t.__setitem__("speed_rpm", _pa().array(
        [2**64 - 1] + [9000] * (x.shape[0] - 1), type=_pa().uint64()))))
case("parquet bool column", R, "bad", outs=["out"], names="run.parquet")(
    lambda d: _parquet(d, lambda t, x, c: t.__setitem__("T2_C", _pa().array(
        [True] * x.shape[0]))))
case("parquet corrupt bytes", R, "bad", outs=["out"], names="run.parquet")(
    run_case(b"PAR1" + os.urandom(2000) + b"PAR1", "run.parquet"))
case("parquet empty file", R, "bad", outs=["out"], names="run.parquet")(
    run_case(b"", "run.parquet"))


def _finite_acc(d: Path) -> str | None:
    for acc in (d / "out").glob("*/accuracy.json"):
        text = acc.read_text()
        if "Infinity" in text or "NaN" in text:
            return "non-finite accuracy"
        return None
    return "no accuracy.json"


# ------------------------------------------------------------------ --out safety
O = "out"


def _fifo(d: Path, name: str) -> str:
    os.mkfifo(d / name)
    return str(d / name)


def _link_to_fifo(d: Path, name: str) -> str:
    os.mkfifo(d / "pipe")
    os.symlink(d / "pipe", d / name)
    return str(d / name)


def _synth(out: str, *extra: str) -> list[str]:
    return [*TWIN, "synth", "--speed", "9000", "--minutes", "3", "--ambient", "25", "--seed",
            "1", "--out", out, "--quiet", *extra]


case("synth --out fifo.csv", O, "bad", names="fifo.csv")(lambda d: _synth(_fifo(d, "fifo.csv")))
case("synth --out symlink to fifo", O, "bad", names="link.csv")(
    lambda d: _synth(_link_to_fifo(d, "link.csv")))
case("synth --out folder.csv", O, "bad", names="dir.csv")(
    lambda d: (d / "dir.csv").mkdir() or _synth(str(d / "dir.csv")))
case("synth --profile P --out P", O, "bad", names="p.csv")(lambda d: [
    *TWIN, "synth", "--profile", put(d, "p.csv", "time_s,speed_rpm\n0,9000\n"), "--minutes",
    "3", "--ambient", "25", "--seed", "1", "--out", str(d / "p.csv"), "--quiet"])
case("synth --out existing regular file (overwrite)", O, "ok", outs=["old.csv", "old.truth.csv"])(
    lambda d: _synth(put(d, "old.csv", "x")))
case("synth --out in a missing folder (created, as replay creates its own)", O, "ok",
     outs=["missing"])(
    lambda d: _synth(str(d / "missing" / "r.csv")))
case("synth --suite into a folder of another suite's runs", O, "bad", names="old_001.csv")(
    lambda d: put(d, "suite/old_001.csv", base_run()) and [
        *TWIN, "synth", "--suite", "1", "--seed", "1", "--minutes", "2", "--rate", "0.2",
        "--out", str(d / "suite"), "--quiet"])
case("replay --out existing file", O, "bad", names="file")(
    lambda d: replay(d, put(d, "run.csv", base_run()), out="file")
    if put(d, "file", "keep") else None)
case("replay --out fifo", O, "bad", names="pipe")(
    lambda d: replay(d, put(d, "run.csv", base_run()), out=Path(_fifo(d, "pipe")).name))
case("replay --out = its own input", O, "bad", names="run.csv")(
    lambda d: replay(d, put(d, "run.csv", base_run()), out="run.csv"))
case("replay --out a folder holding the run", O, "ok",
     outs=["out/run", "out/report.html", "out/summary.json"])(
    lambda d: replay(d, put(d, "out/run.csv", base_run())))
case("train RUN --out RUN", O, "bad", names="run.csv")(
    lambda d: [*TWIN, "train", put(d, "run.csv", base_run()), "--out", str(d / "run.csv"),
               "--epochs", "1", "--quiet"])
case("train --out fifo", O, "bad", names="m.safetensors")(
    lambda d: [*TWIN, "train", put(d, "run.csv", base_run()), "--out",
               _fifo(d, "m.safetensors"), "--epochs", "1", "--quiet"])
case("train --out folder", O, "bad", names="m.safetensors")(
    lambda d: (d / "m.safetensors").mkdir() or [*TWIN, "train", put(d, "run.csv", base_run()),
                                                "--out", str(d / "m.safetensors"),
                                                "--epochs", "1", "--quiet"])
case("mesh --out fifo.msh", O, "bad", names="f.msh")(
    lambda d: [*TWIN, "mesh", "--out", _fifo(d, "f.msh"), "--quiet"])
case("mesh --out folder.msh", O, "bad", names="f.msh")(
    lambda d: (d / "f.msh").mkdir() or [*TWIN, "mesh", "--out", str(d / "f.msh"), "--quiet"])
case("mesh --out = --spec", O, "bad", names="s.toml")(
    lambda d: [*TWIN, "mesh", "--spec", put(d, "s.toml", "x=1\n"), "--out", str(d / "s.toml")])
case("snapshot --out fifo.png", O, "bad", names="s.png")(
    lambda d: [*TWIN, "snapshot", put(d, "run.csv", base_run()), "--time", "100", "--method",
               "open_loop", "--out", _fifo(d, "s.png")])
case("snapshot --out = run", O, "bad", names="run.csv")(
    lambda d: [*TWIN, "snapshot", put(d, "run.csv", base_run()), "--time", "100", "--method",
               "open_loop", "--out", str(d / "run.csv")])
case("simulate --out existing file", O, "bad", names="f")(
    lambda d: [*TWIN, "simulate", "--speed", "9000", "--minutes", "2", "--ambient", "25",
               "--out", put(d, "f", "keep"), "--quiet"])
case("simulate --out fifo", O, "bad", names="pipe")(
    lambda d: [*TWIN, "simulate", "--speed", "9000", "--minutes", "2", "--ambient", "25",
               "--out", _fifo(d, "pipe"), "--quiet"])
case("apdl-like export-cdb --out fifo", O, "bad", names="m.cdb")(
    lambda d: [*APDL, "export-cdb", "--out", _fifo(d, "m.cdb")])
case("apdl-like export-cdb --out folder", O, "bad", names="m.cdb")(
    lambda d: (d / "m.cdb").mkdir() or [*APDL, "export-cdb", "--out", str(d / "m.cdb")])
case("apdl-like run --out file", O, "bad", names="o")(
    lambda d: [*APDL, "run", put(d, "d.inp", "A = 1\n"), "--out", put(d, "o", "keep")])
case("apdl-like run --out = deck", O, "bad", names="d.inp")(
    lambda d: [*APDL, "run", put(d, "d.inp", "A = 1\n"), "--out", str(d / "d.inp")])


# ------------------------------------------------------------------ other arguments
A = "args"
for label, argv in [
    ("simulate --minutes 1e9", ["simulate", "--speed", "9000", "--minutes", "1e9", "--ambient",
                                "25", "--out", "OUT", "--quiet"]),
    ("simulate --minutes nan", ["simulate", "--speed", "9000", "--minutes", "nan", "--ambient",
                                "25", "--out", "OUT", "--quiet"]),
    ("simulate --field-every 1e-9 (rounded to every step: bounded)",
     ["simulate", "--speed", "9000", "--minutes", "2", "--ambient", "25", "--field-every",
      "1e-9", "--out", "OUT", "--quiet"]),
    ("simulate --speed inf", ["simulate", "--speed", "inf", "--minutes", "2", "--ambient", "25",
                              "--out", "OUT", "--quiet"]),
    ("mesh --size-factor 1e-6", ["mesh", "--size-factor", "1e-6", "--out", "OUT.msh"]),
    ("mesh --size-factor nan", ["mesh", "--size-factor", "nan", "--out", "OUT.msh"]),
    ("replay --jobs 0", ["replay", "RUN", "--jobs", "0", "--out", "OUT"]),
    ("replay --jobs 100000", ["replay", "RUN", "--jobs", "100000", "--methods", "open_loop",
                              "--out", "OUT"]),
    ("replay --methods frob", ["replay", "RUN", "--methods", "frob", "--out", "OUT"]),
    ("snapshot --time nan", ["snapshot", "RUN", "--time", "nan", "--method", "open_loop",
                             "--out", "OUT.png"]),
    ("snapshot --time 1e300", ["snapshot", "RUN", "--time", "1e300", "--method", "open_loop",
                               "--out", "OUT.png"]),
    ("snapshot --time -5", ["snapshot", "RUN", "--time", "-5", "--method", "open_loop",
                            "--out", "OUT.png"]),
    ("train --epochs 0", ["train", "RUN", "--epochs", "0", "--out", "OUT.safetensors"]),
    ("report on a missing folder", ["report", "OUT"]),
]:
    case(label, A, "ok" if "bounded)" in label else "bad",
         outs=["OUT", "OUT.msh", "OUT.png", "OUT.safetensors"])(
        lambda d, argv=argv: [*TWIN, *(str(d / "OUT") + a[3:] if a.startswith("OUT") else
                                       put(d, "run.csv", base_run()) if a == "RUN" else a
                                       for a in argv)])


# ------------------------------------------------------------------ synth arguments
S = "synth"


def synth_args(*args: str, name: str = "r.csv") -> Setup:
    def build(d: Path) -> list[str]:
        base = {"--speed": "9000", "--minutes": "3", "--ambient": "25", "--seed": "1"}
        argv = [*TWIN, "synth", "--out", str(d / name), "--quiet"]
        given = dict(zip(args[::2], args[1::2], strict=True))
        for k, v in {**base, **given}.items():
            if v is None:
                continue
            argv += [f"{k}={v}"]
        return argv
    return build


for label, args, expect in [
    ("--speed inf", ("--speed", "inf"), "bad"),
    ("--speed nan", ("--speed", "nan"), "bad"),
    ("--speed -1", ("--speed", "-1"), "bad"),
    ("--speed 1e300", ("--speed", "1e300"), "bad"),
    ("--speed 20000 (over limit)", ("--speed", "20000"), "bad"),
    ("--coolant nan", ("--coolant", "nan"), "bad"),
    ("--coolant 150", ("--coolant", "150"), "bad"),
    ("--coolant 50", ("--coolant", "50"), "bad"),
    ("--seed=-1", ("--seed", "-1"), "bad"),
    ("--seed 2**32 - 1 (the largest: a suite's runs are seeded below 2**32)",
     ("--seed", str(2**32 - 1)), "ok"),
    ("--seed 2**32", ("--seed", str(2**32)), "bad"),
    ("--ambient 50", ("--ambient", "50"), "bad"),
    ("--ambient nan", ("--ambient", "nan"), "bad"),
    ("--ambient -25", ("--ambient", "-25"), "ok"),
    ("--minutes 0", ("--minutes", "0"), "bad"),
    ("--minutes nan", ("--minutes", "nan"), "bad"),
    ("--minutes 1e9", ("--minutes", "1e9"), "bad"),
    ("--rate 0", ("--rate", "0"), "bad"),
    ("--rate 1e-300", ("--rate", "1e-300"), "bad"),
    ("--speed 0 (a stopped spindle)", ("--speed", "0"), "ok"),
    ("--seed abc", ("--seed", "abc"), "bad"),
]:
    case(f"synth {label}", S, expect, outs=["r.csv", "r.truth.csv"])(synth_args(*args))
case("synth .txt output", S, "bad", names="r.txt")(synth_args(name="r.txt"))


def _synth_then_replay(scenario: str, expect_note: str = "") -> Setup:  # noqa: ARG001
    def build(d: Path) -> list[str]:
        put(d, "s.toml", scenario)
        return [*TWIN, "synth", "--speed", "9000", "--minutes", "3", "--ambient", "25",
                "--seed", "1", "--scenario", str(d / "s.toml"), "--out", str(d / "r.csv"),
                "--quiet"]
    return build


def _replays(d: Path) -> str | None:
    """synth wrote a run: replay must read it (exit 0)."""
    if not (d / "r.csv").is_file():
        return None
    p = subprocess.run(replay(d, str(d / "r.csv")), capture_output=True, text=True, timeout=120)
    return None if p.returncode == 0 else f"replay of synth output exit {p.returncode}: " \
                                          f"{p.stderr.strip()[-200:]}"


SC = "scenario"
for label, toml, expect in [
    ("time_s = [0, inf]", "[coolant]\ntime_s = [0, inf]\ninlet_C = [22, 23]\n", "bad"),
    ("time_s = [0, nan]", "[coolant]\ntime_s = [0, nan]\ninlet_C = [22, 23]\n", "bad"),
    ("inlet_C = [22, 1e300]", "[coolant]\ntime_s = [0, 100]\ninlet_C = [22, 1e300]\n", "bad"),
    ("inlet_C 150", "[coolant]\ntime_s = [0, 100]\ninlet_C = [22, 150]\n", "bad"),
    ("unsorted time", "[coolant]\ntime_s = [100, 0]\ninlet_C = [22, 23]\n", "bad"),
    ("deeply nested", "a = " + "[" * 5000 + "]" * 5000 + "\n", "bad"),
    ("not TOML", "[[[\n", "bad"),
    ("unknown table", "[frobnicate]\nx = 1\n", "bad"),
    ("factor negative", "[bearing_heat.front]\ntime_s = [0]\nfactor = [-1]\n", "bad"),
    ("spike size inf", "[faults]\nspikes = [{sensor = \"T1\", time_s = 60, size = inf}]\n",
     "bad"),
    ("spike size 1e300", "[faults]\nspikes = [{sensor = \"T1\", time_s = 60, size = 1e300}]\n",
     "bad"),
    ("dropout over the whole run (a dead channel, which replay excludes)",
     "[faults]\ndropouts = [{sensor = \"T4\", start_s = 0, end_s = 100000}]\n", "ok"),
    ("ambient table 50 °C", "[ambient]\ntime_s = [0]\nambient_C = [50]\n", "bad"),
    ("stuck every sensor", "[faults]\nstuck = [\"T1\",\"T2\",\"T3\",\"T4\",\"T5\"]\n", "ok"),
    ("valid faults", "[faults]\nstuck = [\"T2\"]\n", "ok"),
]:
    case(f"scenario {label}", SC, expect, outs=["r.csv", "r.truth.csv", "out"],
         names=None if expect == "ok" else "s.toml",
         check=_replays)(_synth_then_replay(toml))

P = "profile"
for label, text, expect in [
    ("valid", "time_s,speed_rpm\n0,6000\n90,0\n120,12000\n", "ok"),
    ("inf speed", "time_s,speed_rpm\n0,inf\n", "bad"),
    ("9_000", "time_s,speed_rpm\n0,9_000\n", "bad"),
    ("over limit", "time_s,speed_rpm\n0,99000\n", "bad"),
    ("time back", "time_s,speed_rpm\n0,6000\n100,1\n50,2\n", "bad"),
    ("empty", "", "bad"),
    ("ambient 50", "time_s,speed_rpm,ambient_C\n0,6000,50\n", "bad"),
    ("time 1e300", "time_s,speed_rpm\n0,6000\n1e300,1000\n", "ok"),
    ("binary", os.urandom(300).decode("latin-1"), "bad"),
]:
    case(f"profile {label}", P, expect, outs=["r.csv", "r.truth.csv"],
         names=None if expect == "ok" else "p.csv")(
        lambda d, text=text: [*TWIN, "synth", "--profile", put(d, "p.csv", text), "--minutes",
                              "3", "--ambient", "25", "--seed", "1", "--out", str(d / "r.csv"),
                              "--quiet"])


# ------------------------------------------------------------------ model files
M = "model"


def model_info(data: bytes) -> Setup:
    return lambda d: [*TWIN, "model-info", put(d, "m.safetensors", data)]


case("model-info bundled model", M, "ok")(model_info(BUNDLED_MODEL.read_bytes()))
case("model random bytes", M, "bad", names="m.safetensors")(model_info(os.urandom(1000)))
case("model empty", M, "bad", names="m.safetensors")(model_info(b""))
case("model truncated", M, "bad", names="m.safetensors")(
    model_info(BUNDLED_MODEL.read_bytes()[:500]))
case("model header length 2**63", M, "bad", names="m.safetensors")(
    model_info((2**63).to_bytes(8, "little") + b"{}"))
case("model hidden_sizes = 5", M, "bad", names="m.safetensors")(
    model_info(model_with_metadata(lambda m: m.__setitem__("hidden_sizes", 5))))
case("model r2 = {heat_front: 5}", M, "bad", names="m.safetensors")(
    model_info(model_with_metadata(lambda m: m.__setitem__("r2", {"heat_front": 5}))))
case("model training_runs = 7", M, "bad", names="m.safetensors")(
    model_info(model_with_metadata(lambda m: m.__setitem__("training_runs", 7))))
case("model metadata a list", M, "bad", names="m.safetensors")(
    model_info(model_with_metadata(lambda m: (m.clear(), m.update({"format": []})))))
case("model-info on a fifo", M, "bad", names="m.safetensors")(
    lambda d: [*TWIN, "model-info", _fifo(d, "m.safetensors")])
case("replay --model corrupt", M, "bad", outs=["out"], names="m.safetensors")(
    lambda d: [*TWIN, "replay", put(d, "run.csv", base_run()), "--out", str(d / "out"),
               "--model", put(d, "m.safetensors", os.urandom(100)), "--quiet"])


# ------------------------------------------------------------------ decks
DK = "deck"


def deck(text: str) -> Setup:
    return lambda d: [*APDL, "run", put(d, "d.inp", text), "--out", str(d / "out")]


for label, text, expect in [
    ("valid conduction deck", VALID_DECK, "ok"),
    ("NaN node coordinate", "/PREP7\nN,1,0.01,NAN\n", "bad"),
    ("node at 0/0", "/PREP7\nN,1,0.01,0/0\n", "bad"),
    ("RECTNG at 1e300, solved", "/PREP7\nET,1,PLANE55,,,1\nMP,KXX,1,50\nRECTNG,0,1e300,0,1e300\n"
     "AMESH,ALL\n/SOLU\nNSEL,S,LOC,X,0\nD,ALL,TEMP,20\nALLSEL\nSOLVE\n", "bad"),
    ("ESIZE 1e-300 on a mapped rectangle", "/PREP7\nET,1,PLANE55,,,1\nESIZE,1e-300\n"
     "RECTNG,0,0.1,0,0.1\nAMESH,ALL\n", "bad"),
    ("CMBLOCK id beyond 2**31", "/PREP7\nN,1,0.01,0\nCMBLOCK,C,NODE,1\n(8i30)\n" + "9" * 30
     + "\n", "bad"),
    ("NBLOCK NaN coordinate", "/PREP7\nNBLOCK,6,SOLID\n(3i9,6e21.13e3)\n"
     + f"{1:9d}{0:9d}{0:9d}{'nan':>21}{0.0:21.13E}{0.0:21.13E}\nN,R5.3,LOC,       -1,\n", "bad"),
    ("EBLOCK (19i0)", "/PREP7\nEBLOCK,19,SOLID\n(19i0)\n1 1 1 1 0 0 0 0 4 0 1 1 2 3 4\n-1\n",
     "bad"),
    ("NBLOCK (999999999i9)", "/PREP7\nNBLOCK,6,SOLID\n(999999999i9,6e21.13)\n1 0 0 0\n-1\n",
     "bad"),
    ("DELTIM 1e-9", VALID_DECK.replace("/SOLU\n", "/SOLU\nANTYPE,TRANS\nTIME,100\nDELTIM,1e-9\n"),
     "bad"),
    ("AMESH inside *DO", "/PREP7\nET,1,PLANE55,,,1\nESIZE,0.0001\n*DO,I,1,1000\n"
     "RECTNG,0,0.1,0,0.1\nAMESH,ALL\n*ENDDO\n", "bad"),
    ("CMBLOCK of a node that does not exist", "/PREP7\nN,1,0.01,0\nN,2,0.02,0\n"
     "CMBLOCK,C,NODE,2\n(8i10)\n         1       500\n", "bad"),
    ("huge loop", "*DO,I,1,1e12\n*ENDDO\n", "bad"),
    ("/INPUT escaping", "/INPUT,../../etc/passwd\n", "bad"),
    ("/OUT escaping", "/OUT,../../escape,txt\n*VWRITE,1\n(F8.2)\n/OUT\n", "bad"),
    ("unknown command (warning)", "FROBNICATE,1\nA = 1\n", "ok"),
    ("binary deck", os.urandom(500).decode("latin-1"), "bad"),
]:
    case(f"deck {label}", DK, expect, outs=["out"],
         names=None if expect == "ok" else "d.inp")(deck(text))
case("deck is a fifo", DK, "bad", outs=["out"], names="d.inp")(
    lambda d: [*APDL, "run", _fifo(d, "d.inp"), "--out", str(d / "out")])


# ------------------------------------------------------------------ batch consistency
B = "batch"


def _good_and_bad(d: Path) -> list[str]:
    return replay(d, put(d, "a.csv", base_run()), put(d, "b.csv", "garbage"),
                  str(d / "missing.csv"))


def _check_good_and_bad(d: Path) -> str | None:
    s = json.loads((d / "out/summary.json").read_text())
    runs = [r["run"] for r in s.get("runs", [])]
    failed = sorted(f["run"] for f in s.get("failed", []))
    if runs != ["a"] or failed != ["b", "missing"]:
        return f"summary runs {runs} failed {failed}"
    return None


case("one good, one bad, one missing", B, "bad", outs=["out"], names="b.csv",
     check=_check_good_and_bad)(_good_and_bad)


def _failed_rerun(d: Path) -> list[str]:
    subprocess.run(replay(d, put(d, "run.csv", base_run())), capture_output=True)
    put(d, "run.csv", "broken")
    return replay(d, str(d / "run.csv"))


def _check_failed_rerun(d: Path) -> str | None:
    if (d / "out/run/accuracy.json").exists():
        return "stale accuracy.json left standing"
    s = json.loads((d / "out/summary.json").read_text())
    if s.get("runs") or not s.get("failed"):
        return f"summary lists {s.get('runs')} / failed {s.get('failed')}"
    return None


case("failed rerun leaves no stale result", B, "bad", outs=["out"], names="run.csv",
     check=_check_failed_rerun)(_failed_rerun)


def _shorter_rerun(d: Path) -> list[str]:
    subprocess.run(replay(d, put(d, "run.csv", base_run()), extra=("--snapshots", "every")),
                   capture_output=True)
    short = "\n".join(lines()[: header_index() + 131]) + "\n"
    put(d, "run.csv", short)
    return replay(d, str(d / "run.csv"))


def _check_shorter(d: Path) -> str | None:
    decks = sorted(p.name for p in (d / "out/run/decks").glob("*.inp"))
    snaps = list((d / "out/run/snapshots").glob("*.png"))
    if len(decks) > 3 or snaps:
        return f"stale files: {len(decks)} decks, {len(snaps)} snapshots"
    return None


case("shorter rerun leaves nothing of the longer", B, "ok", outs=["out"],
     check=_check_shorter)(_shorter_rerun)


def _report_victim(d: Path) -> list[str]:
    subprocess.run(replay(d, put(d, "run.csv", base_run())), capture_output=True)
    acc = d / "out/run/accuracy.json"
    a = json.loads(acc.read_text())
    a["run"] = "../../victim"
    acc.write_text(json.dumps(a))
    return [*TWIN, "report", str(d / "out")]


case("report with run ../../victim", B, "ok", outs=["out"])(_report_victim)


def _report_corrupt(d: Path) -> list[str]:
    subprocess.run(replay(d, put(d, "run.csv", base_run()), put(d, "b.csv", base_run())),
                   capture_output=True)
    (d / "out/run/accuracy.json").write_text("{not json")
    return [*TWIN, "report", str(d / "out")]


case("report with a corrupt accuracy.json (named, exit 2)", B, "bad", outs=["out"],
     names="accuracy.json")(_report_corrupt)


def _resume_corrupt(d: Path) -> list[str]:
    subprocess.run(replay(d, put(d, "run.csv", base_run())), capture_output=True)
    (d / "out/run/accuracy.json").write_text("[1, 2")
    return replay(d, str(d / "run.csv"), extra=("--resume",))


def _check_resumed(d: Path) -> str | None:
    try:
        json.loads((d / "out/run/accuracy.json").read_text())
    except ValueError:
        return "accuracy.json still corrupt"
    return None


case("resume with a corrupt accuracy.json", B, "ok", outs=["out"],
     check=_check_resumed)(_resume_corrupt)


def _resume_missing(d: Path) -> list[str]:
    subprocess.run(replay(d, put(d, "run.csv", base_run())), capture_output=True)
    (d / "out/run/accuracy.json").unlink()
    return replay(d, str(d / "run.csv"), extra=("--resume",))


case("resume with a missing accuracy.json", B, "ok", outs=["out"],
     check=_check_resumed)(_resume_missing)


def _orphans(d: Path) -> list[str]:
    put(d, "out/run/.keypoints.99999.deadbeef.csv", "half")
    put(d, "out/.summary.99999.deadbeef.json", "half")
    return replay(d, put(d, "run.csv", base_run()))


def _check_orphans(d: Path) -> str | None:
    left = [p.name for p in (d / "out").rglob(".*.99999.deadbeef.*")]
    return f"orphans left: {left}" if left else None


case("orphan temp files cleaned by the next run", B, "ok", outs=["out"],
     check=_check_orphans)(_orphans)


def _concurrent(d: Path) -> list[str]:
    put(d, "a.csv", base_run())
    put(d, "b.csv", base_run())
    return ["sh", "-c", " & ".join(" ".join(replay(d, str(d / f"{n}.csv"))) for n in "ab")
            + "; wait"]


def _check_concurrent(d: Path) -> str | None:
    s = json.loads((d / "out/summary.json").read_text())
    runs = sorted(r["run"] for r in s.get("runs", []))
    return None if runs == ["a", "b"] else f"summary lists {runs}"


case("two batches into one --out at once", B, "ok", outs=["out"],
     check=_check_concurrent)(_concurrent)


def _report_on_file(d: Path) -> list[str]:
    return [*TWIN, "report", put(d, "f", "x")]


case("report on a file", B, "bad", names="f")(_report_on_file)


# ------------------------------------------------------------------ the runner
def snapshot(root: Path) -> dict[str, tuple]:
    out = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for name in dirnames + filenames:
            p = Path(dirpath) / name
            st = os.lstat(p)
            if stat.S_ISREG(st.st_mode):
                out[str(p.relative_to(root))] = ("f", hashlib.sha256(p.read_bytes()).hexdigest())
            elif stat.S_ISDIR(st.st_mode):
                out[str(p.relative_to(root))] = ("d",)
            else:
                out[str(p.relative_to(root))] = (stat.S_IFMT(st.st_mode), os.readlink(p)
                                                 if stat.S_ISLNK(st.st_mode) else "")
    return out


def judge(c: Case, d: Path) -> tuple[str, str]:
    try:
        argv = c.setup(d)
    except Exception as exc:  # noqa: BLE001
        return "setup", f"{type(exc).__name__}: {exc}"
    before = snapshot(d)
    t0 = time.monotonic()
    try:
        p = subprocess.run(argv, capture_output=True, text=True, timeout=LIMIT_S * 2,
                           stdin=subprocess.DEVNULL, env={**os.environ, **c.env})
        rc, err = p.returncode, p.stderr
    except subprocess.TimeoutExpired:
        return "wrong", f"timeout after {LIMIT_S * 2:.0f} s"
    elapsed = time.monotonic() - t0
    after = snapshot(d)
    problems = []
    want = 0 if c.expect == "ok" else 2
    if rc != want:
        problems.append(f"exit {rc} (want {want}): {err.strip().splitlines()[-1:] }")
    if "Traceback" in err:
        problems.append("traceback")
    if elapsed > LIMIT_S:
        problems.append(f"took {elapsed:.0f} s")
    if c.expect == "bad" and c.names and c.names not in err:
        problems.append(f"message does not name {c.names}: {err.strip()[:160]!r}")
    allowed = tuple(c.outs)

    def inside(path: str) -> bool:
        return any(path == a or path.startswith(a + "/") for a in allowed)

    for path, sig in before.items():
        if after.get(path) != sig and not inside(path):
            problems.append(f"input changed: {path}")
    for path in after:
        if path not in before and not inside(path):
            problems.append(f"written outside --out: {path}")
    if c.check and not problems:
        try:
            msg = c.check(d)
        except Exception as exc:  # noqa: BLE001
            msg = f"check failed: {type(exc).__name__}: {exc}"
        if msg:
            problems.append(msg)
    if problems:
        return "wrong", "; ".join(problems)
    return ("exit 0" if want == 0 else "exit 2 correct"), f"{elapsed:.1f} s"


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--only", default="")
    ap.add_argument("--keep", default=None)
    ap.add_argument("--json", default=None)
    args = ap.parse_args()
    root = Path(args.keep or tempfile.mkdtemp(prefix="fuzz_cli_"))
    root.mkdir(parents=True, exist_ok=True)
    tally: Counter = Counter()
    rows = []
    for i, c in enumerate(CASES):
        if args.only and args.only not in c.name and args.only != c.category:
            continue
        d = root / f"case{i:03d}"
        d.mkdir()
        outcome, note = judge(c, d)
        tally[(c.category, outcome)] += 1
        rows.append({"case": c.name, "category": c.category, "expect": c.expect,
                     "outcome": outcome, "note": note})
        print(f"{outcome:15s} {c.category:9s} {c.name}: {note}", flush=True)
        if not args.keep:
            shutil.rmtree(d, ignore_errors=True)
    print("\ncategory   exit 0   exit 2 correct   still wrong")
    for cat in dict.fromkeys(c.category for c in CASES):
        print(f"{cat:10s} {tally[(cat, 'exit 0')]:6d} {tally[(cat, 'exit 2 correct')]:16d} "
              f"{tally[(cat, 'wrong')] + tally[(cat, 'setup')]:13d}")
    total = Counter(o for (_, o), n in tally.items() for _ in range(n))
    print(f"{'total':10s} {total['exit 0']:6d} {total['exit 2 correct']:16d} "
          f"{total['wrong'] + total['setup']:13d}")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))
    if BASE.get("dir"):
        shutil.rmtree(BASE["dir"], ignore_errors=True)
    if not args.keep:
        shutil.rmtree(root, ignore_errors=True)


if __name__ == "__main__":
    main()
