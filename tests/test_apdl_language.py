"""apdl_like language layer: lexing, expressions, control flow, /INPUT, limits, errors."""

from __future__ import annotations

import math
import re
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from apdl_like.errors import ApdlError
from apdl_like.expressions import evaluate
from apdl_like.interpreter import MAX_LOOP_ITERATIONS
from apdl_like.parser import lex_line, parse_deck
from apdl_like.session import Session
from twin.errors import InputError


def run(text: str, **kw) -> Session:
    s = Session(**kw)
    s.run_text(text, "deck.inp")
    return s


# ------------------------------------------------------------------ lexing
def test_fields_comments_and_case():
    st_ = lex_line("nsel , s,LOC, x ,, 0.1  ! the outer face", "f", 3)
    assert st_.name == "NSEL"
    assert st_.fields == ("s", "LOC", "x", "", "0.1")
    assert lex_line("   ! only a comment", "f", 1) is None
    assert lex_line("Ri = 0.02 ! m", "f", 1).fields == ("RI", "", "0.02")
    com = lex_line("/COM, keep ! this, text", "f", 1)
    assert com.name == "/COM" and com.fields == (" keep ! this, text",)


@pytest.mark.parametrize("deck, name, value", [
    ("N,1,0,0\nN,2,1,0\n*GET,C,NODE,0,COUNT\n", "C", 2.0),
    ("N,1,0,0\nN,2,1,0\nCM,EDGE,NODE\n*GET,C,NODE,0,COUNT\n", "C", 2.0),
    ("N,1,0,0\nN,2,1,0\nNGEN,2,10,ALL,,,0,1\n*GET,C,NODE,0,COUNT\n", "C", 4.0),
    ("N,1,0,0\nN,2,1,0\nN,3,1,1\nN,4,0,1\nET,1,PLANE55\nE,1,2,3,4\nCM,ONE,ELEM\n"
     "*GET,C,ELEM,0,COUNT\n", "C", 1.0),
])
def test_selection_right_after_new_entities(deck, name, value):
    # ids[selected] read the ids before `selected` merged the nodes just added: a CM,
    # NGEN or *GET,,NODE,0,COUNT right after N ended in 'internal error: IndexError'
    assert run("/PREP7\n" + deck).params[name] == value


def test_ic_right_after_new_nodes_is_kept():
    # IC indexed the node arrays it had read before its targets merged the nodes just
    # added: the value went into the discarded arrays (lost without a word) or past
    # their end ('internal error: IndexError' for N,,1,1 then IC,ALL)
    s = run("/PREP7\nN,1,0,0\nN,2,1,0\n*GET,C,NODE,0,COUNT\nN,3,1,1\nIC,1,TEMP,100\n")
    np.testing.assert_array_equal(s.db.nodes.arrays["ic_temp"], [100.0, np.nan, np.nan])
    s = run("/PREP7\nN,,1,1\nIC,ALL,TEMP,100\n")
    np.testing.assert_array_equal(s.db.nodes.arrays["ic_temp"], [100.0])


def test_dollar_separates_commands_on_one_line():
    # MAPDL runs `A $ B` as two commands (NSEL,S,LOC,X,0 $ D,ALL,TEMP,20 in many a macro);
    # the line stopped with "unexpected character '$'" or "element PLANE55 $ MP"
    s = run("A = 1 $ B = A+1 ! B $ C = 9 is a comment\n"
            "/PREP7\nET,1,PLANE55 $ MP,KXX,1,50\nN,1,0,0 $ N,2,1,0 $ N,3,1,1\n"
            "*SET,T,'a$b' $ *GET,NN,NODE,0,COUNT\n/COM, costs $5 $ D = 1\n")
    assert s.params["A"] == 1.0 and s.params["B"] == 2.0 and "C" not in s.params
    assert s.params["NN"] == 3.0 and s.params["T"] == "a$b"
    assert "D" not in s.params  # /COM takes the rest of its line as text
    program = parse_deck("X = 1 $ Y = 2\nZ = 3 $ FOO\n*VWRITE,X\n('a $ b',F5.1)\n", "d.inp")
    assert [(st.line, st.name) for st in program.statements] == [
        (1, "="), (1, "="), (2, "="), (2, "FOO"), (3, "*VWRITE")]
    assert program.statements[-1].block == ("('a $ b',F5.1)",)  # a format line is text
    with pytest.raises(ApdlError, match="data lines come next") as info:
        run("X = 1\n*VWRITE,X $ Y = 2\n(F5.1)\n")
    assert info.value.line == 2


