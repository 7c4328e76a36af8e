"""Issue 14 regressions on decks (defects 5 and 6): caps hold on every path, bad numbers
are refused naming file, line and command."""

from __future__ import annotations

import pytest

from apdl_like.errors import ApdlError
from apdl_like.session import Session
from tests.test_apdl_language import VALID_DECK


@pytest.mark.timeout(60)
@pytest.mark.parametrize(("deck", "line", "message"), [
    ("/PREP7\nNBLOCK,6,SOLID\n(999999999i9,6e21.13)\n1 0 0 0\n-1\n", 2, "1..64"),
    ("/PREP7\nEBLOCK,19,SOLID\n(19i0)\n1 1 1 1 0 0 0 0 4 0 1 1 2 3 4\n-1\n", 2, "1..64"),
    ("/PREP7\nNBLOCK,6,SOLID\n(3i9,6e21.13e3)\n"
     f"{1:9d}{0:9d}{0:9d}{'nan':>21}{0.0:21.13E}{0.0:21.13E}\nN,R5.3,LOC,       -1,\n", 2,
     "non-finite coordinate"),
    ("/PREP7\nN,1,0.01,NAN\n", 2, "NAN"),
    ("/PREP7\nET,1,PLANE55,,,1\nMP,KXX,1,50\nRECTNG,0,1e300,0,1e300\nAMESH,ALL\n/SOLU\n"
     "NSEL,S,LOC,X,0\nD,ALL,TEMP,20\nALLSEL\nSOLVE\n", 10, "out of range"),
    ("/PREP7\nN,1,0.01,0\nN,2,0.02,0\nCMBLOCK,C,NODE,2\n(8i10)\n         1       500\n", 4,
     "node 500 does not exist"),
    ("/PREP7\nN,1,0.01,0\nCMBLOCK,C,NODE,1\n(8i30)\n" + "9" * 30 + "\n", 3, "out of range"),
])
def test_bad_block_and_number_refused(tmp_path, deck, line, message):
    with pytest.raises(ApdlError, match=message) as info:
        Session(base_dir=tmp_path).run_text(deck, "deck.inp")
    assert info.value.file == "deck.inp" and info.value.line == line


@pytest.mark.timeout(60)
def test_deltim_cannot_bypass_the_substep_cap(tmp_path):
    deck = VALID_DECK.replace("SOLVE\n", "ANTYPE,TRANS\nTIME,100\nDELTIM,1e-9\nSOLVE\n")
    with pytest.raises(ApdlError) as info:
        Session(base_dir=tmp_path).run_text(deck, "deck.inp")
    assert info.value.line == VALID_DECK.count("\n") - 1 + 3


@pytest.mark.timeout(60)
def test_amesh_inside_do_cannot_bypass_the_element_cap(tmp_path):
    deck = ("/PREP7\nET,1,PLANE55,,,1\nESIZE,0.0001\n*DO,I,1,1000\n"
            "RECTNG,0,0.1,0,0.1\nAMESH,ALL\n*ENDDO\n")
    with pytest.raises(ApdlError) as info:
        Session(base_dir=tmp_path).run_text(deck, "deck.inp")
    assert info.value.file == "deck.inp"


@pytest.mark.slow
@pytest.mark.timeout(120)
def test_amesh_in_a_loop_stops_at_the_model_element_cap(tmp_path):
    deck = ("/PREP7\nET,1,PLANE55,,,1\nESIZE,0.0005\n*DO,I,1,1000\n"
            "RECTNG,I,I+0.1,0,0.1\nAMESH,ALL\n*ENDDO\n")
    with pytest.raises(ApdlError, match="more than 500000 elements") as info:
        Session(base_dir=tmp_path).run_text(deck, "deck.inp")
    assert info.value.line == 6


@pytest.mark.parametrize("written", ["/OUT,sub,inp\n*VWRITE,X\n(F8.2)\n/OUT\n",
                                     "*CFOPEN,sub,inp\n*CFWRITE,X = 2\n*CFCLOS\n"])
def test_a_deck_does_not_write_over_a_file_it_read_by_input(tmp_path, written):
    # with --out the deck's folder, /OUT,sub,inp replaced the sub.inp the deck had just read
    from typer.testing import CliRunner

    from apdl_like.cli import app

    sub = tmp_path / "sub.inp"
    sub.write_text("X = 1\n")
    deck = tmp_path / "main.inp"
    deck.write_text("/INPUT,sub,inp\n" + written)
    result = CliRunner().invoke(app, ["run", str(deck), "--out", str(tmp_path)])
    assert result.exit_code == 2, result.output
    assert f"{sub}, option '--out': is also an input" in result.output
    assert sub.read_text() == "X = 1\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["main.inp", "sub.inp"]


@pytest.mark.parametrize("moved", ["N,1,0.05,0.2", "N,3,0.1,0.2"])
def test_a_quad_bent_by_a_moved_node_is_refused_at_solve(tmp_path, moved):
    # a node redefined after AMESH made a quad re-entrant or crossed: its area passed the
    # check, and scikit-fem's inverse mapping raised 'Zero Jacobian determinant' or
    # 'Newton iteration didn't converge' (an internal error, exit 1)
    deck = ("/PREP7\nET,1,PLANE55,,,1\nMP,KXX,1,10\nRECTNG,0.1,0.2,0,0.1\nESIZE,0.05\n"
            f"AMESH,ALL\n{moved}\nSF,ALL,CONV,100,20\n/SOLU\nSOLVE\n")
    with pytest.raises(ApdlError, match="not convex") as info:
        Session(base_dir=tmp_path).run_text(deck, "deck.inp")
    assert info.value.line == 10


def test_quiet_keeps_the_unknown_command_warnings(tmp_path):
    # --quiet silenced the warnings too: a deck whose command was skipped ran in CI as if
    # it had run in full
    from typer.testing import CliRunner

    from apdl_like.cli import app

    deck = tmp_path / "deck.inp"
    deck.write_text("A = 1\nFROBNICATE,1\n")
    result = CliRunner().invoke(app, ["run", str(deck), "--out", str(tmp_path / "out"),
                                      "--quiet"])
    assert result.exit_code == 0, result.output
    assert result.stdout == ""
    assert result.stderr == (f"warning: {deck}:2: FROBNICATE: unknown or unsupported command "
                             "FROBNICATE; ignored\n")


def test_start_state_too_large_to_read_is_refused_before_any_work(tmp_path):
    # --start was checked to be a file but read whole by meshio whatever its size
    from typer.testing import CliRunner

    from apdl_like.cli import app
    from twin.paths import MAX_INPUT_BYTES

    deck = tmp_path / "w.inp"
    deck.write_text("/SOLU\n", encoding="utf-8")
    start = tmp_path / "huge.vtu"
    with start.open("wb") as f:  # sparse: no disk used
        f.truncate(MAX_INPUT_BYTES + 1)
    result = CliRunner().invoke(app, ["run", str(deck), "--spindle", "--out",
                                      str(tmp_path / "out"), "--start", str(start)])
    assert result.exit_code == 2, result.output
    assert "huge.vtu, option '--start'" in result.output and "larger than" in result.output
    assert not (tmp_path / "out").exists()
