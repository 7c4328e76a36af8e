"""Property and fuzz tests (issue 14): every reader of user files either accepts its input
or raises `InputError` (exit 2 on the command line), never anything else; examples are
bounded so the module stays fast."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from apdl_like.parser import parse_deck
from tests.test_runs_reader import csv_text, warmup
from twin.correction.modelfile import load_model
from twin.errors import InputError
from twin.plant.profile import read_speed_profile
from twin.plant.scenario import parse_scenario
from twin.runs import read_run

FAST = settings(max_examples=60, deadline=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture,
                                       HealthCheck.too_slow])
BUNDLED_MODEL = Path(__file__).resolve().parent.parent / "examples" / "correction_model.safetensors"

# cells and fragments the 455-case fuzzing pass used against the readers
TOKENS = st.sampled_from([
    "", ",", '"', '"1\n2"', "9_000", "inf", "-inf", "nan", "NaN", "1e309", "1e-400", "0x10",
    "\x00", "\ufeff", "٣", " 31.9 ", "1" * 200, "-0", "+5", ".5", "5.", "1e5e3", "#", "\r",
    "time_s", "T1_C", "-1e300", "99999999999999999999", "\n", "\t", "é",
])


def only_input_errors(call, *args) -> None:  # noqa: ANN001
    try:
        call(*args)
    except InputError as exc:
        assert str(exc)  # a message to show
        assert "\n" not in exc.reason or len(exc.reason) < 10_000


_RUN_LINES = csv_text(warmup(n=150)).splitlines()


@FAST
@given(st.lists(st.tuples(st.integers(0, len(_RUN_LINES) - 1), st.integers(0, 7), TOKENS,
                          st.sampled_from(["cell", "line", "drop", "dup"])), max_size=4))
def test_run_reader_mutations(tmp_path_factory, edits):
    lines = list(_RUN_LINES)
    for row, col, token, how in edits:
        row = min(row, len(lines) - 1)
        if how == "cell":
            fields = lines[row].split(",")
            fields[col % len(fields)] = token
            lines[row] = ",".join(fields)
        elif how == "line":
            lines[row] = token
        elif how == "drop":
            del lines[row]
        else:
            lines.insert(row, lines[row])
        if not lines:
            lines = [""]
    path = tmp_path_factory.mktemp("run") / "run.csv"
    path.write_text("\n".join(lines) + "\n")
    only_input_errors(read_run, path)


@FAST
@given(st.binary(max_size=600))
def test_run_reader_arbitrary_bytes(tmp_path_factory, data):
    folder = tmp_path_factory.mktemp("run")
    for name in ("run.csv", "run.parquet"):
        (folder / name).write_bytes(data)
        only_input_errors(read_run, folder / name)


SCENARIO_TOKENS = st.sampled_from([
    "[coolant]\n", "[faults]\n", "[bearing_heat.front]\n", "[ambient]\n", "[sensors]\n",
    "time_s = [0, 300]\n", "time_s = [0, inf]\n", "time_s = [nan]\n", "time_s = []\n",
    "factor = [1.0, 1.1]\n", "factor = [-1, 1e308]\n", "inlet_C = [22, 1e300]\n",
    "ambient_C = [24, 25]\n", "noise_C = -1\n", "lag_s = inf\n",
    'spikes = [{sensor = "T1", time_s = 60, size = inf}]\n',
    'dropouts = [{sensor = "T9", start_s = 0, end_s = 1}]\n', 'stuck = ["T2", 5]\n',
    "a = " + "[" * 3000 + "]" * 3000 + "\n", "x = {y = {z = 1}}\n", "[[coolant]]\n", "=\n",
    '"\n', "time_s = 5\n",
])


@FAST
@given(st.lists(SCENARIO_TOKENS, max_size=8))
def test_scenario_parser(parts):
    only_input_errors(parse_scenario, "".join(parts), "s.toml")


@FAST
@given(st.text(max_size=300))
def test_scenario_parser_arbitrary_text(text):
    only_input_errors(parse_scenario, text, "s.toml")


@FAST
@given(st.lists(st.lists(TOKENS, min_size=1, max_size=4), max_size=6), st.booleans())
def test_speed_profile_reader(tmp_path_factory, rows, with_ambient):
    header = "time_s,speed_rpm" + (",ambient_C" if with_ambient else "")
    text = "\n".join([header, *(",".join(r) for r in rows)]) + "\n"
    path = tmp_path_factory.mktemp("profile") / "p.csv"
    path.write_text(text)
    only_input_errors(read_speed_profile, path)


_MODEL = BUNDLED_MODEL.read_bytes()


@FAST
@given(st.lists(st.tuples(st.integers(0, len(_MODEL) - 1), st.integers(0, 255)), min_size=1,
                max_size=6), st.integers(0, len(_MODEL)))
def test_model_file_corruption(tmp_path_factory, flips, cut):
    data = bytearray(_MODEL[:max(cut, 1)])
    for where, value in flips:
        if where < len(data):
            data[where] = value
    path = tmp_path_factory.mktemp("model") / "m.safetensors"
    path.write_bytes(bytes(data))
    only_input_errors(load_model, path)


def model_with_metadata(change) -> bytes:  # noqa: ANN001
    """The bundled model's bytes with its metadata dict changed in place by `change`."""
    n = int.from_bytes(_MODEL[:8], "little")
    header = json.loads(_MODEL[8:8 + n])
    meta = json.loads(header["__metadata__"]["spindle_twin"])
    change(meta)
    header["__metadata__"]["spindle_twin"] = json.dumps(meta)
    text = json.dumps(header).encode()
    text += b" " * (-len(text) % 8)
    return len(text).to_bytes(8, "little") + text + _MODEL[8 + n:]