@pytest.mark.parametrize("text, value", [
    ("1+2*3", 7.0), ("-2**2", -4.0), ("2**3**2", 512.0), ("(1+2)*3/4", 2.25),
    ("1.5D3", 1500.0), (".5e-1", 0.05), ("2*-3", -6.0), ("SQRT(16)+ABS(-1)", 5.0),
    ("max(1,7,3)-min(4,2)", 5.0), ("exp(log(3))", 3.0), ("atan(1)*4", math.pi),
    ("sin(0)+cos(0)+tan(0)", 1.0), ("a*B", 6.0),
])
def test_expressions_against_hand_values(text, value):
    assert evaluate(text, {"A": 2.0, "B": 3.0}) == pytest.approx(value, rel=1e-15)


@pytest.mark.parametrize("text, message", [
    ("1/0", "division by zero"), ("sqrt(-1)", "undefined"), ("(-8)**(1/3)", "not a real"),
    ("10**400", "overflows"), ("x+1", "undefined parameter X"), ("foo(1)", "unknown function"),
    ("1+", "unexpected end"), ("1 2", "unexpected"), ("max()", "unexpected"),
    ("sqrt(1,2)", "takes 1 argument"), ("1e308*10", "not a finite"), ("a$b", "character"),
    ("(" * 40 + "1" + ")" * 40, "nesting deeper"),
])
def test_expression_errors(text, message):
    with pytest.raises(ApdlError, match=message):
        evaluate(text, {"A": 1.0})


def test_parameters_do_and_if():
    s = run("""
        TOTAL = 0
        *DO,I,1,10
          *IF,I,EQ,5,CYCLE
          *IF,I,GT,8,EXIT
          TOTAL = TOTAL + I
        *ENDDO
        *SET,K,2.5
        *IF,K,LT,1,THEN
          BRANCH = 1
        *ELSEIF,K,LT,3
          BRANCH = 2
        *ELSE
          BRANCH = 3
        *ENDIF
        *IF,K,GT,0,AND,K,LT,2,THEN
          BOTH = 1
        *ELSE
          BOTH = 0
        *ENDIF
        *DO,J,3,1,-1
          LAST = J
        *ENDDO
    """)
    # 1+2+3+4+6+7+8 (5 cycled, 9 and 10 exited)
    assert s.params["TOTAL"] == 31.0
    assert s.params["BRANCH"] == 2.0 and s.params["BOTH"] == 0.0 and s.params["LAST"] == 1.0


def test_a_failed_assignment_is_named_as_written():
    # the statement was shown as its target only, 'B=: undefined parameter A', which
    # reads as if the deck had written `B=`
    with pytest.raises(ApdlError) as info:
        run("X = 1\nB=A*2   ! twice A\n")
    assert str(info.value) == "deck.inp:2: B=A*2: undefined parameter A"
    with pytest.raises(ApdlError) as info:
        run("C = 1 $ V(2) = C, Q\n")
    assert str(info.value) == "deck.inp:1: V(2) = C, Q: undefined parameter Q"


def test_nested_loops():
    s = run("N = 0\n*DO,I,1,4\n*DO,J,1,I\nN = N + 1\n*ENDDO\n*ENDDO\n")
    assert s.params["N"] == 10.0


@pytest.mark.parametrize("deck, line, message", [
    ("A = 1\nB = C + 1\n", 2, "undefined parameter C"),
    ("*DO,I,1,3\nA = I\n", 1, "never closed"),
    ("A = 1\n*ENDIF\n", 2, "does not close"),
    ("*ELSE\n", 1, "without an open"),
    ("*DO,I,1,3,0\n*ENDDO\n", 1, "must not be zero"),
    (f"*DO,I,1,{MAX_LOOP_ITERATIONS + 1}\n*ENDDO\n", 1, "exceeds the limit"),
    ("/PREP7\nN,1,0,0\nN,2,1,0\nET,1,PLANE55\nE,1,2,7\n", 5, "node 7 does not exist"),
    ("/PREP7\nN,1,0,0,0.5\n", 2, "Z"),
    ("N,1,0,0\n", 1, "not valid in the begin level"),
    ("/PREP7\nMP,KXX,1,-5\n", 2, "KXX must be positive"),
    ("/PREP7\nET,1,SOLID999\n", 2, "not supported"),
    ("/SOLU\nANTYPE,STATIC\nTIME,1\n", 3, "never solved"),
    ("/SOLU\nANTYPE,TRANS,REST\n", 2, r"^deck.inp:2: ANTYPE: REST \(restart\): no "
     r"previous solution in this run to continue from; restarting from another run's "
     r"files \(.rdb, .Rnnn\) is not supported: /INPUT the deck that solves it first"),
    ("/PREP7\nANTYPE,,RESTART\n", 2, r"RESTART \(restart\): no previous solution"),
    ("/SOLU\nANTYPE,4,REST,1\n", 2, "chosen load step or substep .fields 3-4"),
    ("/INPUT,../secret,inp\n", 1, "outside the deck's folder"),
    ("*IF,1,EQ,1,:LABEL\n", 1, "GO labels are not supported"),
    ("A = 'text'\nB = A + 1\n", 2, "A is a character parameter"),
    ("A = 1\nB = A(2)\n", 2, "A is not an array"),
    ("*DIM,V,,2\nV(3) = 1\n", 2, "subscript 1 of V is 3, outside 1..2"),
    ("A = 1\nB = (\nC = 2\n", 2, "unexpected end"),
])
def test_bad_decks_name_file_line_and_command(deck, line, message, tmp_path):
    s = Session(base_dir=tmp_path)
    with pytest.raises(ApdlError, match=message) as info:
        s.run_text(deck, "deck.inp")
    assert info.value.file == "deck.inp"
    assert info.value.line == line
    assert str(info.value).startswith(f"deck.inp:{line}: ")


