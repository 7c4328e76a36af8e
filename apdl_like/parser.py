"""Lexing an APDL deck into statements (APDL conventions, case-insensitive).

One line is one statement: a command with comma-separated fields (`D,ALL,TEMP,20`; empty
fields allowed, `NSEL,S,LOC,X,,0.1`), or a parameter assignment `NAME = expr` or
`NAME(i,j) = v1, v2, ...` (array elements down a column).  `!` starts a comment, and so does
a line starting with `C***` (MAPDL's old comment card); `/COM` and `/TITLE` keep the rest of
the line as text; text in single quotes is a character value (commas and `!` inside it are
text).  Fields stay text here; the command that uses a field decides whether it is a label,
an expression or a character value.  `*VWRITE`/`*MWRITE` carry their format line.

A line that cannot be lexed becomes a `BAD_LINE` statement holding the message, so a bad line
stops the deck where it stands, not before the lines ahead of it have run.  Blocks
(`*DO/*ENDDO`, `*DOWHILE/*ENDDO`, `*IF/*ELSEIF/*ELSE/*ENDIF`) are matched up front; a block
that does not close truncates the program at its opening line, with the error raised there.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

from apdl_like.errors import ApdlError
from twin.errors import InputError
from twin.paths import read_input_bytes

MAX_DECK_BYTES = 20_000_000  # far above any real deck; stops accidental binary/huge input
MAX_LINE_CHARS = 640  # the APDL command-line limit
MAX_FIELDS = 40

_ASSIGNMENT = re.compile(r"\s*([A-Za-z_][A-Za-z0-9_]*)\s*(\([^=']*\))?\s*=(?!=)(.*)\Z", re.S)
_COMMAND_NAME = re.compile(r"[/*]?[A-Za-z][A-Za-z0-9_\-]*\Z")
_TEXT_COMMANDS = ("/COM", "/TITLE", "/STITLE", "/EOF")


# The name of a statement that stands for a line the parser refused. It starts with "!",
# which begins a comment in APDL, so no deck line can produce it as a command name (a user
# command spelled ERROR is an ordinary unknown command).
BAD_LINE = "!BAD_LINE"


@dataclass(frozen=True, slots=True)
class Statement:
    """A command or an assignment, where it came from and its text fields."""

    file: str
    line: int
    name: str  # upper-case command name, "=" for an assignment, BAD_LINE for a bad line
    # text after the name, split at commas; an assignment: (name, subscripts text, value 1,
    # value 2, ...); BAD_LINE: (message, command shown)
    fields: tuple[str, ...]
    text: str = ""  # the raw line (for /COM, /TITLE and messages)
    # NBLOCK/EBLOCK/CMBLOCK: the format line and the data lines; *VWRITE: the format line
    block: tuple[str, ...] = ()

    def error(self, message: str) -> ApdlError:
        return ApdlError(message, file=self.file, line=self.line, command=self.shown)

    @property
    def shown(self) -> str:
        if self.name == BAD_LINE:
            return self.fields[1]
        if self.name == "=":
            # the assignment as the user wrote it (`B=A*2`, not `B=`), comment left out
            written = _strip_comment(self.text).strip()
            return written if written else f"{self.fields[0]}="
        return self.name


@dataclass(slots=True)
class Program:
    """The statements of one file and its matched blocks (indices into `statements`)."""

    file: str
    statements: list[Statement]
    block_end: dict[int, int] = field(default_factory=dict)  # *DO / *IF index -> *ENDDO/*ENDIF
    if_branches: dict[int, list[int]] = field(default_factory=dict)  # *IF -> [*ELSEIF.., *ELSE]
    enclosing_do: dict[int, int] = field(default_factory=dict)  # *EXIT/*CYCLE -> its *DO


def _strip_comment(line: str) -> str:
    # A `!` inside single quotes (a character value) is text, not a comment.
    if "!" not in line:
        return line
    quoted = False
    for i, ch in enumerate(line):
        if ch == "'":
            quoted = not quoted
        elif ch == "!" and not quoted:
            return line[:i]
    return line


def commands_on(line: str) -> list[str]:
    """The commands of one deck line: MAPDL runs `A $ B` as two.  A `$` inside quotes, in
    a `!` comment or in a text command's text (/COM, /TITLE, C***) separates nothing."""
    if "$" not in line:
        return [line]
    head = line.lstrip().upper()
    if head.startswith(("C***", *_TEXT_COMMANDS)):
        return [line]
    return split_fields(_strip_comment(line), separators="$")


def split_fields(body: str, separators: str = ",", kept: str = "") -> list[str]:
    """Split at commas outside parentheses and quotes: `*GET,T,NODE,NODE(0.1,0),TEMP` has 5
    fields, `L(1) = 'T,F(AT X','q'` has 2 values.  Other `separators` may split too; those
    also in `kept` stay as items of their own (a Fortran format's `/`)."""
    parts, depth, start, quoted = [], 0, 0, False
    for i, ch in enumerate(body):
        if ch == "'":
            quoted = not quoted
        elif quoted:
            continue
        elif ch == "(":
            depth += 1
        elif ch == ")":
            depth = max(depth - 1, 0)
        elif ch in separators and depth == 0:
            parts.append(body[start:i])
            if ch in kept:
                parts.append(ch)
            start = i + 1
    parts.append(body[start:])
    return parts


