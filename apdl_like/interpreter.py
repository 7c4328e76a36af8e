"""Running a parsed deck: parameters, *DO/*IF control flow, /INPUT and macros, dispatch.

A macro is a file beside the deck run with arguments: `*USE,Name,ARG1,...,AR18`, or its
name as a command (`name,ARG1,...,AR19` runs `name.mac`, MAPDL's macro search, when no
command has that name).  ARG1..ARG9 and AR10..AR19 are local to each macro: set from the
call (0 when not given), the caller's own values back when the macro ends.  /INPUT and
macros read their files the same way: only beside the deck.

Limits keep any deck finite: loop iterations per run, statements per run, file depth.
"""

from __future__ import annotations

import math
import os
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from apdl_like.call import Call
from apdl_like.errors import ApdlError
from apdl_like.expressions import compile_expression, is_parameter_name
from apdl_like.params import store, subscripts, value_of
from apdl_like.parser import BAD_LINE, Program, Statement, read_deck, split_fields
from apdl_like.registry import lookup

if TYPE_CHECKING:
    from apdl_like.state import SessionState

MAX_LOOP_ITERATIONS = 100_000
MAX_STATEMENTS = 2_000_000
MAX_INPUT_DEPTH = 20  # /INPUT and macro files inside each other (MAPDL nests macros 20 deep)
IF_OPERATORS = ("EQ", "NE", "LT", "GT", "LE", "GE", "ABLT", "ABGT")
EQ_TOLERANCE = 1e-10  # APDL compares *IF values with this absolute tolerance
# statements `execute` runs itself (assignments, control flow, /INPUT, *REPEAT, bad lines);
# every other name is a command for `_dispatch`
_CONTROL = frozenset((BAD_LINE, "=", "*DO", "*DOWHILE", "*ENDDO", "*IF", "*ELSEIF", "*ELSE",
                      "*ENDIF", "*EXIT", "*CYCLE", "/INPUT", "*REPEAT", "*USE", "/EOF"))
# a macro's local parameters, in MAPDL's spelling: ARG1..ARG9, then AR10..AR19
MACRO_ARGUMENTS = tuple(f"ARG{k}" for k in range(1, 10)) + tuple(f"AR{k}" for k in range(10, 20))
MACRO_EXTENSION = "mac"


class _EndOfFile(Exception):
    """/EOF reached inside a block: the file being read ends there."""


class _Exit(Exception):
    """*EXIT / *CYCLE of the loop starting at statement `do_index`."""

    def __init__(self, do_index: int, cycle: bool) -> None:
        self.do_index, self.cycle = do_index, cycle


def _value(session: SessionState, st: Statement, i: int, what: str) -> float:
    text = st.fields[i - 1] if i <= len(st.fields) else ""
    if not text:
        raise st.error(f"field {i} ({what}) is required")
    try:
        return compile_expression(text)(session.params, session.model_functions)
    except ApdlError as exc:
        raise st.error(f"field {i} ({what}): {exc.reason}") from None


def _compare(a: float, op: str, b: float) -> bool:
    if op == "EQ":
        return abs(a - b) <= EQ_TOLERANCE
    if op == "NE":
        return abs(a - b) > EQ_TOLERANCE
    if op == "LT":
        return a < b
    if op == "GT":
        return a > b
    if op == "LE":
        return a <= b
    if op == "GE":
        return a >= b
    if op == "ABLT":
        return abs(a) < abs(b)
    return abs(a) > abs(b)  # ABGT


def _condition(session: SessionState, st: Statement) -> tuple[bool, str]:
    """Evaluate `*IF/*ELSEIF,V1,OP1,V2[,AND|OR|XOR,V3,OP2,V4]` -> (truth, action)."""
    f = [x.upper() for x in st.fields]

    def one(base: int) -> bool:
        op = f[base] if base < len(f) else ""
        if op not in IF_OPERATORS:
            raise st.error(f"field {base + 1}: comparison must be one of {', '.join(IF_OPERATORS)}")
        a = _value(session, st, base, "VAL1")
        b = _value(session, st, base + 2, "VAL2")
        return _compare(a, op, b)

    truth = one(1)
    action_field = 3 if st.name == "*IF" else None
    conj = f[3] if len(f) > 3 else ""
    if conj in ("AND", "OR", "XOR"):
        second = one(5)
        truth = {"AND": truth and second, "OR": truth or second, "XOR": truth != second}[conj]
        action_field = 7 if st.name == "*IF" else None
    elif st.name == "*ELSEIF" and conj:
        raise st.error(f"field 4 must be AND, OR or XOR, got {conj!r}")
    action = f[action_field] if action_field is not None and action_field < len(f) else ""
    return truth, action