def test_unknown_commands_warn_and_the_run_goes_on_strict_stops(tmp_path):
    s = Session()
    s.run_text("A = 1\nFROBNICATE,1\nB = A + 1\n", "deck.inp")
    assert s.params["B"] == 2.0
    assert s.state.listing.warnings == [
        "warning: deck.inp:2: FROBNICATE: unknown or unsupported command FROBNICATE; ignored"]
    strict = Session(strict=True)
    with pytest.raises(ApdlError, match="deck.inp:2: FROBNICATE: unknown"):
        strict.run_text("A = 1\nFROBNICATE,1\nB = A + 1\n", "deck.inp")
    assert strict.params == {"A": 1.0}  # what came before the bad line has run


def test_abbreviations_and_processor_rules():
    s = Session()
    s.run_text("/PREP7\nANTY,TRANS\nKBC,1\nDELTIM,1\nFINI\n/SOLUTION\n"
               "NSUB,4\nALLS\nFINISH\n", "deck.inp")
    settings = s.db.settings
    assert settings.antype == "TRANS" and settings.kbc == 1
    assert settings.nsubst == 4 and s.state.listing.warnings == []


def test_slash_and_star_commands_abbreviate_to_four_characters_with_their_prefix():
    # MAPDL reads the first four characters, the slash or star included: `/SOL` is /SOLU
    # (common in users' decks) and `/PRE` /PREP7; `/POS` fits /POST1 and /POST26 and so
    # stands for neither, and three characters stand for nothing
    s = Session()
    s.run_text("/PRE\nET,1,PLANE55\nFINI\n/SOL\nANTYPE,TRANS\nNSUB,4\nFINI\n/POS\n/SO\n",
               "deck.inp")
    assert s.db.settings.antype == "TRANS" and s.db.settings.nsubst == 4
    assert [w.split(": ")[2] for w in s.state.listing.warnings] == ["/POS", "/SO"]


def test_runaway_loops_stop(tmp_path):
    # nested loops: each small, the product over the limit
    deck = "*DO,I,1,1000\n*DO,J,1,1000\n*ENDDO\n*ENDDO\n"
    with pytest.raises(ApdlError, match="loop iterations"):
        run(deck)


def test_input_stays_in_the_deck_folder(tmp_path):
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "part.mac").write_text("FROM_PART = A * 2\n/INPUT,sub/leaf,inp\n")
    (tmp_path / "sub" / "leaf.inp").write_text("LEAF = 1\nB = UNDEFINED_NAME\n")
    (tmp_path / "main.inp").write_text("A = 21\n/INPUT,sub/part,mac\n")
    s = Session()
    with pytest.raises(ApdlError, match="undefined parameter UNDEFINED_NAME") as info:
        s.run_file(tmp_path / "main.inp")
    assert info.value.file.endswith("leaf.inp") and info.value.line == 2
    assert s.params["FROM_PART"] == 42.0 and s.params["LEAF"] == 1.0
    outside = tmp_path.parent / f"{tmp_path.name}_outside.inp"
    outside.write_text("X = 1\n")
    (tmp_path / "escape.inp").write_text(f"/INPUT,../{outside.name}\n")
    with pytest.raises(ApdlError, match="outside the deck's folder"):
        Session().run_file(tmp_path / "escape.inp")
    (tmp_path / "self.inp").write_text("/INPUT,self,inp\n")
    with pytest.raises(ApdlError, match="nested deeper"):
        Session().run_file(tmp_path / "self.inp")
    (tmp_path / "loop_a.inp").symlink_to(tmp_path / "loop_b.inp")
    (tmp_path / "loop_b.inp").symlink_to(tmp_path / "loop_a.inp")
    (tmp_path / "loops.inp").write_text("/INPUT,loop_a,inp\n")
    with pytest.raises(ApdlError, match="not found") as info:  # was a RuntimeError
        Session().run_file(tmp_path / "loops.inp")
    assert info.value.line == 1


