"""Results tables and listings: *DIM, *VFILL, *VOPER, *VSCFUN, *VWRITE, *MSG, /OUT,
*CFOPEN/*CFWRITE/*CFCLOS, *LIST, *STATUS, SAVE and RESUME (valid in every processor).

Files the deck writes are kept in memory by name (`SessionState.listing.files`) and written
by the CLI inside its --out folder only: a name is a plain file name, never a path.  SAVE and
RESUME keep named copies of the database and parameters in memory (no .db file).
"""

from __future__ import annotations

import copy
import re
from typing import TYPE_CHECKING

import numpy as np

from apdl_like.call import ANY, Call, CommandSpec, command, specs_of
from apdl_like.errors import ApdlError
from apdl_like.expressions import compile_expression, element_index, is_parameter_name
from apdl_like.params import (
    column,
    dimension,
    is_text,
    numeric_array,
    split_target,
    start_subscripts,
    store,
    subscripts,
    value_of,
)

if TYPE_CHECKING:
    from apdl_like.state import SessionState

_FILE_PART = re.compile(r"[A-Za-z0-9_\-]+(\.[A-Za-z0-9_\-]+)*\Z")
RESERVED_FILES = ("params.json", "log.txt")
MAX_VWRITE_LINES = 1_000_000
JOBNAME = "file"


def file_name(c: Call, default_ext: str = "") -> str:
    """`Fname.Ext` from fields 1 and 2: a plain name inside the output folder."""
    fname, ext = c.raw(1), c.raw(2)
    if not fname:
        fname = JOBNAME
    ext = ext or default_ext
    name = f"{fname}.{ext}" if ext else fname
    if not _FILE_PART.match(fname) or (ext and not _FILE_PART.match(ext)) or \
            name.lower() in RESERVED_FILES or name.lower().startswith("result_"):
        raise ApdlError(f"file {name!r}: files a deck writes are plain names (letters, digits, "
                        f"_ - .) inside the output folder, not {', '.join(RESERVED_FILES)} or "
                        "result_*")
    return name


@command("*DIM", ANY, 8)
def star_dim(s: SessionState, c: Call) -> None:
    name, subs = split_target(c.raw(1))
    if subs:
        raise ApdlError("field 1: the array name without subscripts")
    kind = c.label(2, "ARRAY")
    shape = (c.int(3, 1, what="IMAX"), c.int(4, 1, what="JMAX"), c.int(5, 1, what="KMAX"))
    if kind == "STRING":
        shape = (shape[1], 1, 1)  # *DIM,Par,STRING,length,rows: rows of one string
    variables = (c.label(6), c.label(7), c.label(8))  # a TABLE's primary variables
    dimension(s.params, name, kind, shape, variables)


@command("*VFILL", ANY, 20)
def star_vfill(s: SessionState, c: Call) -> None:
    """*VFILL,Par(i,j),DATA,v1,v2,... or RAMP,start,increment (down the column)."""
    name, subs_text = split_target(c.raw(1))
    params, funcs = s.params, s.model_functions
    subs = start_subscripts(subs_text, params, funcs)
    func = c.label(2, "DATA")
    array = params.get(name)
    if not isinstance(array, np.ndarray):
        raise ApdlError(f"{name} is not an array (define it with *DIM first)")
    if func == "DATA":
        last = max((i for i in range(3, c.count() + 1) if c.given(i)), default=2)
        values = [value_of(c.raw(i), params, funcs) if c.given(i) else 0.0
                  for i in range(3, last + 1)]
    elif func == "RAMP":
        start, step = c.num(3, 0.0, what="start"), c.num(4, 0.0, what="increment")
        rows = array.shape[0] - element_index(name, array, subs)[0]
        values = [start + k * step for k in range(rows)]
    else:
        raise ApdlError(f"field 2: *VFILL supports DATA and RAMP, got {func!r}")
    store(params, name, subs, values)