def lex_line(raw: str, file: str, number: int) -> Statement | None:
    """One deck line -> a statement, or None for blank and comment lines."""
    try:
        lexed = _lex(raw)
    except ApdlError as exc:
        lexed = (BAD_LINE, (exc.reason, exc.command or ""))
    if lexed is None:
        return None
    return Statement(file, number, lexed[0], lexed[1], raw)


@lru_cache(maxsize=8192)
def _lex(raw: str) -> tuple[str, tuple[str, ...]] | None:
    """(name, fields) of one line; cached because a window deck repeats most of its lines."""
    if len(raw) > MAX_LINE_CHARS:
        raise ApdlError(f"line longer than {MAX_LINE_CHARS} characters")
    head = raw.lstrip()
    upper = head[:7].upper()
    if upper.startswith("C***"):
        return None
    for text_cmd in _TEXT_COMMANDS:
        n = len(text_cmd)
        if upper.startswith(text_cmd) and (len(head) == n or head[n] in ", \t"):
            rest = head[len(text_cmd) :]
            rest = rest.lstrip(" \t")[1:] if rest.lstrip(" \t").startswith(",") else \
                rest.strip()
            return text_cmd, (rest.rstrip(),)
    body = _strip_comment(raw).strip()
    if not body:
        return None
    if "\x00" in body:
        raise ApdlError("binary data in deck")
    m = _ASSIGNMENT.match(body)
    if m is not None and "," not in body[: m.start(1) if m.group(2) is None else m.end(1)]:
        subscripts = (m.group(2) or "").strip()[1:-1].strip()
        values = split_fields(m.group(3)) if "," in m.group(3) else [m.group(3)]
        return "=", (m.group(1).upper(), subscripts, *(v.strip() for v in values))
    parts = split_fields(body) if "(" in body or "'" in body else body.split(",")
    name = parts[0].strip().upper()
    if not _COMMAND_NAME.match(name):
        shown = parts[0].strip() or "(empty)"
        raise ApdlError(f"not a command or assignment: {shown!r}")
    if len(parts) - 1 > MAX_FIELDS:
        raise ApdlError(f"more than {MAX_FIELDS} fields", command=name)
    return name, tuple(p.strip() for p in parts[1:])


def _match_blocks(program: Program) -> None:
    stack: list[tuple[str, int]] = []  # ("DO"|"IF", index)
    for i, st in enumerate(program.statements):
        name = st.name
        if name in ("*DO", "*DOWHILE"):
            stack.append(("DO", i))
        elif name == "*IF" and _if_is_block(st):
            stack.append(("IF", i))
            program.if_branches[i] = []
        elif name in ("*ELSEIF", "*ELSE"):
            if not stack or stack[-1][0] != "IF":
                raise st.error(f"{name} without an open *IF")
            branches = program.if_branches[stack[-1][1]]
            if branches and program.statements[branches[-1]].name == "*ELSE":
                raise st.error(f"{name} after *ELSE")
            branches.append(i)
        elif name in ("*ENDDO", "*ENDIF"):
            kind = name[4:]
            if not stack or stack[-1][0] != kind:
                open_block = (f"*{stack[-1][0]} of line {program.statements[stack[-1][1]].line}"
                              if stack else "no block")
                raise st.error(f"{name} does not close an open *{kind} ({open_block} is open)")
            program.block_end[stack.pop()[1]] = i
        elif name in ("*EXIT", "*CYCLE") or (name == "*IF" and not _if_is_block(st)):
            dos = [j for kind, j in stack if kind == "DO"]
            if name != "*IF" and not dos:
                raise st.error(f"{name} outside a *DO loop")
            if dos:
                program.enclosing_do[i] = dos[-1]
    if stack:
        kind, j = stack[-1]
        raise program.statements[j].error(f"*{kind} block is never closed (no *END{kind})")


def _if_is_block(st: Statement) -> bool:
    """`*IF,V1,OP,V2,THEN` or `*IF,V1,OP,V2,AND|OR|XOR,V3,OP,V4,THEN`."""
    f = [x.upper() for x in st.fields]
    action = f[7] if len(f) > 3 and f[3] in ("AND", "OR", "XOR") and len(f) > 7 else \
        (f[3] if len(f) > 3 else "")
    return action == "THEN"


BLOCK_COMMANDS = ("NBLOCK", "EBLOCK", "CMBLOCK")
FORMAT_COMMANDS = ("*VWRITE", "*MWRITE", "*VREAD", "*MSG")  # the next line is their format
_DATA_COMMANDS = frozenset((*BLOCK_COMMANDS, *FORMAT_COMMANDS))  # data or format follows
MAX_BLOCK_LINES = 5_000_000
MAX_MSG_LINES = 10  # a *MSG format and its '&' continuations, as MAPDL reads them