def test_macros_run_beside_the_deck_with_local_arguments(tmp_path):
    # MAPDL's *USE and its macro search: `name.mac` beside the deck runs as a command;
    # ARG1..AR19 are the macro's own (0 when not given), the caller's come back after it
    (tmp_path / "hyp.mac").write_text(
        "HYP = SQRT(ARG1**2 + ARG2**2)\nSEEN3 = ARG3\nINNER = 0\n"
        "*IF,ARG3,NE,0,THEN\n  TWICE,ARG1 + 1\n  AFTER_INNER = ARG1\n*ENDIF\n")
    (tmp_path / "twice.mac").write_text("INNER = 2*ARG1\nARG1 = -1\n")
    (tmp_path / "early.mac").write_text(
        "*IF,ARG1,EQ,0,THEN\n  WHY = 'no ARG1'\n  /EOF\n*ENDIF\nEARLY = ARG1\n")
    (tmp_path / "label.mac").write_text("*VWRITE,ARG1\n('label ',A8)\nN19 = AR19\n")
    (tmp_path / "main.inp").write_text(
        "ARG1 = 100\n*USE,hyp,3,4\nA_HYP = HYP\nA_SEEN3 = SEEN3\n"
        "hyp,5,12,1\nearly\nearly,7\n"
        "label,'plate',,,,,,,,,,,,,,,,,,9\nN19_BY_NAME = N19\n*USE,label.mac,'x'\n")
    s = Session()
    s.run_file(tmp_path / "main.inp")
    p = s.params
    assert (p["A_HYP"], p["A_SEEN3"]) == (5.0, 0.0)  # 3-4-5; ARG3 not given: 0
    assert p["HYP"] == 13.0 and p["SEEN3"] == 1.0  # 5-12-13 by the macro's name
    assert p["INNER"] == 12.0  # twice.mac got ARG1 = 5 + 1
    assert p["AFTER_INNER"] == 5.0  # twice.mac's ARG1 = -1 stayed in twice.mac
    assert p["WHY"] == "no ARG1" and p["EARLY"] == 7.0  # /EOF left `early` the first time
    # AR19 = 9 by name; *USE (18 arguments at most) leaves it 0
    assert p["N19_BY_NAME"] == 9.0 and p["N19"] == 0.0
    # Fortran's A8 right-justifies a shorter text in its 8 columns
    assert [line for line in s.log if "label" in line] == ["label    plate", "label        x"]
    assert p["ARG1"] == 100.0 and "ARG2" not in p  # the deck's own ARG1 is back
    assert s.state.listing.warnings == []


def test_macro_calls_that_go_wrong_name_their_line(tmp_path):
    (tmp_path / "bad.mac").write_text("X = 1\nY = NOPE + 1\n")
    cases = {
        "*USE,missing\n": ("main.inp", 1, "macro file 'missing' not found"),
        "*USE,../outside\n": ("main.inp", 1, "outside the deck's folder"),
        "bad\n": ("bad.mac", 2, "undefined parameter NOPE"),
        "*USE,bad,UNDEF*2\n": ("main.inp", 1, "argument ARG1 (UNDEF*2): undefined"),
        "*USE,bad" + ",1" * 19 + "\n": ("main.inp", 1, "at most 18 arguments, got 19"),
    }
    for deck, (file, line, message) in cases.items():
        (tmp_path / "main.inp").write_text(deck)
        with pytest.raises(ApdlError, match=re.escape(message)) as info:
            Session().run_file(tmp_path / "main.inp")
        assert info.value.file.endswith(file) and info.value.line == line, deck
    # a name with no macro beside the deck stays an unknown command: a warning
    (tmp_path / "main.inp").write_text("NOSUCHMACRO,1\nZ = 1\n")
    s = Session()
    s.run_file(tmp_path / "main.inp")
    assert s.params["Z"] == 1.0 and "unknown or unsupported command NOSUCHMACRO" in \
        s.state.listing.warnings[0]