METADATA_VALUES = st.one_of(st.none(), st.integers(-5, 5), st.text(max_size=5),
                            st.lists(st.integers(), max_size=2),
                            st.dictionaries(st.sampled_from(["heat_front", "value"]),
                                            st.integers(), max_size=2))


@FAST
@given(st.sampled_from(["hidden_sizes", "r2", "training_runs", "samples", "seed", "targets",
                        "sha256", "inputs", "outputs", "version", "config"]), METADATA_VALUES)
def test_model_metadata_of_any_type(tmp_path_factory, key, value):
    path = tmp_path_factory.mktemp("model") / "m.safetensors"
    path.write_bytes(model_with_metadata(lambda m: m.__setitem__(key, value)))
    only_input_errors(load_model, path)


DECK_TOKENS = st.sampled_from([
    "/PREP7", "/SOLU", "N,1,0.01,0", "N,2,NAN,0", "N,3,1e300,0", "N,4,0/0,0", "ET,1,PLANE55",
    "RECTNG,0,1e300,0,1", "AMESH,ALL", "*DO,I,1,3", "*ENDDO", "NBLOCK,6,SOLID",
    "(999999999i9,6e21.13)", "(19i0)", "EBLOCK,19,SOLID", "-1", "CM,C,NODE", "DELTIM,1e-9",
    "NSEL,S,NODE,,99999999999", "A = 1", "B = A/0", "*IF,A,EQ,1,THEN", "*ENDIF", "SOLVE",
    "/INPUT,../x", "'", "!", ",,,,", "E,1,2,3,4",
])


@FAST
@given(st.lists(DECK_TOKENS, max_size=10))
def test_deck_parser(lines):
    only_input_errors(parse_deck, "\n".join(lines) + "\n", "fuzz.inp")


@pytest.mark.parametrize("cell", ["9_000", "1e309", "0x10", "nan", "1" * 70])
def test_profile_cells_read_like_run_cells(tmp_path, cell):
    path = tmp_path / "p.csv"
    path.write_text(f"time_s,speed_rpm\n0,{cell}\n")
    with pytest.raises(InputError) as info:
        read_speed_profile(path)
    assert info.value.row == 2 and info.value.column == "speed_rpm"


@FAST
@given(ambient=st.integers(-3500, 6000).map(lambda v: v / 100.0),
       nan_from=st.integers(0, 150), nan_len=st.integers(0, 150),
       spike=st.integers(-10_000, 10_000).map(lambda v: v / 100.0),
       speed=st.sampled_from([0.0, 9000.0, 15000.0, 15001.0]))
def test_what_the_synth_check_accepts_replay_reads(tmp_path_factory, ambient, nan_from,
                                                   nan_len, spike, speed):
    """`check_replayable` (run by `twin synth` before writing) agrees with `read_run` on
    the written file: synth never writes a run replay refuses, nor refuses one it reads."""
    import numpy as np

    from twin.runs import check_replayable, write_run

    cols = warmup(n=150)
    cols["ambient_C"] = np.full(150, ambient)
    cols["speed_rpm"] = np.full(150, speed)
    for k in range(1, 6):
        cols[f"T{k}_C"] = cols[f"T{k}_C"] - 25.0 + ambient
    cols["T4_C"][nan_from:nan_from + nan_len] = np.nan
    cols["T1_C"][75] += spike
    path = tmp_path_factory.mktemp("synth") / "r.csv"
    try:
        check_replayable(cols, str(path), max_speed_rpm=15000.0)
    except InputError:
        checked = False
    else:
        checked = True
    write_run(path, cols)
    try:
        read_run(path, max_speed_rpm=15000.0)
    except InputError:
        read = False
    else:
        read = True
    assert checked == read