@command("*VWRITE", ANY, 19)
def star_vwrite(s: SessionState, c: Call) -> None:
    """*VWRITE,Par1,...: one line per row of the array arguments, by the format line."""
    from apdl_like.fortran_format import format_c_line, format_line, parse_format

    params, funcs = s.params, s.model_functions
    columns: list[list[float | str]] = []
    arrays = []
    for i in range(1, c.count() + 1):
        text = c.raw(i)
        if not text:
            continue
        if text.startswith("'"):
            columns.append([value_of(text, params, funcs)])
            continue
        name, subs_text = split_target(text) if _is_reference(text) else ("", [])
        if name and (subs_text or isinstance(params.get(name), np.ndarray | str)):
            col = column(params, name, subscripts(subs_text, params, funcs))
            if isinstance(params.get(name), np.ndarray):
                arrays.append(len(col))
            columns.append(col)
        else:
            columns.append([c.num(i)])
    rows = min(arrays) if arrays else 1
    if rows > MAX_VWRITE_LINES:
        raise ApdlError(f"more than {MAX_VWRITE_LINES} lines")
    fmt = c.statement.block[0] if c.statement.block else ""
    c_style = "%" in fmt and not fmt.strip().startswith("(")
    items = None if c_style else parse_format(fmt)
    lines: list[str] = []
    for r in range(rows):
        values = [col[r] if len(col) > 1 or r < len(col) else col[0] for col in columns]
        lines += format_c_line(fmt, values) if items is None else format_line(items, values)
    listing = s.listing
    target = listing.command_file
    for line in lines:
        if target is not None:
            listing.files[target].append(line)
        else:
            s.say(line)


_VOPER = {
    "ADD": np.add, "SUB": np.subtract, "MULT": np.multiply, "MIN": np.minimum,
    "MAX": np.maximum,
    "LT": lambda a, b: (a < b).astype(float), "LE": lambda a, b: (a <= b).astype(float),
    "EQ": lambda a, b: (a == b).astype(float), "NE": lambda a, b: (a != b).astype(float),
    "GE": lambda a, b: (a >= b).astype(float), "GT": lambda a, b: (a > b).astype(float),
}


@command("*VOPER", ANY, 6)
def star_voper(s: SessionState, c: Call) -> None:
    """*VOPER,ParR(i),Par1(j),Oper,Par2(k): element by element down the columns, ParR =
    Par1 Oper Par2, for ADD, SUB, MULT, DIV, MIN, MAX and the comparisons LT, LE, EQ, NE,
    GE, GT (1 true, 0 false).  Par1 and Par2 are array elements (the column from there on)
    or a scalar parameter or number, used on every row.  As MAPDL documents, the rows run
    from ParR(i) to the end of ParR's column, and an input column that ends before is read
    as zeros.  Derivatives, integrals, GATH/SCAT, DOT/CROSS, *VLEN and *VMASK are not
    supported."""
    params, funcs = s.params, s.model_functions
    oper = c.label(3)
    if oper not in (*_VOPER, "DIV"):
        raise ApdlError(f"field 3: *VOPER supports ADD, SUB, MULT, DIV, MIN, MAX, LT, LE, EQ, "
                        f"NE, GE and GT, got {oper or '(empty)'!r}")
    if c.given(5) or c.given(6):
        raise ApdlError("fields 5-6 (CON1, CON2) are not supported")
    name, subs_text = split_target(c.raw(1).strip())
    result = numeric_array(params, name, 1)
    subs = start_subscripts(subs_text, params, funcs)
    operands: list[np.ndarray | float] = []
    for field in (2, 4):
        text = c.raw(field).strip()
        if not text:
            raise ApdlError(f"field {field} (Par{field // 2}) is required")
        if _is_reference(text):
            ref, ref_subs = split_target(text)
            array = params.get(ref)
            if isinstance(array, np.ndarray):
                if array.dtype == object:
                    raise ApdlError(f"field {field}: {ref} is a character array")
                operands.append(np.array(column(params, ref, start_subscripts(
                    ref_subs, params, funcs)), float))
                continue
        operands.append(c.num(field, what=f"Par{field // 2}"))
    rows = result.shape[0] - element_index(name, result, subs)[0]
    a, b = (np.pad(o[:rows], (0, max(rows - len(o), 0))) if isinstance(o, np.ndarray)
            else np.full(rows, o) for o in operands)
    if oper == "DIV":
        zero = np.nonzero(b == 0.0)[0]
        if zero.size:
            raise ApdlError(f"division by zero (row {int(zero[0]) + 1} of Par2)")
        values = a / b
    else:
        values = _VOPER[oper](a, b)
    if not np.all(np.isfinite(values)):
        raise ApdlError("the result is not a finite number")
    store(params, name, subs, [float(v) for v in values])