def test_msg_writes_its_format_with_mapdls_fortran_descriptors():
    # MAPDL documents %I, %G, %C as Fortran I9 (of NINT), 1PG16.9 and A8: 'Inner' is
    # right-justified in 8 columns (after the format's own blank), 1.2 is F editing with 9
    # significant digits and 4 blanks after, 148.5 rounds half away from zero to 149 (and
    # -2.5 to -3); a G value past 1e9 takes the 1P E form, one digit before the point.
    # With only these normal descriptors "consecutive blanks are condensed into one blank
    # upon output, and a period is appended" (MAPDL's *MSG notes): 'Radius (    Inner) =
    #        25, Thick =   1.20000000    , Length =       149' is printed as below; a
    # format with an enhanced descriptor (%8.3F) is written as formatted
    s = run("R = 25\n*MSG,INFO,'Inner',R,1.2,148.5\n"
            "Radius ( %C) = %I, Thick = %G, Length = %I\n"
            "*MSG,NOTE,-2.5,1.23456789012e10,99.5\nhalf %I big %G &\n"
            " and %8.3F%% done%/next line\nAFTER = 1\n")
    assert s.log == [
        "Radius ( Inner) = 25, Thick = 1.20000000 , Length = 149.",
        " *** NOTE ***",
        "half        -3 big  1.234567890E+10  and   99.500% done",  # joined as written
        "next line",
    ]
    assert s.params["AFTER"] == 1.0 and s.state.listing.warnings == []


def test_msg_warn_and_error_go_on_fatal_stops_at_its_line():
    s = run("*MSG,WARN,3\n%I nodes left\n*MSG,ERROR\nbad input\n*MSG,ERROR\nagain\nZ = 5\n")
    assert s.params["Z"] == 5.0  # ERROR counts, the batch run goes on
    assert s.state.listing.errors == 2
    assert s.state.listing.warnings == ["warning: deck.inp:1: *MSG: 3 nodes left.",
                                        "error: deck.inp:3: *MSG: bad input.",
                                        "error: deck.inp:5: *MSG: again."]
    assert s.log[:2] == [" *** WARNING ***", " 3 nodes left."]
    with pytest.raises(ApdlError) as info:
        run("T = 412\n*MSG,FATAL,T\nT = %I exceeds the limit\nZ = 5\n")
    assert str(info.value) == "deck.inp:2: *MSG: FATAL: T = 412 exceeds the limit."
    for deck, message in [("*MSG,INFO,1,2\nonly %I\n", "1 data descriptor(s) (%I, %G, %C, "
                           "...) for 2 value(s)"),
                          ("*MSG,LOUD\ntext\n", "Lab) must be one of INFO"),
                          ("*MSG,INFO,1\n", "format line is missing")]:
        with pytest.raises(ApdlError, match=re.escape(message)):
            run(deck)


def test_msg_writes_to_the_current_output_as_mapdl_does():
    # MAPDL's message subroutine writes to the current output: after /OUT,report,txt the
    # message (heading and text) is in report.txt, not in the log; /OUT alone sends the next
    # one back to the log.  A *CFOPEN command file is no output: it gets no message.
    s = run("/OUT,report,txt\n*MSG,WARN,7\n%I hot spots\n*MSG,INFO,2.5\nk = %G\n"
            "*CFOPEN,cmds,mac\n*MSG,NOTE\nstill the report\n*CFCLOS\n/OUT\n"
            "*MSG,INFO\nback in the log\n")
    assert s.state.listing.files["report.txt"] == [
        " *** WARNING ***", " 7 hot spots.", "k = 2.50000000.",
        " *** NOTE ***", "still the report."]
    assert s.state.listing.files["cmds.mac"] == []
    assert s.log == ["back in the log."]
    # the warning is still told (stderr) with its place
    assert s.state.listing.warnings == ["warning: deck.inp:2: *MSG: 7 hot spots."]


def test_file_size_limit(tmp_path, monkeypatch):
    import apdl_like.parser as parser

    monkeypatch.setattr(parser, "MAX_DECK_BYTES", 100)
    big = tmp_path / "big.inp"
    big.write_text("A = 1\n" * 50)
    with pytest.raises(ApdlError, match="over the 0 MB limit|larger than"):
        Session().run_file(big)


def test_a_deck_file_is_refused_in_the_words_of_every_input(tmp_path, monkeypatch):
    # the deck reader checked its file itself: "deck is 0.0 MB, over the 0 MB limit" and
    # "cannot read deck: ..." where every other input says what twin.paths says
    import apdl_like.parser as parser
    from twin.paths import read_input_bytes

    monkeypatch.setattr(parser, "MAX_DECK_BYTES", 100)
    big = tmp_path / "big.inp"
    big.write_text("A = 1\n" * 50)
    for path in (big, tmp_path / "missing.inp"):
        with pytest.raises(InputError) as as_input:
            read_input_bytes(path, max_bytes=100)
        with pytest.raises(ApdlError) as as_deck:
            Session().run_file(path)
        assert str(as_deck.value) == str(as_input.value)