def _assign(session: SessionState, st: Statement) -> None:
    """`NAME = value` or `NAME(i,j) = v1, v2, ...` (down the column)."""
    name, subs_text, *values = st.fields
    if not is_parameter_name(name):
        raise st.error(f"{name!r} is not a valid parameter name (≤ 32 characters, letter or _ "
                       "first, not a function name)")
    params, funcs = session.params, session.model_functions
    try:
        if not subs_text and values == [""]:
            params.pop(name, None)  # `NAME =` deletes the parameter, as in APDL
            return
        subs = subscripts(split_fields(subs_text), params, funcs) if subs_text else []
        store(params, name, subs, [value_of(v, params, funcs) for v in values])
    except ApdlError as exc:
        raise st.error(exc.reason) from None


def execute(session: SessionState, program: Program, depth: int = 0) -> None:
    """Run `program`; nested `/INPUT` files run recursively with their own file:line."""
    stmts = program.statements
    n = len(stmts)
    loops: dict[int, list[float]] = {}  # *DO index -> [value, increment, remaining]
    previous: Statement | None = None  # the last command run, for *REPEAT
    i = 0
    while i < n:
        st = stmts[i]
        session.budget.statements_run += 1
        if session.budget.statements_run > MAX_STATEMENTS:
            raise st.error(f"more than {MAX_STATEMENTS} statements executed (runaway deck?)")
        name = st.name
        if name not in _CONTROL:  # a command: the usual statement, one set lookup
            _dispatch(session, st, depth)
            previous = st
            i += 1
            continue
        try:
            if name == BAD_LINE:
                raise st.error(st.fields[0])
            if name == "=":
                _assign(session, st)
            elif name == "*DO":
                i = _start_loop(session, program, st, i, loops)
                continue
            elif name == "*DOWHILE":
                if _value(session, st, 1, "Par") > 0.0:
                    loops[i] = [0.0, 0.0, 0.0]
                    _count_iteration(session, st)
                    i += 1
                else:
                    i = program.block_end[i] + 1
                continue
            elif name == "*ENDDO":
                i = _next_iteration(session, program, i, loops)
                continue
            elif name == "*IF":
                truth, action = _condition(session, st)
                if action == "THEN":
                    i = _take_branch(session, program, i, truth)
                    continue
                if truth:
                    if action in ("EXIT", "CYCLE"):
                        if i not in program.enclosing_do:
                            raise st.error(f"*IF action {action} outside a *DO loop")
                        raise _Exit(program.enclosing_do[i], action == "CYCLE")
                    if action == "STOP":
                        raise st.error("deck stopped by *IF,...,STOP")
                    raise st.error(f"*IF action must be THEN, EXIT, CYCLE or STOP, got {action!r}"
                                   " (*GO labels are not supported)")
                elif action not in ("EXIT", "CYCLE", "STOP"):
                    raise st.error(f"*IF action must be THEN, EXIT, CYCLE or STOP, got {action!r}")
            elif name in ("*ELSEIF", "*ELSE"):
                # reached the end of a branch that ran: skip to after *ENDIF
                i = program.block_end[_owner_if(program, i)] + 1
                continue
            elif name == "*ENDIF":
                pass
            elif name in ("*EXIT", "*CYCLE"):
                raise _Exit(program.enclosing_do[i], name == "*CYCLE")
            elif name == "/INPUT":
                _input(session, st, depth)
            elif name == "*USE":
                name_field = st.fields[0] if st.fields else ""
                if not name_field:
                    raise st.error("field 1 (macro name) is required")
                _run_macro(session, st, _macro_file(session, st, name_field), st.fields[1:],
                           depth)
            elif name == "/EOF":
                raise _EndOfFile
            elif name == "*REPEAT":
                _repeat(session, previous, st, depth)
            else:
                _dispatch(session, st, depth)
                previous = st
        except _EndOfFile:
            return
        except _Exit as jump:
            end = program.block_end[jump.do_index]
            if jump.cycle:
                i = end
            else:
                for j in [j for j in loops if jump.do_index <= j <= end]:
                    del loops[j]
                i = end + 1
            continue
        i += 1


def _owner_if(program: Program, i: int) -> int:
    for if_index, branches in program.if_branches.items():
        if i in branches:
            return if_index
    raise program.statements[i].error("branch without its *IF")  # pragma: no cover


def _take_branch(session: SessionState, program: Program, i: int, truth: bool) -> int:
    if truth:
        return i + 1
    for j in program.if_branches[i]:
        st = program.statements[j]
        if st.name == "*ELSE":
            return j + 1
        ok, _ = _condition(session, st)
        if ok:
            return j + 1
    return program.block_end[i] + 1