_VSCFUN = ("MAX", "MIN", "LMAX", "LMIN", "FIRST", "LAST", "SUM", "MEDI", "MEAN", "VARI",
           "STDV", "RMS", "NUM")


@command("*VSCFUN", ANY, 3)
def star_vscfun(s: SessionState, c: Call) -> None:
    """*VSCFUN,ParR,Func,Par1(i): a scalar from the column of Par1 from row i to its end:
    MAX, MIN, SUM, MEAN, MEDI (the middle value; the mean of the two middle ones for an
    even count), VARI (Σ(x − mean)²/NUM), STDV (its square root), RMS, NUM, and the row
    numbers LMAX, LMIN, FIRST and LAST (first and last nonzero value; 0 when none), these
    four from row 1 only.  *VLEN, *VMASK, *VABS, *VFACT and *VCUM are not supported."""
    params, funcs = s.params, s.model_functions
    target = c.raw(1).strip().upper()
    if not is_parameter_name(target):
        raise ApdlError(f"field 1: {c.raw(1)!r} is not a valid parameter name")
    func = c.label(2)
    if func not in _VSCFUN:
        raise ApdlError(f"field 2: *VSCFUN supports {', '.join(_VSCFUN)}, got "
                        f"{func or '(empty)'!r}")
    name, subs_text = split_target(c.raw(3).strip())
    array = numeric_array(params, name, 3)
    subs = start_subscripts(subs_text, params, funcs)
    start = element_index(name, array, subs)
    x = np.array(column(params, name, subs), float)
    if func in ("LMAX", "LMIN", "FIRST", "LAST"):
        if start[0] != 0:
            raise ApdlError(f"{func} from a row other than 1 is not supported (is the row "
                            "counted from row 1 or from the start?)")
        nonzero = np.nonzero(x)[0]
        value = float({"LMAX": np.argmax(x) + 1, "LMIN": np.argmin(x) + 1,
                       "FIRST": nonzero[0] + 1 if nonzero.size else 0,
                       "LAST": nonzero[-1] + 1 if nonzero.size else 0}[func])
    else:
        mean = float(x.mean())
        value = {"MAX": float(x.max()), "MIN": float(x.min()), "SUM": float(x.sum()),
                 "MEDI": float(np.median(x)), "MEAN": mean, "NUM": float(x.size),
                 "VARI": float(((x - mean) ** 2).mean()),
                 "STDV": float(np.sqrt(((x - mean) ** 2).mean())),
                 "RMS": float(np.sqrt((x ** 2).mean()))}[func]
    params[target] = value


def _vector_control(s: SessionState, c: Call) -> None:
    """*VLEN, *VMASK, *VABS, *VFACT, *VCUM: refused rather than ignored, since ignoring one
    would change what the next *VOPER, *VSCFUN or *VWRITE computes without a word."""
    raise ApdlError("not supported: *VGET, *VOPER, *VSCFUN and *VWRITE here run over whole "
                    "columns, with no length, mask, absolute value, scale factor or "
                    "accumulation")