def test_input_of_a_folder_says_so_at_the_input_line(tmp_path):
    # /INPUT of a folder was "not found" in a folder where it plainly was
    (tmp_path / "sub").mkdir()
    (tmp_path / "main.inp").write_text("A = 1\n/INPUT,sub\n")
    with pytest.raises(ApdlError) as info:
        Session().run_file(tmp_path / "main.inp")
    assert info.value.line == 2 and info.value.reason == ("/INPUT file 'sub': is a folder, "
                                                          "not a file")


# -------------------------------------------------------------- fuzzing
VALID_DECK = """/PREP7
ET,1,PLANE55,,,1
MP,KXX,1,50
*DO,I,0,4
N,I+1,0.01+0.01*I,0
N,I+11,0.01+0.01*I,0.01
*ENDDO
*DO,I,1,4
E,I,I+1,I+11,I+10
*ENDDO
/SOLU
NSEL,S,LOC,X,0.01
SF,ALL,HFLUX,1E4
NSEL,S,LOC,X,0.05
D,ALL,TEMP,20
ALLSEL
SOLVE
*GET,T1,NODE,1,TEMP
"""
_LINES = VALID_DECK.splitlines()


def _only_apdl_errors(text: str) -> None:
    try:
        Session().run_text(text, "fuzz.inp")
    except ApdlError:
        pass


@pytest.mark.slow
@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.text(alphabet=st.characters(codec="utf-8", exclude_categories=["Cs"]), max_size=300))
def test_fuzz_arbitrary_text(text):
    _only_apdl_errors(text)


_TOKENS = st.sampled_from(["", ",", "ALL", "-1", "0", "1e400", "I", "*DO", "*ENDDO", "*IF",
                           "(", ")", "**", "X", "TEMP", "/INPUT", "1/0", "'", "!", "P", "99"])


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.tuples(st.integers(0, len(_LINES) - 1),
                          st.sampled_from(["drop", "dup", "edit", "swap"]), _TOKENS,
                          st.integers(0, 60)), max_size=4))
def test_fuzz_mutated_valid_deck(mutations):
    lines = list(_LINES)
    for index, how, token, pos in mutations:
        index %= len(lines) if lines else 1
        if not lines:
            break
        if how == "drop":
            del lines[index]
        elif how == "dup":
            lines.insert(index, lines[index])
        elif how == "swap":
            j = (index + 1) % len(lines)
            lines[index], lines[j] = lines[j], lines[index]
        else:
            line = lines[index]
            p = min(pos, len(line))
            lines[index] = line[:p] + token + line[p + 1:]
    _only_apdl_errors("\n".join(lines))


def test_a_face_load_on_an_edge_of_zero_length_is_a_located_error():
    """Found by the mutation fuzz: nodes 1..5 at one point make edges of zero length, and the
    flux on them had no facet map (scikit-fem's 'Zero Jacobian determinant', exit 1)."""
    deck = VALID_DECK.replace("N,I+1,0.01+0.01*I,0", "N,I+1,0.01+0.0*I,0", 1)
    with pytest.raises(ApdlError, match=r"fuzz.inp:17: SOLVE: a face load on the edge of nodes "
                                        r"\d+ and \d+, which lie at one point"):
        Session().run_text(deck, "fuzz.inp")


def test_the_fuzzed_deck_itself_is_valid():
    s = run(VALID_DECK)
    # q ri / k ln(ro / ri) + T_o, the log profile of a hollow cylinder (4 elements: ~1 %)
    exact = 20.0 + 1e4 * 0.01 / 50 * math.log(5.0)
    assert s.params["T1"] == pytest.approx(exact, rel=0.02)


def test_parse_only_never_raises_other_errors():
    for text in ["\x00", "*DO", ",,,", "=", "A==1", "1A = 2", "*IF,1,EQ,1,THEN\n*ELSE\n*ELSE"]:
        try:
            parse_deck(text)
        except ApdlError:
            pass