def _start_loop(session: SessionState, program: Program, st: Statement, i: int,
                loops: dict[int, list[float]]) -> int:
    par = st.fields[0].upper() if st.fields else ""
    if not is_parameter_name(par):
        raise st.error(f"field 1 must be a parameter name, got {par!r}")
    start = _value(session, st, 2, "IVAL")
    final = _value(session, st, 3, "FVAL")
    inc = _value(session, st, 4, "INC") if len(st.fields) >= 4 and st.fields[3] else 1.0
    if inc == 0.0:
        raise st.error("field 4 (INC) must not be zero")
    count = math.floor((final - start) / inc + 1e-9) + 1
    if count > MAX_LOOP_ITERATIONS:
        raise st.error(f"loop of {count} iterations exceeds the limit of {MAX_LOOP_ITERATIONS}")
    session.params[par] = start
    if count <= 0:
        return program.block_end[i] + 1
    loops[i] = [start, inc, count - 1]
    _count_iteration(session, st)
    return i + 1


def _next_iteration(session: SessionState, program: Program, end: int,
                    loops: dict[int, list[float]]) -> int:
    do_index = next(j for j, e in program.block_end.items() if e == end)
    state = loops.get(do_index)
    do_st = program.statements[do_index]
    if do_st.name == "*DOWHILE":  # again while Par > 0, as MAPDL
        if state is not None and _value(session, do_st, 1, "Par") > 0.0:
            _count_iteration(session, do_st)
            return do_index + 1
        loops.pop(do_index, None)
        return end + 1
    if state is None or state[2] <= 0:
        loops.pop(do_index, None)
        return end + 1
    state[0] += state[1]
    state[2] -= 1
    session.params[do_st.fields[0].upper()] = state[0]
    _count_iteration(session, do_st)
    return do_index + 1


def _count_iteration(session: SessionState, st: Statement) -> None:
    session.budget.loop_iterations += 1
    if session.budget.loop_iterations > MAX_LOOP_ITERATIONS:
        raise st.error(f"more than {MAX_LOOP_ITERATIONS} loop iterations (runaway *DO?)")


def _input(session: SessionState, st: Statement, depth: int) -> None:
    fname = st.fields[0] if st.fields else ""
    ext = st.fields[1] if len(st.fields) > 1 else ""
    if not fname:
        raise st.error("field 1 (file name) is required")
    name = f"{fname}.{ext}" if ext else fname
    execute(session, _read_beside_deck(session, st, name, "/INPUT file", depth), depth + 1)


def _beside_deck(session: SessionState, st: Statement, name: str, what: str) -> Path:
    """The file `name` in the deck's folder (DESIGN: files are read only beside the deck);
    it need not exist."""
    if session.base_dir is None:
        raise st.error(f"{what} {name!r} needs a deck folder (run the deck from a file)")
    base = session.base_dir.resolve()
    # realpath, not Path.resolve: a symlink loop is a file not found, not a RuntimeError
    target = Path(os.path.realpath(base / name))
    if not target.is_relative_to(base):
        raise st.error(f"{what} {name!r} lies outside the deck's folder {str(base)!r}")
    return target


def _read_beside_deck(session: SessionState, st: Statement, name: str, what: str,
                      depth: int) -> Program:
    """Parse the file `name` beside the deck, for /INPUT or a macro run from a file at
    `depth`, shown by its name."""
    if depth + 1 > MAX_INPUT_DEPTH:
        raise st.error(f"/INPUT and macro files nested deeper than {MAX_INPUT_DEPTH} files")
    target = _beside_deck(session, st, name, what)
    if not target.exists():  # a symlink loop too
        raise st.error(f"{what} {name!r} not found in {str(session.base_dir.resolve())!r}")
    shown = str(Path(st.file).parent / name) if st.file and not st.file.startswith("<") else name
    try:
        program = read_deck(target, shown)
    except ApdlError as exc:
        if exc.line is not None:
            raise
        # a folder or a fifo was "not found"; the file's problem at the calling line
        raise st.error(f"{what} {name!r}: {exc.reason}") from None
    session.inputs.append(target)
    return program


def _macro_file(session: SessionState, st: Statement, name: str) -> str:
    """*USE,Name: the file `Name` beside the deck, else `Name.mac` (its name as written,
    then in lower case, as a Linux MAPDL looks for it)."""
    candidates = [name, f"{name}.{MACRO_EXTENSION}", f"{name.lower()}.{MACRO_EXTENSION}"]
    for candidate in candidates:
        if _beside_deck(session, st, candidate, "macro file").is_file():
            return candidate
    raise st.error(f"macro file {name!r} not found in the deck's folder (tried "
                   f"{', '.join(dict.fromkeys(candidates))})")