def _block_lines(st: Statement, lines: list[str], start: int) -> tuple[tuple[str, ...], int]:
    """The format line and data lines that follow a block command (archive format).

    NBLOCK ends at `N,R5.3,LOC,...` or `-1`, EBLOCK at `-1`; CMBLOCK holds its count of
    numbers, eight per line.
    """
    if start >= len(lines) or not lines[start].lstrip().startswith("("):
        raise st.error("the block must be followed by its format line, e.g. (3i9,6e21.13e3)")
    out = [lines[start]]
    i = start + 1
    if st.name == "CMBLOCK":
        try:
            count = int(st.fields[2])
        except (IndexError, ValueError):
            raise st.error("field 3 (count of numbers) must be an integer") from None
        if not 0 <= count <= 8 * MAX_BLOCK_LINES:
            raise st.error(f"field 3 (count) out of range: {count}")
        n = -(-count // 8)
        if i + n > len(lines):
            raise st.error(f"the block ends early: {n} data lines expected")
        out += lines[i : i + n]
        return tuple(out), 1 + n
    while i < len(lines):
        line = lines[i]
        head = line.strip().upper()
        if head.startswith("N,R5.3,LOC") or head == "-1" or head.startswith("-1 "):
            return tuple(out), i - start + 1
        out.append(line)
        i += 1
        if len(out) > MAX_BLOCK_LINES:
            raise st.error("the block is too long")
    raise st.error("the block is never terminated (-1)")


def parse_deck(text: str, file: str = "<deck>") -> Program:
    """Lex a whole deck and match its blocks; raises ApdlError with file:line."""
    if len(text) > MAX_DECK_BYTES:
        raise ApdlError(f"deck larger than {MAX_DECK_BYTES // 1_000_000} MB", file=file)
    statements = []
    lines = text.splitlines()
    number = 0
    queued: list[str] = []  # the further commands of a line with `$`
    open_blocks = 0  # *DO and *IF,...,THEN not yet closed: /EOF inside one runs when reached
    while queued or number < len(lines):
        if not queued:
            queued = commands_on(lines[number])
            number += 1
        raw = queued.pop(0)
        st = lex_line(raw, file, number)
        if st is None:
            continue
        if st.name == "/EOF" and open_blocks <= 0:
            break  # the file ends here; what follows is never read
        if st.name in ("*DO", "*DOWHILE") or (st.name == "*IF" and _if_is_block(st)):
            open_blocks += 1
        elif st.name in ("*ENDDO", "*ENDIF"):
            open_blocks -= 1
        if st.name not in _DATA_COMMANDS:
            statements.append(st)
            continue
        if queued:
            # its data or format are the next lines, not the rest of this one
            statements.append(Statement(file, st.line, BAD_LINE, (
                "no command may follow it after '$': its data lines come next", st.name)))
            break
        if st.name in BLOCK_COMMANDS:
            try:
                data, used = _block_lines(st, lines, number)
            except ApdlError as exc:
                statements.append(Statement(file, st.line, BAD_LINE, (exc.reason, st.name)))
                break
            st = Statement(st.file, st.line, st.name, st.fields, st.text, data)
            number += used
        elif st.name in FORMAT_COMMANDS:
            if number >= len(lines):
                statements.append(Statement(file, st.line, BAD_LINE,
                                            ("the format line is missing", st.name)))
                break
            block = [lines[number]]
            number += 1
            # *MSG: a format line ending in '&' goes on on the next line (10 lines at most)
            while (st.name == "*MSG" and block[-1].rstrip().endswith("&")
                   and len(block) < MAX_MSG_LINES and number < len(lines)):
                block.append(lines[number])
                number += 1
            st = Statement(st.file, st.line, st.name, st.fields, st.text, tuple(block))
        statements.append(st)
    program = Program(file, statements)
    try:
        _match_blocks(program)
    except ApdlError as exc:
        # run what comes before the bad block, then stop there with its message
        bad = next(i for i, st in enumerate(statements) if st.line == exc.line)
        program = Program(file, statements[:bad] + [
            Statement(file, statements[bad].line, BAD_LINE, (exc.reason, exc.command or ""))])
        _match_blocks(program)
    return program


def read_deck(path: Path, shown: str | None = None) -> Program:
    """Read and parse a deck file: a regular file of at most `MAX_DECK_BYTES`, checked
    before a byte is read and refused in the words of every input of the twin
    (`twin.paths.read_input_bytes`)."""
    name = shown or str(path)
    try:
        data = read_input_bytes(path, max_bytes=MAX_DECK_BYTES)
    except InputError as exc:
        raise ApdlError(exc.reason, file=name) from None
    try:
        text = data.decode("utf-8-sig")  # a Windows editor's byte-order mark is no command
    except UnicodeDecodeError:
        text = data.decode("latin-1")  # decks from old tools; every byte decodes
    return parse_deck(text, name)