TABLE_DECK = """C*** a results table as the Verification Manual writes it
/COM,header line
*DIM,VALUE,,3,3
*DIM,LABEL,CHAR,3,2
LABEL(1,1) = 'T,F(AT X','T (C) X=','q'
LABEL(1,2) = '/L = 0.0','.2788 in','/hr'
*VFILL,VALUE(1,1),DATA,1100,-.67037,5050
_T2 = -0.6712
*VFILL,VALUE(1,2),DATA,1100.4,_T2,4998.2
*DO,I,1,3
VALUE(I,3) = ABS(VALUE(I,2)/VALUE(I,1))
*ENDDO
SAVE,TABLE_1
VALUE(1,1) = 0
RESUME,TABLE_1
/OUT,vm0,vrt
/COM,table
*VWRITE,LABEL(1,1),LABEL(1,2),VALUE(1,1),VALUE(1,2),VALUE(1,3)
(1X,A8,A8,'   ',F10.0,'  ',F14.5,'   ',1F15.3)
/OUT
*LIST,vm0,vrt
"""


def test_results_table_idiom_writes_fortran_formatted_rows():
    s = Session()
    s.run_text(TABLE_DECK, "t.inp")
    rows = s.state.listing.files["vm0.vrt"]
    assert rows == [
        " table",
        " T,F(AT X/L = 0.0        1100.      1100.40000             1.000",
        " T (C) X=.2788 in          -1.        -0.67120             1.001",
        "        q     /hr        5050.      4998.20000             0.990",
    ]
    assert s.log[-4:] == rows  # *LIST copies the file into the output
    assert "header line" in s.log[0]
    assert s.params["_T2"] == -0.6712


def test_integer_edits_round_halves_away_from_zero_as_fortran_nint():
    # MAPDL's values are double precision and its integer descriptors take Fortran's NINT
    # (*MSG's documentation; *VWRITE's C formats are *MSG's): 2.5 -> 3, -2.5 -> -3,
    # 3.5 -> 4, 0.5 -> 1, -0.5 -> -1, 1.49999 -> 1 (Python's round() gave 2, -2, 4, 0, 0)
    s = run("*DIM,V,ARRAY,6\n*VFILL,V(1),DATA,2.5,-2.5,3.5,0.5,-0.5,1.49999\n"
            "/OUT,ints,txt\n*VWRITE,V(1),V(1)\n(I4,1X,I3)\n*VWRITE,V(1),V(1),V(1)\n"
            "%I|%5I|%-4I|\n/OUT\n*MSG,INFO,-2.5,2.5\n%4I and %I\n")
    assert s.state.listing.files["ints.txt"] == [
        "   3   3", "  -3  -3", "   4   4", "   1   1", "  -1  -1", "   1   1",
        "3|    3|3   |", "-3|   -3|-3  |", "4|    4|4   |", "1|    1|1   |",
        "-1|   -1|-1  |", "1|    1|1   |"]
    assert s.log == ["  -3 and         3"]


def test_integer_edit_of_a_value_that_is_no_number():
    from apdl_like.fortran_format import format_c_line, format_line, integer, parse_format

    assert [integer(v) for v in (float("nan"), float("inf"), -float("inf"), -0.4)] == [
        "NaN", "Inf", "-Inf", "0"]
    assert format_line(parse_format("(I2)"), [float("nan")]) == ["**"]
    assert format_c_line("%5I", [float("inf")]) == ["  Inf"]


def test_vwrite_fortran_format_reversion_when_values_outlast_the_format():
    # Fortran's format reversion: values left at the format's end start a new record and
    # the format is taken up again from its last top-level group, repeat count included,
    # or from its start when it has none.  Written by hand from the edit descriptors:
    #   (F6.2,F6.2) of 1..5: no group, back to the start each line
    #   (1X,'T=',F5.1,2(1X,F4.1)) of 1..7: back to 2(1X,F4.1), two values a line
    #   (A4,2(F4.1),'|',I3) of 'ab',1,2,3,4,5,6: back to 2(F4.1): the literal '|' and I3
    #   take the 4th and 7th values; output stops at I3 with no value left
    # Before, the values past the format's end were dropped (one line each).
    s = run("*DIM,V,ARRAY,1,7\n*VFILL,V(1,1),DATA,1\n*VFILL,V(1,2),DATA,2\n"
            "*VFILL,V(1,3),DATA,3\n*VFILL,V(1,4),DATA,4\n*VFILL,V(1,5),DATA,5\n"
            "*VFILL,V(1,6),DATA,6\n*VFILL,V(1,7),DATA,7\n/OUT,rev,txt\n"
            "*VWRITE,V(1,1),V(1,2),V(1,3),V(1,4),V(1,5)\n(F6.2,F6.2)\n"
            "*VWRITE,V(1,1),V(1,2),V(1,3),V(1,4),V(1,5),V(1,6),V(1,7)\n"
            "(1X,'T=',F5.1,2(1X,F4.1))\n"
            "*VWRITE,'ab',V(1,1),V(1,2),V(1,3),V(1,4),V(1,5),V(1,6)\n"
            "(A4,2(F4.1),'|',I3)\n/OUT\n")
    assert s.state.listing.files["rev.txt"] == [
        "  1.00  2.00", "  3.00  4.00", "  5.00",
        " T=  1.0  2.0  3.0", "  4.0  5.0", "  6.0  7.0",
        "  ab 1.0 2.0|  3", " 4.0 5.0|  6"]
    assert s.state.listing.warnings == []


