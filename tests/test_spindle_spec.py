"""Spec validation: every bad input is an InputError naming the file and the field."""

import copy
import tomllib

import pytest
from typer.testing import CliRunner

from twin.errors import InputError
from twin.spindle.spec import DEFAULT_SPEC_PATH, load_spec, parse_spec


@pytest.fixture(scope="module")
def raw():
    with open(DEFAULT_SPEC_PATH, "rb") as fh:
        return tomllib.load(fh)


def bad(raw, edit, field, tmp_path=None):
    data = copy.deepcopy(raw)
    edit(data)
    with pytest.raises(InputError) as exc:
        parse_spec(data, "my_spec.toml")
    assert "my_spec.toml" in str(exc.value)
    assert field in str(exc.value), str(exc.value)
    return str(exc.value)


def test_bundled_spec_loads_with_derived_quantities():
    spec = load_spec()
    assert spec.interfaces() == ("contact_front", "contact_rear")
    # 7014: pitch diameter (39.5 + 50.5) = 90 mm; volume π/4 (0.110² − 0.070²) 0.020 m³
    assert spec.pitch_diameter_mm("front") == pytest.approx(90.0)
    assert spec.bearing_volume_m3("front") == pytest.approx(3.14159265 / 4 * 0.0072 * 0.02)
    assert spec.spindle.max_speed_rpm == 15000.0


def test_negative_size(raw):
    def edit(d):
        d["parts"][3]["r_inner_mm"] = -1.0
    bad(raw, edit, "parts[3].r_inner_mm")


def test_inverted_rectangle(raw):
    def edit(d):
        d["parts"][0]["z_end_mm"] = -5.0
    bad(raw, edit, "parts[0]")


def test_overlapping_parts(raw):
    def edit(d):
        d["parts"][11]["r_inner_mm"] = 30.0  # rotor into the shaft
    msg = bad(raw, edit, "parts[11]")
    assert "overlaps" in msg


def test_sensor_outside_the_body(raw):
    def edit(d):
        d["sensors"]["T2"]["r_mm"] = 500.0
    msg = bad(raw, edit, "sensors.T2")
    assert "outside" in msg


def test_sensor_inside_a_coolant_channel_is_outside(raw):
    def edit(d):
        ch = d["coolant_channels"][0]
        d["sensors"]["T5"] = {"r_mm": 0.5 * (ch["r_inner_mm"] + ch["r_outer_mm"]),
                              "z_mm": 0.5 * (ch["z_start_mm"] + ch["z_end_mm"])}
    bad(raw, edit, "sensors.T5")


def test_missing_field(raw):
    def edit(d):
        del d["bearings"]["front"]["preload_N"]
    msg = bad(raw, edit, "bearings.front.preload_N")
    assert "missing" in msg.lower()


def test_missing_sensor_and_convection(raw):
    bad(raw, lambda d: d["sensors"].pop("T4"), "sensors.T4")
    bad(raw, lambda d: d["convection"].pop("coolant"), "convection.coolant")


def test_unknown_names(raw):
    def edit(d):
        d["parts"][0]["region"] = "shaftt"
    bad(raw, edit, "parts[0].region")
    bad(raw, lambda d: d["regions"].__setitem__("rotor", "unobtainium"), "regions.rotor")


def test_unknown_field_is_rejected(raw):
    bad(raw, lambda d: d["motor"].__setitem__("rated_power_kW", 15), "motor.rated_power_kW")


def test_convection_model_needs_its_parameters(raw):
    bad(raw, lambda d: d["convection"]["nose_outer"].pop("diameter_mm"), "convection.nose_outer")


def test_file_errors_name_the_file(tmp_path):
    missing = tmp_path / "nope.toml"
    with pytest.raises(InputError, match="nope.toml"):
        load_spec(missing)
    broken = tmp_path / "broken.toml"
    broken.write_text("[spindle\nname = 1\n")
    with pytest.raises(InputError, match="broken.toml.*TOML"):
        load_spec(broken)


def test_bad_spec_via_cli_exits_2(tmp_path, raw):
    text = DEFAULT_SPEC_PATH.read_text().replace("r_outer_mm = 55.0", "r_outer_mm = -55.0", 1)
    path = tmp_path / "neg.toml"
    path.write_text(text)
    from twin.cli import app

    result = CliRunner().invoke(app, ["mesh", "--spec", str(path), "--out",
                                      str(tmp_path / "m.msh")])
    assert result.exit_code == 2
    assert "neg.toml" in result.output and "r_outer_mm" in result.output
    assert "Traceback" not in result.output
    assert not (tmp_path / "m.msh").exists()