def _run_macro(session: SessionState, st: Statement, file_name: str,
               arguments: tuple[str, ...], depth: int) -> None:
    """Run a macro file with ARG1..AR19 set from `arguments` (evaluated by the caller)."""
    limit = len(MACRO_ARGUMENTS) - (1 if st.name == "*USE" else 0)
    given = len(arguments)
    while given and not arguments[given - 1].strip():
        given -= 1
    if given > limit:
        raise st.error(f"a macro takes at most {limit} arguments, got {given}")
    values: list[float | str] = []
    for k, text in enumerate(arguments[:given]):
        try:
            values.append(value_of(text, session.params, session.model_functions)
                          if text.strip() else 0.0)
        except ApdlError as exc:
            raise st.error(f"argument {MACRO_ARGUMENTS[k]} ({text.strip()}): "
                           f"{exc.reason}") from None
    program = _read_beside_deck(session, st, file_name, "macro file", depth)
    params = session.params
    callers = {name: params.pop(name) for name in MACRO_ARGUMENTS if name in params}
    params.update(zip(MACRO_ARGUMENTS, values + [0.0] * (len(MACRO_ARGUMENTS) - len(values)),
                      strict=True))
    try:
        execute(session, program, depth + 1)
    finally:
        for name in MACRO_ARGUMENTS:
            params.pop(name, None)
        params.update(callers)


def _repeat(session: SessionState, previous: Statement | None, st: Statement,
            depth: int) -> None:
    """*REPEAT,NTOT,VINC1,...,VINC11: the previous command NTOT-1 more times, field j
    increased by k·VINCj in the k-th repetition."""
    if previous is None:
        raise st.error("*REPEAT needs a command before it")
    total = int(round(_value(session, st, 1, "NTOT")))
    if not 1 <= total <= MAX_LOOP_ITERATIONS:
        raise st.error(f"field 1 (NTOT) must lie in 1..{MAX_LOOP_ITERATIONS}")
    incs = [_value(session, st, j + 2, "VINC") if j + 2 <= len(st.fields) and
            st.fields[j + 1] else 0.0 for j in range(11)]
    for k in range(1, total):
        fields = list(previous.fields)
        for j, inc in enumerate(incs):
            if inc == 0.0:
                continue
            base = _value(session, previous, j + 1, "repeated field") if j < len(fields) \
                and fields[j] else 0.0
            fields += [""] * (j + 1 - len(fields))
            fields[j] = repr(base + k * inc)
        _count_iteration(session, st)
        _dispatch(session, Statement(previous.file, st.line, previous.name, tuple(fields),
                                     previous.text, previous.block), depth)


def _dispatch(session: SessionState, st: Statement, depth: int) -> None:
    spec = lookup(st.name)
    if spec is None:
        macro = _macro_by_name(session, st)
        if macro is not None:
            _run_macro(session, st, macro, st.fields, depth)
            return
        message = f"unknown or unsupported command {st.name}"
        if session.strict:
            raise st.error(message + " (--strict)")
        session.warn(st.error(message + "; ignored"))
        return
    if session.processor not in spec.processors:
        where = {"BEGIN": "the begin level", "PREP7": "/PREP7", "SOLU": "/SOLU",
                 "POST1": "/POST1", "POST26": "/POST26", "AUX12": "/AUX12"}
        allowed = " or ".join(where[p] for p in sorted(spec.processors))
        raise st.error(f"not valid in {where[session.processor]} (use it in {allowed})")
    given = len(st.fields)
    while given > spec.max_fields and not str(st.fields[given - 1]).strip():
        given -= 1  # trailing blank fields are no input (FSUM,,,)
    if given > spec.max_fields:
        # values past the fields apdl_like reads (MAPDL has undocumented ones: VM228 sets
        # HEMIOPT's 19th) are unsupported input: a warning, as for an unknown command
        message = f"takes at most {spec.max_fields} fields, got {given}"
        if session.strict:
            raise st.error(message + " (--strict)")
        session.warn(st.error(f"{message}; fields {spec.max_fields + 1}..{given} ignored"))
        st = replace(st, fields=st.fields[:spec.max_fields])
    try:
        spec.handler(session, Call(st, session))
    except ApdlError as exc:
        raise exc.located(st.file, st.line, st.shown) from None
    except ValueError as exc:  # validation inside twin.fem (names the item)
        raise st.error(str(exc)) from None
    except ArithmeticError as exc:  # the deck's numbers overflow (RECTNG at 1e300, ...)
        raise st.error(f"numbers out of range ({exc})") from None


def _macro_by_name(session: SessionState, st: Statement) -> str | None:
    """MAPDL's macro search for an unknown command `NAME`: `name.mac` beside the deck (in
    lower case, as a Linux MAPDL writes and finds it, or in upper case)."""
    if session.base_dir is None or not is_parameter_name(st.name):
        return None
    for candidate in (f"{st.name.lower()}.{MACRO_EXTENSION}", f"{st.name}.{MACRO_EXTENSION}"):
        if _beside_deck(session, st, candidate, "macro file").is_file():
            return candidate
    return None