def test_a_command_spelled_error_is_an_unknown_command_not_a_crash():
    # found by the arbitrary-text fuzz: a deck line `ERROR` used to index the fields of the
    # parser's own bad-line statement (IndexError, exit 1)
    s = run("ERROR\nB = 2\n")
    assert s.params["B"] == 2.0
    assert s.state.listing.warnings == [
        "warning: deck.inp:1: ERROR: unknown or unsupported command ERROR; ignored"]


def test_trailing_blank_fields_are_no_input():
    """MAPDL reads `FSUM,,,` as FSUM (VM99 writes it): blank fields past a command's last
    field are accepted; a value there is unsupported input, a warning naming the command
    and the fields ignored (MAPDL has undocumented fields: VM228 sets HEMIOPT's 19th), and
    an error with --strict."""
    s = run("/PREP7\nTUNIF,20,,,\nFINISH\n")
    assert s.state.listing.warnings == []
    s = run("/PREP7\nTUNIF,20,,,5\nFINISH\n")
    assert s.state.listing.warnings == [
        "warning: deck.inp:2: TUNIF: takes at most 1 fields, got 4; fields 2..4 ignored"]
    with pytest.raises(ApdlError, match="TUNIF.*takes at most 1 fields, got 4 \\(--strict\\)"):
        run("/PREP7\nTUNIF,20,,,5\nFINISH\n", strict=True)


def test_table_parameters_interpolate_between_their_index_values():
    """*DIM,TABLE: row 0 / column 0 hold index values; TB(x[,y]) interpolates linearly
    (hand arithmetic below) and holds the end value outside the index range."""
    s = run("""*DIM,TB,TABLE,3,1,1,TIME
TB(1,0) = 0,10,20
TB(1,1) = 1,2,3
A = TB(15)
B = TB(-5)
C = TB(99)
*DIM,T2,TABLE,2,2
T2(1,0) = 0,1
T2(0,1) = 0
T2(0,2) = 2
T2(1,1) = 0,10
T2(1,2) = 20,30
D = T2(0.5,1)
*VFILL,TB(1,1),RAMP,5,5
E = TB(5)
""")
    p = s.params
    assert (p["A"], p["B"], p["C"]) == (2.5, 1.0, 3.0)
    # T2 (assignments fill down a column): x = 0 → (0, 20), x = 1 → (10, 30) at y = 0, 2;
    # halfway in both: 15
    assert p["D"] == pytest.approx(15.0)
    assert p["E"] == pytest.approx(7.5)  # the RAMP refilled column 1 with 5, 10, 15
    with pytest.raises(ApdlError, match=r"deck.inp:2: TB\(4,1\) = 1: subscript 1 of table TB is 4"):
        run("*DIM,TB,TABLE,3\nTB(4,1) = 1\n")


def test_cfwrite_substitutes_parameter_values_and_keeps_labels():
    """MAPDL's *CFWRITE writes the command with numeric parameters and expressions
    replaced by their values; labels (ALL, TEMP) and quoted text stay as written."""
    s = run("""NN = 7
*DIM,V,ARRAY,2
V(2) = 2.5
*CFOPEN,cmds,inp
*CFWRITE,D,NN,TEMP,V(2)*2
*CFWRITE,NSEL,ALL
*CFCLOS
""")
    assert s.state.listing.files["cmds.inp"] == ["D,7,TEMP,5", "NSEL,ALL"]


def test_a_singular_thermal_system_is_one_located_error_without_scipy_s_warning():
    """Found by the mutation fuzz: with nothing holding the temperature (no D,,TEMP and
    no convection) SuperLU may not raise but warn `MatrixRankWarning` and return NaN; the
    ApdlError came, but the warning went to the user's console before it."""
    from scipy.sparse.linalg import MatrixRankWarning

    deck = VALID_DECK.replace("D,ALL,TEMP,20\n", "", 1)
    with warnings.catch_warnings():
        warnings.simplefilter("error", MatrixRankWarning)
        with pytest.raises(ApdlError, match=r"fuzz.inp:\d+: SOLVE: the thermal system is "
                                            r"singular: fix a temperature"):
            Session().run_text(deck, "fuzz.inp")
