"""NSORT/NUSORT and *GET,,SORT on a bar whose steady temperatures are known by hand.

A PLANE55 strip 0 ≤ x ≤ 4, 0 ≤ y ≤ 1 of four elements, held at T_LEFT at x = 0 and T_RIGHT
at x = 4 with no other load, conducts a linear field: bilinear elements hold it exactly,
T = T_LEFT + (T_RIGHT - T_LEFT)·x/4 at the bottom nodes 1..5 (x = 0..4) and the top nodes
6..10 above them.
"""

from __future__ import annotations

import pytest

from apdl_like.errors import ApdlError
from apdl_like.session import Session
from tests.apdl_decks import SOLVE_THEN_POST


def bar(t_left: float, t_right: float, post: str) -> Session:
    s = Session()
    s.run_text(f"""/PREP7
ET,1,PLANE55
MP,KXX,1,10
*DO,I,1,5
N,I,I-1,0
N,I+5,I-1,1
*ENDDO
*DO,I,1,4
E,I,I+1,I+6,I+5
*ENDDO
NSEL,S,LOC,X,0
D,ALL,TEMP,{t_left}
NSEL,S,LOC,X,4
D,ALL,TEMP,{t_right}
NSEL,ALL
{SOLVE_THEN_POST}
{post}
""", "bar.inp")
    return s


GET_ALL = "*GET,TMAX,SORT,,MAX\n*GET,NMAX,SORT,,IMAX\n*GET,TMIN,SORT,,MIN\n*GET,NMIN,SORT,,IMIN\n"


def extremes(s: Session) -> tuple[float, float, float, float]:
    p = s.params
    return p["TMAX"], p["NMAX"], p["TMIN"], p["NMIN"]


def test_nsort_by_temperature_gives_the_extremes_and_their_nodes():
    # 100 °C at x = 0 (nodes 1 and 6: the lower number), 20 °C at x = 4 (nodes 5 and 10)
    s = bar(100, 20, "NSORT,TEMP\n" + GET_ALL)
    assert extremes(s) == pytest.approx((100.0, 1.0, 20.0, 5.0))
    s = bar(100, 20, "NSORT,TEMP,,1\n" + GET_ALL)  # ascending order: the same extremes
    assert extremes(s) == pytest.approx((100.0, 1.0, 20.0, 5.0))


def test_nsort_by_absolute_value():
    # the bottom nodes (an inner node and the one above it are equal only to round-off):
    # -50 + 21x is -50, -29, -8, 13, 34 at x = 0..4; |T| largest at node 1, smallest at 3
    s = bar(-50, 34, "NSEL,S,LOC,Y,0\nNSORT,TEMP,,0,1\n" + GET_ALL)
    assert extremes(s) == pytest.approx((50.0, 1.0, 8.0, 3.0))
    s = bar(-50, 34, "NSEL,S,LOC,Y,0\nNSORT,TEMP\n" + GET_ALL)  # signed: 34 at 5, -50 at 1
    assert extremes(s) == pytest.approx((34.0, 5.0, -50.0, 1.0))


def test_nsort_sorts_the_selected_nodes_and_selects_the_first_numb():
    s = bar(100, 20, "NSEL,S,LOC,X,1,3\nNSEL,R,LOC,Y,0\nNSORT,TEMP\n" + GET_ALL +
            "NSEL,S,LOC,Y,0\nNSORT,TEMP,,0,0,2,SELECT\n*GET,KEPT,NODE,0,COUNT\n"
            "*GET,KEPT_MIN,NODE,0,NUM,MIN\n*GET,KEPT_MAX,NODE,0,NUM,MAX\n"
            "NSEL,ALL\nNSORT,LOC,X\n*GET,XMAX,SORT,,MAX\n*GET,NXMAX,SORT,,IMAX\n"
            "NUSORT\n*GET,XMAX_AFTER,SORT,,MAX\n")
    # x = 1..3 at the bottom holds 80, 60, 40 °C (nodes 2..4)
    assert extremes(s) == pytest.approx((80.0, 2.0, 40.0, 4.0))
    # the two hottest bottom nodes: 100 °C at node 1, 80 °C at node 2
    p = s.params
    assert (p["KEPT"], p["KEPT_MIN"], p["KEPT_MAX"]) == (2.0, 1.0, 2.0)
    assert (p["XMAX"], p["NXMAX"]) == (4.0, 5.0)
    assert p["XMAX_AFTER"] == 4.0  # *GET,,SORT reads the last sort; NUSORT keeps it


@pytest.mark.parametrize("post, message", [
    ("*GET,A,SORT,,MAX\n", "no NSORT or ESORT has been run"),
    ("NSORT,U,X\n", "needs a structural result"),
    ("NSORT,HEAT\n", "NSORT supports TEMP"),
    ("NSORT,TEMP\n*GET,A,SORT,,AVG\n", "SORT supports MAX, MIN, IMAX and IMIN"),
    ("NSORT,TEMP,,2\n", "ORDER"),
    ("NSEL,NONE\nNSORT,TEMP\n", "no selected node"),
])
def test_nsort_refusals_name_the_line(post, message):
    with pytest.raises(ApdlError, match=message) as info:
        bar(100, 20, post)
    assert info.value.file == "bar.inp" and info.value.line > 20