def _is_reference(text: str) -> bool:
    return bool(re.match(r"\s*[A-Za-z_][A-Za-z0-9_]*\s*(\(.*\))?\s*\Z", text, re.S))


@command("/OUT", ANY, 4)
def out(s: SessionState, c: Call) -> None:
    """/OUT,Fname,Ext,,APPEND: output to a file; /OUT alone (or TERM): back to the log."""
    listing = s.listing
    if not c.given(1) and not c.given(2) or c.label(1) == "TERM":
        listing.target = None
        return
    name = file_name(c)
    if c.label(4) != "APPEND" or name not in listing.files:
        listing.files[name] = []
    listing.target = name


@command("*CFOPEN", ANY, 4)
def cfopen(s: SessionState, c: Call) -> None:
    name = file_name(c, "" if c.given(1) else "cmd")
    if c.label(4) != "APPEND" or name not in s.listing.files:
        s.listing.files[name] = []
    s.listing.command_file = name


@command("*CFWRITE", ANY, 40)
def cfwrite(s: SessionState, c: Call) -> None:
    """*CFWRITE,Command,...: the command written, not run; as MAPDL documents, numeric
    parameters and expressions in its fields are replaced by their values (labels such as
    ALL or TEMP, quoted text and an assignment stay as written)."""
    if s.listing.command_file is None:
        raise ApdlError("no command file is open (*CFOPEN first)")
    fields = list(c.statement.fields)
    text = c.statement.text.split(",", 1)[1] if "," in c.statement.text else ""
    if fields and "=" not in text:
        for i, field in enumerate(fields[1:], start=1):
            if not field or is_text(field):
                continue
            try:
                fields[i] = f"{compile_expression(field)(s.params, s.model_functions):.10g}"
            except ApdlError:
                pass  # a label: written as it is
        text = ",".join(fields)
    s.listing.files[s.listing.command_file].append(text.rstrip())


@command("*CFCLOS", ANY, 0)
def cfclos(s: SessionState, c: Call) -> None:
    s.listing.command_file = None


@command("*LIST", ANY, 3)
def star_list(s: SessionState, c: Call) -> None:
    """*LIST,Fname,Ext: a file this deck wrote, copied into the output."""
    name = file_name(c)
    lines = s.listing.files.get(name)
    if lines is None:
        raise ApdlError(f"file {name!r} was not written by this run")
    for line in list(lines):
        s.say(line)


@command("*STATUS", ANY, 5)
def star_status(s: SessionState, c: Call) -> None:
    """*STATUS[,Par]: parameters, their type and value or dimensions."""
    wanted = c.raw(1).upper()
    s.say("PARAMETER STATUS")
    s.say(f"{'NAME':<32} {'VALUE':>20}  TYPE")
    for name, value in sorted(s.params.items()):
        if wanted and wanted != "ALL" and name != wanted:
            continue
        if isinstance(value, np.ndarray):
            kind = "CHARACTER ARRAY" if value.dtype == object else "ARRAY"
            dims = " x ".join(str(n) for n in value.shape)
            s.say(f"{name:<32} {dims:>20}  {kind}")
        elif isinstance(value, str):
            s.say(f"{name:<32} {value:>20}  CHARACTER")
        else:
            s.say(f"{name:<32} {value:>20.10G}  SCALAR")


@command("SAVE", ANY, 4)
def save(s: SessionState, c: Call) -> None:
    """SAVE,Fname,Ext: a copy of the database and parameters, in memory."""
    s.saved[file_name(c, "db")] = (copy.deepcopy(s.db), copy.deepcopy(s.params))


@command("RESUME", ANY, 4)
def resume(s: SessionState, c: Call) -> None:
    name = file_name(c, "db")
    saved = s.saved.get(name)
    if saved is None:
        raise ApdlError(f"{name!r} was never saved in this run (SAVE first)")
    s.db, s.params = copy.deepcopy(saved[0]), copy.deepcopy(saved[1])