@pytest.mark.parametrize("old, new, field", [
    ("max_speed_rpm = 15000.0", "max_speed_rpm = -5", "spindle.max_speed_rpm"),
    ('region = "shaft"', 'region = "shaftt"', "parts[0].region"),  # the first [[parts]]
    ("r_outer_mm = 55.0", "r_outer_mm = -55.0", "r_outer_mm"),
])
def test_spec_errors_name_the_line(tmp_path, old, new, field):
    # a scenario's errors named their line, a spec's (twin simulate/mesh --spec) only the
    # field: with 30 [[parts]] a user had to count tables to find parts[17]
    text = DEFAULT_SPEC_PATH.read_text()
    path = tmp_path / "spec.toml"
    path.write_text(text.replace(old, new, 1))
    line = text[:text.index(old)].count("\n") + 1
    with pytest.raises(InputError) as info:
        load_spec(path)
    assert info.value.row == line and field in str(info.value)


@pytest.mark.parametrize("new, says", [
    ("conductivity_W_per_mK = inf", "finite"),  # passed `gt=0`: a field of inf and nan
    ("conductivity_W_per_mK = nan", "finite"),
    ('conductivity_W_per_mK = "49.8"', "number"),  # a quoted number, read as 49.8
    ("conductivity_W_per_mK = true", "number"),  # read as 1.0 W/mK
])
def test_a_spec_value_must_be_a_finite_number_as_written(tmp_path, new, says):
    # a spec's values were parsed leniently (a scenario's strictly): a slip in the TOML
    # became a number the user never wrote
    text = DEFAULT_SPEC_PATH.read_text()
    old = "conductivity_W_per_mK = 49.8"
    path = tmp_path / "spec.toml"
    path.write_text(text.replace(old, new, 1))
    with pytest.raises(InputError) as info:
        load_spec(path)
    assert info.value.row == text[:text.index(old)].count("\n") + 1
    assert "conductivity_W_per_mK" in str(info.value) and says in str(info.value)


@pytest.mark.parametrize("old, new, message", [
    # a size typed in cm (0.7) or m (0.007): the mesher ran on without bound
    ("element_size_mm = 7.0", "element_size_mm = 0.3",
     "line 14, key 'mesh.element_size_mm': Input should be greater than or equal to 1.4"),
    ("min_elements_across = 2", "min_elements_across = 50",
     "line 15, key 'mesh.min_elements_across': Input should be less than or equal to 10"),
])
def test_a_mesh_too_fine_to_build_is_refused_before_meshing(tmp_path, old, new, message):
    from twin.cli import app

    text = DEFAULT_SPEC_PATH.read_text()
    assert text[:text.index(old)].count("\n") + 1 == int(message.split()[1].rstrip(","))
    path = tmp_path / "fine.toml"
    path.write_text(text.replace(old, new, 1))
    for command in (["mesh"], ["simulate", "--speed", "9000", "--minutes", "1",
                               "--ambient", "22"]):
        out = tmp_path / ("m.msh" if command == ["mesh"] else "sim")
        result = CliRunner().invoke(app, [*command, "--spec", str(path), "--out", str(out)])
        assert result.exit_code == 2
        assert result.output == f"error: {path}, {message}\n"
        assert not out.exists()


def test_the_size_factor_keeps_the_finest_element_on_any_spec(tmp_path):
    # --size-factor is floored at 0.2 for the reference spindle's 7 mm; a spec of 1.4 mm at
    # 0.5 made 0.7 mm elements, four times the floor's count
    from twin.cli import app

    text = DEFAULT_SPEC_PATH.read_text()
    path = tmp_path / "fine.toml"
    path.write_text(text.replace("element_size_mm = 7.0", "element_size_mm = 1.4", 1))
    out = tmp_path / "m.msh"
    result = CliRunner().invoke(app, ["mesh", "--spec", str(path), "--size-factor", "0.5",
                                      "--out", str(out)])
    assert result.exit_code == 2 and not out.exists()
    assert result.output == ("error: option '--size-factor': 0.5 times the spec's "
                             "element_size_mm 1.4 makes 0.7 mm elements; the finest allowed "
                             "is 1.4 mm; see 'twin mesh --help'\n")
    result = CliRunner().invoke(app, ["mesh", "--spec", str(path), "--size-factor", "2",
                                      "--out", str(out), "--quiet"])
    assert result.exit_code == 0 and out.exists()
