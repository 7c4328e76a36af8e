"""Emulator inputs and sensor models: scenario TOML, speed profile, lag, noise, faults."""

from __future__ import annotations

import numpy as np
import pytest

from twin.errors import InputError
from twin.plant.profile import read_speed_profile
from twin.plant.scenario import load_scenario, parse_scenario
from twin.plant.sensors import add_noise, apply_faults
from twin.plant.timetable import StepTable, TimeTable
from twin.plant.truth import (
    XY_GAIN_UM_PER_K,
    XY_LAG_S,
    default_tables,
    preload_factor,
    truth_tables,
    xy_drift_um,
)

SCENARIO = """\
[bearing_heat.front]            # multiplier on the nominal (Palmgren) heat of that bearing
time_s = [0, 300, 1800]
factor = [1.00, 1.12, 1.04]
[contact_resistance.rear]
time_s = [0, 1800]
factor = [1.0, 0.8]
[coolant]
time_s = [0, 1800]
inlet_C = [22.0, 23.5]
[ambient]
time_s = [0, 1800]
ambient_C = [24.0, 25.0]
[motor_heat]                    # multiplier on the motor loss (rotor and stator)
time_s = [0]
factor = [1.2]
[film.housing]
time_s = [0, 1800]
factor = [0.7, 0.8]
[film.coolant]
time_s = [0]
factor = [0.8]
[material]
conductivity = 0.92
expansion = 1.05
[sensors]
noise_C = 0.05
lag_s = 8.0
noise_um = 0.1
placement_mm = 0.0
[faults]
stuck = ["T2"]
dropouts = [{sensor = "T4", start_s = 600, end_s = 660}]
spikes = [{sensor = "T1", time_s = 100, size = 6.0}]
"""