@command("*SET", ANY, 11)
def star_set_values(s: SessionState, c: Call) -> None:
    """*SET,Par,v1[,v2,...]: a scalar or character value, or values down an array column."""
    name, subs_text = split_target(c.raw(1))
    params, funcs = s.params, s.model_functions
    if not c.given(2) and not subs_text:
        params.pop(name, None)
        return
    values = [value_of(c.raw(i), params, funcs) for i in range(2, c.count() + 1)]
    store(params, name, subscripts(subs_text, params, funcs) if subs_text else [], values)


# *MSG labels: the heading MAPDL writes above the message (INFO: none)
MSG_HEADINGS = {"INFO": "", "NOTE": "NOTE", "UI": "NOTE", "WARN": "WARNING", "ERROR": "ERROR",
                "FATAL": "FATAL ERROR"}


@command("*MSG", ANY, 9)
def star_msg(s: SessionState, c: Call) -> None:
    """*MSG,Lab,VAL1,...,VAL8 and its format line(s): the message under its heading in the
    current output (the /OUT file, else the log).  WARN and ERROR are told on stderr too
    and ERROR counted (the run goes on, as in MAPDL batch); FATAL stops the run here."""
    from apdl_like.fortran_format import c_descriptors, format_c_line, normal_descriptors

    label = c.label(1, "INFO")
    if label not in MSG_HEADINGS:
        raise ApdlError(f"field 1 (Lab) must be one of {', '.join(MSG_HEADINGS)}, got {label!r}")
    params = s.params
    values: list[float | str] = []
    last = max((i for i in range(2, c.count() + 1) if c.given(i)), default=1)
    for i in range(2, last + 1):
        text = c.raw(i).strip()
        named = text.upper()
        if is_text(text):
            values.append(text[1:-1])
        elif is_parameter_name(named) and isinstance(params.get(named), str):
            values.append(params[named])  # a character parameter
        else:
            values.append(c.num(i, 0.0, f"VAL{i - 1}"))
    # the format: its lines joined where each ends in '&'
    fmt = "".join(line.rstrip()[:-1] if line.rstrip().endswith("&") else line
                  for line in c.statement.block)
    wanted = c_descriptors(fmt)
    if wanted != len(values):
        raise ApdlError(f"the format has {wanted} data descriptor(s) (%I, %G, %C, ...) for "
                        f"{len(values)} value(s)")
    lines = format_c_line(fmt, values, bare_fortran=True)
    if normal_descriptors(fmt):
        # MAPDL: "If normal descriptions are used, then consecutive blanks are condensed
        # into one blank upon output, and a period is appended" (the message's last line;
        # after its last non-blank character)
        lines = [re.sub(" {2,}", " ", line) for line in lines]
        lines[-1] = lines[-1].rstrip() + "."
    heading = MSG_HEADINGS[label]
    one_line = " ".join(" ".join(lines).split())  # for stderr and the error
    if label == "FATAL":
        raise ApdlError(f"FATAL: {one_line}")
    # MAPDL's message subroutine writes to the current output: the /OUT file when one is
    # open, else the log (a *CFOPEN command file takes *VWRITE and *CFWRITE lines only)
    if heading:
        s.say(f" *** {heading} ***")
    for line in lines:
        s.say(line)
    if label in ("WARN", "ERROR"):
        st = c.statement
        if label == "ERROR":
            s.listing.errors += 1
        s.listing.warnings.append(f"{heading.lower()}: {st.file}:{st.line}: *MSG: {one_line}")


COMMANDS = (
    *specs_of(star_dim, star_vfill, star_vwrite, star_voper, star_vscfun, star_msg, out,
              cfopen, cfwrite, cfclos, star_list, star_status, save, resume, star_set_values),
    CommandSpec("/OUTPUT", ANY, 4, out),
    *(CommandSpec(name, ANY, 10, _vector_control)
      for name in ("*VLEN", "*VMASK", "*VABS", "*VFACT", "*VCUM")),
)