def test_design_example_scenario_parses(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(SCENARIO)
    s = load_scenario(path)
    assert s.bearing_heat.front.table()(150.0) == pytest.approx(1.06)
    assert s.bearing_heat.rear is None
    assert s.coolant.table()(900.0) == pytest.approx(22.75)
    assert s.faults.stuck == ["T2_C"] and s.faults.dropouts[0].sensor == "T4_C"
    assert s.motor_heat.table()(0.0) == pytest.approx(1.2)
    assert s.film.housing.table()(900.0) == pytest.approx(0.75) and s.film.rotor is None
    assert (s.material.conductivity, s.material.expansion) == (0.92, 1.05)
    assert s.sensors.placement_mm == 0.0
    assert load_scenario(None).sensors.lag_s == 8.0


@pytest.mark.parametrize("text, row, column, words", [
    ("[bearing_heat.front]\ntime_s = [0, 300]\nfactor = [1.0]\n", 1, "bearing_heat.front",
     "1 values for 2 times"),
    ("[sensors]\nlag_s = 8\nnoise_c = 1\n", 3, "sensors.noise_c", "unknown key"),
    ("[faults]\nstuck = [\"T9\"]\n", 2, "faults.stuck[0]", "unknown sensor"),
    ("\n[coolant]\ntime_s = [0]\ninlet_C = [300]\n", 4, "coolant.inlet_C[0]", "less than"),
    # the one plausible range (twin.contract.OPERATING_TEMPERATURE_C): a coolant at 50 °C
    # was emulated in full and then refused as a run replay would read as Fahrenheit
    ("[coolant]\ntime_s = [0, 60]\ninlet_C = [20, 50]\n", 3, "coolant.inlet_C[1]",
     "less than or equal to 45"),
    ("[ambient]\ntime_s = [0]\nambient_C = [-41]\n", 3, "ambient.ambient_C[0]",
     "greater than or equal to -40"),
    ("[contact_resistance.front]\ntime_s = [0, 60]\nfactor = [1.0, 0.0]\n", 3,
     "contact_resistance.front.factor[1]", "greater than 0"),
    ("[ambient]\ntime_s = [0, 0]\nambient_C = [20, 21]\n", 1, "ambient", "increasing"),
    ("[faults]\ndropouts = [{sensor = \"T1\", start_s = 60, end_s = 10}]\n", 2,
     "faults.dropouts[0]", "end_s"),
    ("x = [\n", 1, None, "not valid TOML"),
    # model-form error tables (issue 12)
    ("[film.housng]\ntime_s = [0]\nfactor = [1]\n", 1, "film.housng", "unknown key"),
    ("[material]\nconductivty = 0.9\n", 2, "material.conductivty", "unknown key"),
    ("\n[sensors]\nplacement_mm = -1\n", 3, "sensors.placement_mm", "greater than or equal"),
    ("[motor_heat]\ntime_s = [0]\nfactor = [0]\n", 3, "motor_heat.factor[0]", "greater than 0"),
    ("[material]\nexpansion = 3\n", 2, "material.expansion", "less than or equal to 2"),
    # a boolean or a quoted number is a slip, not a factor (lax parsing read true as 1.0)
    ("[motor_heat]\ntime_s = [0]\nfactor = [true]\n", 3, "motor_heat.factor[0]",
     "valid number"),
    ("[sensors]\nlag_s = \"8\"\n", 2, "sensors.lag_s", "valid number"),
    # calibration offsets: temperature channels only, each once, within a thermocouple's
    # plausible error
    ("[sensors]\noffset_C = {T2 = 0.3, disp_z = 1.0}\n", 2, "sensors.offset_C.disp_z",
     "'disp_z' is no temperature channel"),
    # a bad channel is told on its own line, not on the table's header
    ("[sensors.offset_C]\nT2 = 0.2\nT9 = 0.1\n", 3, "sensors.offset_C.T9", "'T9'"),
    ("[sensors.offset_C]\nT1 = 0.1\ndisp_z = 0.2\nT3 = 0.1\n", 3,
     "sensors.offset_C.disp_z", "'disp_z' is no temperature channel"),
    ("[sensors.offset_C]\nT2 = 0.2\nT3 = 0.1\nT2_C = 0.1\n", 4, "sensors.offset_C.T2_C",
     "'T2_C' names T2_C a second time (as 'T2' does)"),
    ("[sensors.offset_C]\nT1 = 0.1\ncoolant = -7.5\n", 3, "sensors.offset_C.coolant",
     "greater than or equal to -5"),
])
def test_bad_scenarios(text, row, column, words):
    with pytest.raises(InputError) as info:
        parse_scenario(text, "bad.toml")
    assert info.value.file == "bad.toml"
    assert (info.value.row, info.value.column) == (row, column)
    assert words in info.value.reason


@pytest.mark.parametrize("text, row, column", [
    # a list's bad item is named on its own line, not on its key's (the first line of the
    # list): in a list of ten dropouts the key's line said nothing of which one was wrong
    ('[faults]\ndropouts = [{sensor = "T4", start_s = 600, end_s = 660},\n'
     '            {sensor = "T9", start_s = 700, end_s = 760}]\n', 3, "faults.dropouts[1].sensor"),
    ('[faults]\nspikes = [\n  # one per sensor\n  {sensor = "T1", time_s = 60},\n'
     '  {sensor = "T2", time_s = 120, size = 500.0},\n]\n', 5, "faults.spikes[1].size"),
    ('[faults]\nstuck = ["T1", "T2",\n         "T7"]\n', 3, "faults.stuck[2]"),
    ('[bearing_heat.front]\ntime_s = [0, 300, 600]\nfactor = [\n  1.0, # "x" [\n  1.1,\n'
     '  -1.0,\n]\n', 6, "bearing_heat.front.factor[2]"),
    # arrays of tables: the item's own [[header]] or its key under it
    ('[[faults.dropouts]]\nsensor = "T4"\nstart_s = 600\nend_s = 660\n'
     '[[faults.dropouts]]\nsensor = "T3"\nstart_s = 700\nend_s = 650\n', 5,
     "faults.dropouts[1]"),
    ('[[faults.spikes]]\nsensor = "T4"\ntime_s = 60\n[[faults.spikes]]\nsensor = "T5"\n'
     'time_s = 60\nsize = 1e3\n', 7, "faults.spikes[1].size"),
])
def test_a_list_items_error_names_the_items_line(text, row, column):
    with pytest.raises(InputError) as info:
        parse_scenario(text, "bad.toml")
    assert (info.value.row, info.value.column) == (row, column), str(info.value)


def test_toml_errors_name_the_line_and_key_not_a_row_and_column(tmp_path):
    # the scenario's errors were told in the CSV reader's words: "bad.toml, row 2, column
    # 'material.conductivty'", and a user looked for a column in a TOML file
    from typer.testing import CliRunner

    from twin.cli import app
    from twin.spindle.spec import load_spec

    with pytest.raises(InputError) as info:
        parse_scenario("[material]\nconductivty = 0.9\n", "bad.toml")
    assert str(info.value) == ("bad.toml, line 2, key 'material.conductivty': unknown key "
                               "(check the spelling and the unit in the name)")
    with pytest.raises(InputError) as info:
        parse_scenario("x = [\n", "bad.toml")
    assert str(info.value).startswith("bad.toml, line 1: not valid TOML")
    spec = tmp_path / "spec.toml"
    spec.write_text("[spindle]\nname = 1\n")
    with pytest.raises(InputError) as info:
        load_spec(spec)
    assert str(info.value).startswith(f"{spec}, line 2, key 'spindle.name': ")
    from twin.spindle.spec import DEFAULT_SPEC_PATH

    text = DEFAULT_SPEC_PATH.read_text()
    line = text[:text.index("max_speed_rpm = ")].count("\n") + 1
    spec.write_text(text.replace("max_speed_rpm = ", "max_sped = 1\nmax_speed_rpm = ", 1))
    with pytest.raises(InputError, match=f"line {line}, key 'spindle.max_sped': unknown key"):
        load_spec(spec)
    # pydantic's words ("Field required", "unknown field") were left in the message
    with pytest.raises(InputError) as info:
        parse_scenario("[motor_heat]\nfactor = [1.2]\n", "bad.toml")
    assert str(info.value) == "bad.toml, line 1, key 'motor_heat.time_s': missing required key"
    # a table clashing with the profile's column
    scenario, profile = tmp_path / "s.toml", tmp_path / "p.csv"
    scenario.write_text("[ambient]\ntime_s = [0]\nambient_C = [20]\n")
    profile.write_text("time_s,speed_rpm,ambient_C\n0,6000,20\n")
    result = CliRunner().invoke(app, ["synth", "--profile", str(profile), "--minutes", "2",
                                      "--ambient", "20", "--seed", "1", "--scenario",
                                      str(scenario), "--out", str(tmp_path / "run.csv")])
    assert result.exit_code == 2
    assert result.output.startswith(f"error: {scenario}, key 'ambient': [ambient] and ")
    assert "column 'ambient'" not in result.output and not (tmp_path / "run.csv").exists()


def _spec_text(old: str, new: str) -> str:
    from twin.spindle.spec import DEFAULT_SPEC_PATH

    text = DEFAULT_SPEC_PATH.read_text()
    assert old in text
    return text.replace(old, new, 1)


@pytest.mark.parametrize("scenario, spec_old, spec_new", [
    # a misspelt key: the scenario said "(check the spelling)", the spec "(check the
    # spelling and the unit in the name)"
    ("[sensors]\nnoise_c = 0.1\n", "max_speed_rpm = 15000.0",
     "max_speed_rpm = 15000.0\nmax_speed = 1.0"),
    # a value where a table belongs: "a valid dictionary or instance of Sensors" and
    # "... of MeshOptions" named classes of the code, not anything in the file
    ("sensors = 1\n", "[mesh]\nelement_size_mm = 7.0\nmin_elements_across = 2\n", ""),
])
def test_scenario_and_spec_word_one_problem_alike(tmp_path, scenario, spec_old, spec_new):
    from twin.spindle.spec import load_spec

    with pytest.raises(InputError) as as_scenario:
        parse_scenario(scenario, "bad.toml")
    spec = tmp_path / "spec.toml"
    text = _spec_text(spec_old, spec_new)
    if spec_new == "":  # the table taken out above comes back as a value on top
        text = "mesh = 1\n" + text
    spec.write_text(text)
    with pytest.raises(InputError) as as_spec:
        load_spec(spec)
    assert as_scenario.value.reason == as_spec.value.reason
    assert "instance of" not in as_scenario.value.reason


def test_toml_files_word_a_validators_message_and_more_problems_alike(tmp_path):
    from twin.spindle.spec import load_spec

    # a validator's own words: the spec kept pydantic's "Value error, " before them
    spec = tmp_path / "spec.toml"
    spec.write_text(_spec_text("r_outer_mm = 55.0", "r_outer_mm = 5.0"))
    with pytest.raises(InputError) as info:
        load_spec(spec)
    assert info.value.reason == "r_outer_mm must be larger than r_inner_mm"
    assert info.value.column.startswith("parts[")  # a list's item as a spec names it
    # a second problem: the spec said "(and 1 more problem)", the scenario nothing
    spec.write_text(_spec_text("max_speed_rpm = 15000.0",
                               "max_speed_rpm = 15000.0\nmax_speed = 1.0\nmin_speed = 0"))
    with pytest.raises(InputError) as as_spec:
        load_spec(spec)
    with pytest.raises(InputError) as as_scenario:
        parse_scenario("[sensors]\nnoise_c = 0.1\nlag = 2\n", "bad.toml")
    assert as_scenario.value.reason == as_spec.value.reason
    assert as_spec.value.reason.endswith(" (and 1 more problem)")


def test_toml_text_that_is_not_utf8_names_its_line_as_a_line(tmp_path):
    # read as a CSV file is, its bad byte was at "row 2" of a file of lines and keys
    from twin.spindle.spec import load_spec

    scenario, spec = tmp_path / "s.toml", tmp_path / "spec.toml"
    scenario.write_bytes(b"[sensors]\nnoise_C = 0.1  # caf\xe9\n")
    spec.write_bytes(b"# caf\xe9\n" + _spec_text("[spindle]", "\n[spindle]").encode())
    with pytest.raises(InputError) as as_scenario:
        load_scenario(scenario)
    with pytest.raises(InputError) as as_spec:
        load_spec(spec)
    hint = "(byte 0xE9, 'é' in Windows-1252 or Latin-1); save it as UTF-8 (Excel: 'CSV UTF-8')"
    assert str(as_scenario.value) == (f"{scenario}, line 2, option '--scenario': not UTF-8 "
                                      f"text {hint}")
    assert str(as_spec.value) == f"{spec}, line 1: not UTF-8 text {hint}"


def test_faults_after_the_runs_end_are_refused_naming_them(tmp_path):
    # a spike at 99999 s in a 5-min run landed on its last sample; a late dropout vanished
    from typer.testing import CliRunner

    from twin.cli import app

    path = tmp_path / "late.toml"
    path.write_text('[faults]\nspikes = [{sensor = "T1", time_s = 300, size = 6.0},\n'
                    '          {sensor = "T2", time_s = 99999, size = 6.0}]\n')
    assert len(load_scenario(path).faults.spikes) == 2  # the run's length is not known here
    load_scenario(path, duration_s=99999.0)
    with pytest.raises(InputError, match=r"spike at 99999 s is after the run's end \(300 s\)"
                       ) as info:
        load_scenario(path, duration_s=300.0)
    assert (info.value.row, info.value.column) == (3, "faults.spikes[1].time_s")  # its line
    path.write_text('[faults]\ndropouts = [{sensor = "T3", start_s = 400, end_s = 460}]\n')
    with pytest.raises(InputError, match="dropout from 400 s is after the run's end"):
        load_scenario(path, duration_s=300.0)
    out = tmp_path / "run.csv"
    result = CliRunner().invoke(app, ["synth", "--speed", "9000", "--minutes", "5",
                                      "--ambient", "22", "--seed", "1", "--scenario", str(path),
                                      "--out", str(out)])
    assert result.exit_code == 2 and "faults.dropouts[0].start_s" in result.output
    assert not out.exists()


def test_profile_steps_after_the_runs_end_are_told_naming_the_first(tmp_path):
    # issue13_speed_steps.csv (steps at 600 and 1500 s) in a 5-min run: the two steps were
    # dropped without a word, where a scenario fault after the end is refused; a profile
    # longer than the run is a legitimate reuse, so it is a warning and the run is written
    from typer.testing import CliRunner

    from twin.cli import app

    path = tmp_path / "steps.csv"
    path.write_text("# shift\ntime_s,speed_rpm\n0,6500\n300,9000\n600,11500\n1500,8500\n")
    out = tmp_path / "run.csv"
    args = ["synth", "--profile", str(path), "--ambient", "22", "--seed", "1", "--quiet"]
    result = CliRunner().invoke(app, [*args, "--minutes", "5", "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert result.output == (f"warning: {path}, line 5, column 'time_s': the step at 600 s is "
                             "after the run's end (300 s, --minutes 5); 2 steps of the profile "
                             "from there on left out of the run\n")
    assert out.is_file()
    # a step at the end itself is reached (the run's last sample), as a fault there is
    result = CliRunner().invoke(app, [*args, "--minutes", "10", "--out", str(out)])
    assert result.exit_code == 0 and "line 6" in result.output and "1 step of" in result.output
    result = CliRunner().invoke(app, [*args, "--minutes", "25", "--out", str(out)])
    assert result.exit_code == 0 and result.output == ""


def test_speed_profile(tmp_path):
    path = tmp_path / "p.csv"
    path.write_text("# warm-up then full speed\ntime_s,speed_rpm,ambient_C\n0,6000,24\n"
                    "600,12000,24.5\n")
    p = read_speed_profile(path)
    np.testing.assert_array_equal(p.speed_rpm(np.array([0, 599.9, 600, 5000])),
                                  [6000, 6000, 12000, 12000])
    assert p.ambient_C(700.0) == 24.5
    assert p.speed_rpm.changes_in(0.0, 1800.0).tolist() == [600.0]


@pytest.mark.parametrize("text, row, column", [
    ("time_s,speed\n0,1\n", 1, "speed_rpm"),
    ("time_s,speed_rpm\n0,9000\n60,fast\n", 3, "speed_rpm"),
    ("time_s,speed_rpm\n0,9000\n0,8000\n", 3, "time_s"),
    ("time_s,speed_rpm\n0,-1\n", 2, "speed_rpm"),
    ("time_s,speed_rpm,ambient_C\n0,9000,298\n", 2, "ambient_C"),
    ("time_s,speed_rpm,ambient_C\n0,9000,25\n60,9000,50\n", 3, "ambient_C"),  # > 45 °C
    # a first row after 0 s held its speed back to 0 s without a word (a spindle standing
    # until then was as likely meant): the row is named
    ("# warm start\ntime_s,speed_rpm\n60,9000\n600,12000\n", 3, "time_s"),
    ("time_s,speed_rpm\n0.5,9000\n", 2, "time_s"),
    ("time_s,speed_rpm\n", 1, None),
    # a `;` file reads (tests/test_csv_dialect.py); one whose header holds tabs too is
    # told, as is "9.000" rpm where no other cell says whether '.' is a decimal mark
    ("# from the logger\ntime_s;speed_rpm\tambient_C\n0;9000\n", 2, None),
    ("time_s;speed_rpm\n0;0\n60;9.000\n", 3, "speed_rpm"),
    # a column named twice (or without a name) was read from its first place without a
    # word: which speed the emulated spindle ran was the reader's choice, not the file's
    ("time_s,speed_rpm,speed_rpm\n0,6000,5000\n", 1, "speed_rpm"),
    ("time_s,speed_rpm,,ambient_C\n0,6000,1,24\n", 1, None),
])
def test_bad_speed_profiles(tmp_path, text, row, column):
    path = tmp_path / "p.csv"
    path.write_text(text)
    with pytest.raises(InputError) as info:
        read_speed_profile(path)
    assert (info.value.row, info.value.column) == (row, column)
    # a profile is a CSV file: its place is called a line, as an editor numbers it (the
    # location said "row 3" of a file whose first data row was line 3)
    assert str(info.value).startswith(f"{path}, line {row}"), info.value


def _run_and_profile_text(change) -> str:  # noqa: ANN001
    """A recorded run of 31 rows 10 s apart, which is a valid speed profile too (a profile
    reads its time_s, speed_rpm and ambient_C), with its lines changed by `change`."""
    lines = ["time_s,speed_rpm,ambient_C,T1_C,T2_C,T3_C,T4_C,T5_C"]
    lines += [f"{10 * i},6000,22.0,{22 + 0.01 * i:.2f},22.1,22.2,22.3,22.4" for i in range(31)]
    return "\n".join(change(lines)) + "\n"


def _cell(lines: list[str], line: int, column: int, value: str) -> list[str]:
    cells = lines[line - 1].split(",")
    cells[column] = value
    return lines[:line - 1] + [",".join(cells)] + lines[line:]


@pytest.mark.parametrize("change", [
    lambda lines: [],  # empty file
    lambda lines: ["# name: run", ""],  # comments only
    lambda lines: lines[:1],  # a header and no data
    lambda lines: [",".join(c for c in ln.split(",")[:1] + ln.split(",")[2:]) for ln in lines],
    lambda lines: _cell(lines, 3, 1, "abc"),
    lambda lines: _cell(lines, 3, 0, ""),  # no time
    lambda lines: lines[:2] + [lines[3], lines[2]] + lines[4:],  # time goes back
    lambda lines: _cell(lines, 3, 1, "-10"),
    lambda lines: lines[:2] + [lines[2] + ",1"] + lines[3:],  # a field too many
], ids=["empty", "comments-only", "header-only", "no-speed-column", "not-a-number",
        "no-time", "time-goes-back", "negative-speed", "field-count"])
def test_a_profile_is_refused_in_the_words_of_the_run_reader(tmp_path, change):
    # the profile reader was a reader of its own: the same file was "empty speed profile"
    # to synth and "empty file: no header row and no data" to replay, a blank time "'' is
    # not a finite number" and "time is missing", time going back "time must increase
    # from row to row" and "time goes back from 20 s (line 3) to 10 s"
    from twin.runs import read_run

    path = tmp_path / "run.csv"
    path.write_text(_run_and_profile_text(change))
    with pytest.raises(InputError) as as_run:
        read_run(path)
    with pytest.raises(InputError) as as_profile:
        read_speed_profile(path)
    assert str(as_profile.value) == str(as_run.value)


@pytest.mark.parametrize("cell", ["", "nan", "NA"])
def test_a_profile_step_without_a_value_is_called_missing(tmp_path, cell):
    # a blank speed was "'' is not a finite number": no number was there to be infinite
    path = tmp_path / "p.csv"
    path.write_text(f"time_s,speed_rpm,ambient_C\n0,6000,22\n60,{cell},22\n120,0,{cell}\n")
    with pytest.raises(InputError) as info:
        read_speed_profile(path)
    assert str(info.value) == f"{path}, line 3, column 'speed_rpm': value is missing"
    path.write_text(f"time_s,speed_rpm,ambient_C\n0,6000,22\n60,0,{cell}\n")
    with pytest.raises(InputError) as info:
        read_speed_profile(path)
    assert str(info.value) == f"{path}, line 3, column 'ambient_C': value is missing"


def test_scenario_and_profile_take_the_range_replay_takes(tmp_path):
    from twin.contract import OPERATING_TEMPERATURE_C

    low, high = OPERATING_TEMPERATURE_C
    scenario = parse_scenario(f"[ambient]\ntime_s = [0, 60]\nambient_C = [{low}, {high}]\n")
    assert scenario.ambient.ambient_C == [low, high]
    path = tmp_path / "p.csv"
    path.write_text(f"time_s,speed_rpm,ambient_C\n0,6000,{low}\n60,6000,{high}\n")
    assert read_speed_profile(path).ambient_C(60.0) == high


def test_tables():
    t = TimeTable([0, 100], [1.0, 2.0])
    np.testing.assert_allclose(t([-5, 50, 500]), [1.0, 1.5, 2.0])
    s = StepTable([0, 100], [1.0, 2.0])
    np.testing.assert_allclose(s([50, 100, 500]), [1.0, 2.0, 2.0])
    with pytest.raises(ValueError):
        TimeTable([0, 0], [1, 2])


def test_noise_statistics_and_determinism():
    x = np.zeros(20000)
    a = add_noise(np.random.default_rng(3), x, 0.05)
    b = add_noise(np.random.default_rng(3), x, 0.05)
    np.testing.assert_array_equal(a, b)
    assert np.std(a) == pytest.approx(0.05, rel=0.03)


def test_faults():
    s = parse_scenario(SCENARIO)
    t = np.arange(0.0, 900.0)
    cols = {f"T{k}_C": 25.0 + 0.01 * t for k in range(1, 6)}
    out = apply_faults(t, cols, s.faults)
    assert (out["T2_C"] == 25.0).all()
    assert np.isnan(out["T4_C"][600:661]).all() and np.isfinite(out["T4_C"][:600]).all()
    assert np.isfinite(out["T4_C"][661:]).all()
    assert out["T1_C"][100] == pytest.approx(25.0 + 1.0 + 6.0)
    assert out["T3_C"] is not cols["T3_C"] and (cols["T2_C"] == 25.0 + 0.01 * t).all()


def test_preload_factor_shape():
    t = np.arange(0.0, 1801.0, 10.0)
    f = preload_factor(t, np.full(t.size, 9000.0), 0.10, 0.07, 90.0, 550.0)
    peak = int(np.argmax(f))
    assert f[0] == 1.0
    assert 60.0 <= t[peak] <= 400.0 and 1.03 < f[peak] < 1.10  # builds up early ...
    assert f[-1] < f[peak] - 0.02  # ... then relaxes
    assert np.all(np.abs(f - 1.0) < 0.10)
    slow = preload_factor(t, np.full(t.size, 3000.0), 0.10, 0.07, 90.0, 550.0)
    assert np.max(slow) - 1.0 < np.max(f) - 1.0  # smaller swing at lower speed
    assert preload_factor(t, np.zeros(t.size), 0.1, 0.07, 90.0, 550.0).tolist() == [1.0] * t.size


def test_default_truth_is_seeded_and_overridable():
    def speed(t):
        return np.full(np.shape(t), 9000.0)

    def ambient(t):
        return np.full(np.shape(t), 25.0)

    a = default_tables(np.random.default_rng(1), 1800.0, speed, ambient, 22.0)
    b = default_tables(np.random.default_rng(1), 1800.0, speed, ambient, 22.0)
    c = default_tables(np.random.default_rng(2), 1800.0, speed, ambient, 22.0)
    np.testing.assert_array_equal(a.H_front.values, b.H_front.values)
    assert not np.array_equal(a.H_front.values, c.H_front.values)
    for table in (a.H_front, a.H_rear, a.R_front, a.R_rear):
        assert np.all(np.abs(table.values - 1.0) <= 0.15)
    # X/Y come from the spindle's own temperatures (xy_drift_um), scaled per run
    assert a.x_um is None and a.y_um is None
    assert all(0.9 <= g <= 1.1 for g in a.xy_gain_scale)
    assert a.coolant_C(0.0) == pytest.approx(22.0) and a.ambient_C(0.0) == pytest.approx(25.0)
    merged = truth_tables(parse_scenario(SCENARIO), a)
    assert merged.H_front(300.0) == pytest.approx(1.12)
    assert merged.H_rear is a.H_rear and merged.R_rear(1800.0) == pytest.approx(0.8)


def test_default_drift_stays_in_the_plausible_range():
    # a run started at the range's edge: the coolant's default rise (0.3–1.2 K) took it
    # past 45 °C and the truth's own nominal model refused it, naming no option
    from twin.contract import OPERATING_TEMPERATURE_C

    low, high = OPERATING_TEMPERATURE_C
    for edge in (low, high):
        for seed in range(4):
            tables = default_tables(np.random.default_rng(seed), 1800.0,
                                    lambda t: np.full(np.shape(t), 9000.0),
                                    lambda t, e=edge: np.full(np.shape(t), e), edge)
            for table in (tables.ambient_C, tables.coolant_C):
                assert low <= table.values.min() and table.values.max() <= high


def test_xy_drift_is_the_lagged_linear_response_to_the_temperature_rises():
    # a step of +10 K at T1 only: x(t) = 0.22 µm/K · 10 K · (1 − e^(−t/τ)) with τ = 120 s
    # (the first-order lag of a step held from the first sample), y untouched by T1
    time_s = np.arange(0.0, 1200.0 + 1e-9, 2.0)
    sensors = np.full((time_s.size, 5), 25.0)
    sensors[1:, 0] += 10.0
    xy = xy_drift_um(time_s, sensors, (1.1, 0.9))
    exact_x = 1.1 * XY_GAIN_UM_PER_K[0, 0] * 10.0 * (1.0 - np.exp(-(time_s - 2.0) / XY_LAG_S))
    # the lag sees the step as a ramp over the first 2 s: compare after it
    assert np.abs(xy[0, 5:] - exact_x[5:]).max() < 0.02 * xy[0, -1]
    assert xy[0, -1] == pytest.approx(1.1 * 0.22 * 10.0, rel=1e-3)
    assert np.allclose(xy[1], 0.0)


def test_a_profile_with_a_spreadsheets_trailing_separators_reads(tmp_path):
    path = tmp_path / "p.csv"
    path.write_text("time_s,speed_rpm,,\n0,6000,,\n600,9000,\n")
    profile = read_speed_profile(path)
    assert list(profile.speed_rpm.values) == [6000.0, 9000.0] and profile.ignored == ()


def test_a_toml_file_that_cannot_be_read_names_its_option(tmp_path):
    # --scenario named its option ("s.toml, option '--scenario': cannot read file ..."),
    # --spec of twin mesh and twin simulate did not
    from typer.testing import CliRunner

    from twin.cli import app

    missing = tmp_path / "missing.toml"
    runs = {
        "--scenario": ["synth", "--speed", "6000", "--minutes", "2", "--ambient", "22",
                       "--seed", "1", "--scenario", str(missing), "--out",
                       str(tmp_path / "run.csv")],
        "--spec": ["mesh", "--spec", str(missing), "--out", str(tmp_path / "m.msh")],
    }
    for option, args in runs.items():
        result = CliRunner().invoke(app, args)
        assert result.exit_code == 2
        assert result.output == (f"error: {missing}, option {option!r}: cannot read file: "
                                 "No such file or directory\n")


def test_an_ambient_or_coolant_a_table_overrides_is_told(tmp_path):
    # `--ambient 30` with an [ambient] table from 24 °C emulated a run at 24 °C, and a
    # profile's ambient_C column and a [coolant] table did the same to --ambient and
    # --coolant: the required option was dropped without a word
    from typer.testing import CliRunner

    from twin.cli import app

    scenario, profile = tmp_path / "s.toml", tmp_path / "p.csv"
    scenario.write_text("[ambient]\ntime_s = [0, 120]\nambient_C = [24, 25]\n"
                        "[coolant]\ntime_s = [0]\ninlet_C = [22]\n")
    profile.write_text("time_s,speed_rpm,ambient_C\n0,6000,20\n")
    runner = CliRunner()

    def synth(*args: str) -> tuple[str, str]:
        out = tmp_path / "run.csv"
        result = runner.invoke(app, ["synth", "--minutes", "2", "--seed", "1", "--quiet",
                                     "--out", str(out), *args])
        assert result.exit_code == 0, result.output
        metadata = dict(line[2:].split(": ", 1) for line in out.read_text().splitlines()
                        if line.startswith("# "))
        return result.output, metadata["ambient_C"]

    told, emulated = synth("--speed", "6000", "--scenario", str(scenario),
                           "--ambient", "30", "--coolant", "26")
    assert emulated == "24"  # the table wins, as DESIGN.md says: and the user hears of it
    assert told == (f"warning: --ambient 30 is not used: {scenario}'s [ambient] sets it "
                    "(24 °C at 0 s)\n"
                    f"warning: --coolant 26 is not used: {scenario}'s [coolant] sets it "
                    "(22 °C at 0 s)\n")
    told, emulated = synth("--profile", str(profile), "--ambient", "35")
    assert emulated == "20"
    assert told == (f"warning: --ambient 35 is not used: {profile}'s ambient_C column sets "
                    "it (20 °C at 0 s)\n")
    # the same value as the table (a suite's reproducing command) is nothing to tell
    assert synth("--speed", "6000", "--scenario", str(scenario), "--ambient", "24",
                 "--coolant", "22") == ("", "24")
    assert synth("--profile", str(profile), "--ambient", "20") == ("", "20")


@pytest.mark.parametrize("ambient, table, line, key", [
    ("44.8", "[sensors.offset_C]\nT2 = 0.1\nambient = 0.5\n", 3, "sensors.offset_C.ambient"),
    ("-39.5", "[sensors]\noffset_C = {coolant_C = -3.0}\n", 2, "sensors.offset_C.coolant_C"),
])
def test_an_offset_that_takes_the_air_or_inlet_out_of_range_is_refused_naming_it(
        tmp_path, ambient, table, line, key):
    """The air and inlet readings' noise is kept inside the range replay reads, but an
    offset taking the reading itself out was clipped away as the noise is: +0.5 K at
    44.8 °C read a flat 45 °C while the truth file told 0.5 K.  Now the offset's key is
    named; within the range the offset is read whole."""
    from typer.testing import CliRunner

    from twin.cli import app
    from twin.runs import read_table

    path = tmp_path / "s.toml"
    path.write_text(table)
    out = tmp_path / "run.csv"
    args = ["synth", "--speed", "9000", "--minutes", "3", "--seed", "1", "--scenario",
            str(path), "--out", str(out), "--quiet"]
    refused = CliRunner().invoke(app, [*args, "--ambient", ambient])
    assert refused.exit_code == 2, refused.output
    assert refused.output.startswith(f"error: {path}, line {line}, key '{key}': with this "
                                     "calibration offset"), refused.output
    assert "Traceback" not in refused.output and not out.exists()
    done = CliRunner().invoke(app, [*args, "--ambient", "30"])
    assert done.exit_code == 0, done.output
    column = key.rsplit(".", 1)[1].removesuffix("_C") + "_C"
    offset = float(table.split("= ")[-1].rstrip("}\n"))
    reading, truth = read_table(out).columns, read_table(tmp_path / "run.truth.csv").columns
    np.testing.assert_allclose(reading[column] - truth[column], offset, atol=0.2)


def test_a_fault_on_a_channel_with_an_offset_is_not_blamed_on_the_offset(tmp_path):
    """An ambient logged as NaN throughout is refused for that, offset or not."""
    from typer.testing import CliRunner

    from twin.cli import app

    path = tmp_path / "s.toml"
    path.write_text('[sensors.offset_C]\nambient = 0.1\n'
                    '[faults]\ndropouts = [{sensor = "ambient", start_s = 0, end_s = 200}]\n')
    refused = CliRunner().invoke(app, ["synth", "--speed", "9000", "--minutes", "3", "--seed",
                                       "1", "--ambient", "22", "--scenario", str(path),
                                       "--out", str(tmp_path / "run.csv"), "--quiet"])
    assert refused.exit_code == 2, refused.output
    assert refused.output.startswith(f"error: {path}, column 'ambient_C': the emulated run "
                                     "would be refused by replay"), refused.output
