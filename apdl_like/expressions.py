"""A small, hand-written evaluator for APDL numeric expressions (no `eval`).

Grammar (APDL/Fortran precedence; `**` binds tighter than unary minus, so -2**2 = -4)::

    expr  := term (("+" | "-") term)*
    term  := unary (("*" | "/") unary)*
    unary := ("+" | "-") unary | power
    power := atom ("**" unary)?              right-associative
    atom  := NUMBER | NAME | NAME "(" expr ("," expr)* ")" | "(" expr ")"

Numbers take any float notation, including Fortran's `1.5D3`.  Names are parameters
(case-insensitive; `_NAME` too, MAPDL's hidden ones); `NAME(i[,j[,k]])` is an element of an
array parameter (1-based) unless NAME is a function.  A parameter may share a name with a
model function (`*GET,TEMP,...` then `TEMP/28`): without parentheses it is the parameter.
Functions: ABS SQRT EXP LOG LOG10 SIN COS TAN ASIN ACOS ATAN ATAN2 MIN
MAX SIGN NINT MOD (radians), plus model functions such as NX(n), NY(n), NODE(x,y,z) that the
caller supplies at evaluation time.  Text is compiled once into closures (cached), so a deck
that runs every 60 s pays the parse only once.

Limits stop runaway input: expression length and nesting depth.  Every failure is an
`ApdlError` with a plain message; the caller adds file:line and the command.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping
from functools import lru_cache
from typing import TYPE_CHECKING

from apdl_like.errors import ApdlError
from apdl_like.table_array import TableArray, table_index, table_value

if TYPE_CHECKING:
    import numpy as np

MAX_EXPRESSION_CHARS = 640  # the APDL command-line length
MAX_DEPTH = 32  # nesting of parentheses, unary signs and function calls
MAX_NAME_CHARS = 32  # APDL parameter-name length

ModelFunction = Callable[..., float]
Evaluator = Callable[[Mapping[str, float], Mapping[str, ModelFunction]], float]

_TOKEN = re.compile(
    r"\s*(?:"
    r"(?P<num>(?:\d+\.?\d*|\.\d+)(?:[eEdD][+-]?\d+)?)"
    r"|(?P<name>[A-Za-z_][A-Za-z0-9_]*)"
    r"|(?P<op>\*\*|[-+*/(),])"
    r")"
)
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")


def _sign(a: float, b: float) -> float:
    return math.copysign(abs(a), b)


def nint(a: float) -> float:
    # Fortran NINT: halves away from zero (Python's round() would go to even).
    return float(math.floor(abs(a) + 0.5)) * (1.0 if a >= 0 else -1.0)


# name -> (function, minimum arguments, maximum arguments)
BUILTINS: dict[str, tuple[Callable[..., float], int, int]] = {
    "ABS": (abs, 1, 1),
    "SQRT": (math.sqrt, 1, 1),
    "EXP": (math.exp, 1, 1),
    "LOG": (math.log, 1, 1),
    "LOG10": (math.log10, 1, 1),
    "SIN": (math.sin, 1, 1),
    "COS": (math.cos, 1, 1),
    "TAN": (math.tan, 1, 1),
    "ASIN": (math.asin, 1, 1),
    "ACOS": (math.acos, 1, 1),
    "ATAN": (math.atan, 1, 1),
    "ATAN2": (math.atan2, 2, 2),
    "SINH": (math.sinh, 1, 1),
    "COSH": (math.cosh, 1, 1),
    "TANH": (math.tanh, 1, 1),
    "MIN": (min, 1, 20),
    "MAX": (max, 1, 20),
    "SIGN": (_sign, 2, 2),
    "NINT": (nint, 1, 1),
    "MOD": (math.fmod, 2, 2),
}

# Functions answered by the model (nodes, results); arity is checked at compile time.
MODEL_FUNCTIONS: dict[str, tuple[int, int]] = {
    "NX": (1, 1),
    "NY": (1, 1),
    "NZ": (1, 1),
    "NODE": (2, 3),
    "TEMP": (1, 1),
    "UX": (1, 1),
    "UY": (1, 1),
}



def _tokenize(text: str) -> list[tuple[str, str]]:
    tokens: list[tuple[str, str]] = []
    pos = 0
    end = len(text.rstrip())
    while pos < end:
        m = _TOKEN.match(text, pos)
        if m is None or m.end() == pos:
            bad = text[pos:].strip()[:1]
            raise ApdlError(f"unexpected character {bad!r} in expression {text.strip()!r}")
        kind = m.lastgroup
        assert kind is not None
        tokens.append((kind, m.group(kind)))
        pos = m.end()
    return tokens


def is_parameter_name(name: str) -> bool:
    """A valid user parameter name: letter first, letters/digits/_, ≤ 32 chars, not a function."""
    return (
        bool(_NAME.match(name))
        and len(name) <= MAX_NAME_CHARS
        and name.upper() not in BUILTINS
    )


class _Parser:
    def __init__(self, text: str) -> None:
        self.text = text.strip()
        self.tokens = _tokenize(text)
        self.i = 0
        self.depth = 0

    def fail(self, what: str) -> ApdlError:
        return ApdlError(f"{what} in expression {self.text!r}")

    def peek(self) -> tuple[str, str] | None:
        return self.tokens[self.i] if self.i < len(self.tokens) else None

    def take(self) -> tuple[str, str]:
        tok = self.peek()
        if tok is None:
            raise self.fail("unexpected end")
        self.i += 1
        return tok

    def expect(self, op: str) -> None:
        tok = self.peek()
        if tok != ("op", op):
            raise self.fail(f"expected {op!r}")
        self.i += 1

    def enter(self) -> None:
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise self.fail(f"nesting deeper than {MAX_DEPTH}")

    def parse(self) -> Evaluator:
        if not self.tokens:
            raise ApdlError("empty expression")
        node = self.expr()
        if self.peek() is not None:
            raise self.fail(f"unexpected {self.peek()[1]!r}")  # type: ignore[index]
        return node

    def _left_associative(self, ops: tuple[str, ...],
                          operand: Callable[[], Evaluator]) -> Evaluator:
        """operand (op operand)*, folded from the left: a - b - c is (a - b) - c."""
        node = operand()
        while (tok := self.peek()) is not None and tok[0] == "op" and tok[1] in ops:
            self.i += 1
            node = _binary(tok[1], node, operand())
        return node

    def expr(self) -> Evaluator:
        return self._left_associative(("+", "-"), self.term)

    def term(self) -> Evaluator:
        return self._left_associative(("*", "/"), self.unary)

    def unary(self) -> Evaluator:
        tok = self.peek()
        if tok in (("op", "-"), ("op", "+")):
            self.i += 1
            self.enter()
            inner = self.unary()
            self.depth -= 1
            if tok[1] == "+":  # type: ignore[index]
                return inner
            return _negate(inner)
        return self.power()

    def power(self) -> Evaluator:
        base = self.atom()
        if self.peek() == ("op", "**"):
            self.i += 1
            self.enter()
            exponent = self.unary()
            self.depth -= 1
            return _binary("**", base, exponent)
        return base

    def atom(self) -> Evaluator:
        kind, value = self.take()
        if kind == "num":
            number = float(value.replace("d", "e").replace("D", "e"))
            if not math.isfinite(number):
                raise self.fail(f"number {value} out of range")
            return _constant(number)
        if kind == "name":
            name = value.upper()
            if self.peek() == ("op", "("):
                self.i += 1
                self.enter()
                args = [self.expr()]
                while self.peek() == ("op", ","):
                    self.i += 1
                    args.append(self.expr())
                self.expect(")")
                self.depth -= 1
                return self.call(name, args)
            if name in BUILTINS:
                raise self.fail(f"function {name} needs arguments")
            if len(name) > MAX_NAME_CHARS:
                raise self.fail(f"parameter name {value!r} longer than {MAX_NAME_CHARS}")
            return _parameter(name)
        if (kind, value) == ("op", "("):
            self.enter()
            node = self.expr()
            self.expect(")")
            self.depth -= 1
            return node
        raise self.fail(f"unexpected {value!r}")

    def call(self, name: str, args: list[Evaluator]) -> Evaluator:
        if name in BUILTINS:
            func, lo, hi = BUILTINS[name]
            if not lo <= len(args) <= hi:
                raise self.fail(f"{name} takes {_arity(lo, hi)}, got {len(args)}")
            return _builtin_call(name, func, args)
        if name in MODEL_FUNCTIONS:
            lo, hi = MODEL_FUNCTIONS[name]
            if not lo <= len(args) <= hi:
                raise self.fail(f"{name} takes {_arity(lo, hi)}, got {len(args)}")
            return _model_call(name, args)
        if len(args) > 3:
            raise self.fail(f"array {name} takes 1 to 3 subscripts, got {len(args)}")
        return _array_element(name, args)


def _arity(lo: int, hi: int) -> str:
    return f"{lo} argument{'s' if lo > 1 else ''}" if lo == hi else f"{lo} to {hi} arguments"


def _constant(value: float) -> Evaluator:
    def const(params: Mapping[str, float], funcs: Mapping[str, ModelFunction]) -> float:
        return value

    const.constant = value  # type: ignore[attr-defined]
    return const


def _parameter(name: str) -> Evaluator:
    def param(params: Mapping[str, float], funcs: Mapping[str, ModelFunction]) -> float:
        try:
            value = params[name]
        except KeyError:
            raise ApdlError(f"undefined parameter {name}") from None
        if isinstance(value, float):
            return value
        if isinstance(value, str):
            raise ApdlError(f"{name} is a character parameter (a number is needed here)")
        if isinstance(value, int):
            return float(value)
        raise ApdlError(f"{name} is an array: give its subscripts, {name}(i,j)")

    return param


def _array_element(name: str, args: list[Evaluator]) -> Evaluator:
    def element(params: Mapping[str, float], funcs: Mapping[str, ModelFunction]) -> float:
        array = params.get(name)
        if array is None:
            raise ApdlError(f"unknown function or array {name}")
        return array_value(name, array, [a(params, funcs) for a in args])

    return element


def array_value(name: str, array: object, subscripts: list[float]) -> float:
    """NAME(i, j, k) of a numeric array parameter (1-based subscripts, missing ones 1)."""
    if not hasattr(array, "shape"):
        raise ApdlError(f"{name} is not an array parameter")
    if isinstance(array, TableArray):
        return table_value(name, array, subscripts)
    index = array_index(name, array.shape, subscripts)  # type: ignore[attr-defined]
    value = array[index]  # type: ignore[index]
    if isinstance(value, str):
        raise ApdlError(f"{name} is a character array (a number is needed here)")
    return float(value)


def element_index(name: str, array: np.ndarray, subscripts: list[float]) -> tuple[int, ...]:
    """0-based storage index of the element `NAME(i, j, k)` an assignment or *VWRITE names
    (a TABLE's index row and column are subscripts 0)."""
    if isinstance(array, TableArray):
        return table_index(name, array, subscripts)
    return array_index(name, array.shape, subscripts)


def array_index(name: str, shape: tuple[int, ...], subscripts: list[float]) -> tuple[int, ...]:
    """0-based index of `NAME(i, j, k)`; an ApdlError names the subscript out of range."""
    out = []
    for axis, size in enumerate(shape):
        sub = subscripts[axis] if axis < len(subscripts) else 1.0
        i = int(round(sub))
        if abs(sub - i) > 1e-9 or not 1 <= i <= size:
            raise ApdlError(f"subscript {axis + 1} of {name} is {sub:g}, outside 1..{size}")
        out.append(i - 1)
    return tuple(out)


def _negate(inner: Evaluator) -> Evaluator:
    c = getattr(inner, "constant", None)
    if c is not None:
        return _constant(-c)

    def neg(params: Mapping[str, float], funcs: Mapping[str, ModelFunction]) -> float:
        return -inner(params, funcs)

    return neg


def _power(a: float, b: float) -> float:
    try:
        return math.pow(a, b)
    except ValueError:
        raise ApdlError(f"{a!r}**{b!r} is not a real number") from None
    except OverflowError:
        raise ApdlError(f"{a!r}**{b!r} overflows") from None


def _divide(a: float, b: float) -> float:
    if b == 0.0:
        raise ApdlError("division by zero")
    return a / b


_OPS: dict[str, Callable[[float, float], float]] = {
    "+": lambda a, b: a + b,
    "-": lambda a, b: a - b,
    "*": lambda a, b: a * b,
    "/": _divide,
    "**": _power,
}


def _binary(op: str, left: Evaluator, right: Evaluator) -> Evaluator:
    f = _OPS[op]
    a, b = getattr(left, "constant", None), getattr(right, "constant", None)
    if a is not None and b is not None:
        return _constant(_finite(f(a, b)))

    def binop(params: Mapping[str, float], funcs: Mapping[str, ModelFunction]) -> float:
        return f(left(params, funcs), right(params, funcs))

    return binop


# *AFUN,DEG: the model-function mapping holds this key, a function giving the radians in
# one unit of angle (π/180); the trig functions take their argument, and the inverse ones
# give their result, in that unit.  Without it they are in radians, MAPDL's default.
ANGLE_UNIT = "*AFUN"
_ANGLE_ARGUMENT = ("SIN", "COS", "TAN")
_ANGLE_RESULT = ("ASIN", "ACOS", "ATAN", "ATAN2")


def _builtin_call(name: str, func: Callable[..., float], args: list[Evaluator]) -> Evaluator:
    angle_in, angle_out = name in _ANGLE_ARGUMENT, name in _ANGLE_RESULT

    def call(params: Mapping[str, float], funcs: Mapping[str, ModelFunction]) -> float:
        values = [a(params, funcs) for a in args]
        unit = funcs.get(ANGLE_UNIT) if angle_in or angle_out else None
        try:
            if unit is not None:
                if angle_in:
                    return float(func(values[0] * unit()))
                return float(func(*values)) / unit()
            return float(func(*values))
        except (ValueError, ZeroDivisionError):
            shown = ", ".join(repr(v) for v in values)
            raise ApdlError(f"{name}({shown}) is undefined") from None
        except OverflowError:
            raise ApdlError(f"{name} overflows") from None

    return call


def _model_call(name: str, args: list[Evaluator]) -> Evaluator:
    def call(params: Mapping[str, float], funcs: Mapping[str, ModelFunction]) -> float:
        values = [a(params, funcs) for a in args]
        func = funcs.get(name)
        if func is None:
            raise ApdlError(f"{name}() needs a model, none is defined here")
        return float(func(*values))

    return call


def _finite(value: float) -> float:
    if not math.isfinite(value):
        raise ApdlError("result is not a finite number")
    return value


@lru_cache(maxsize=8192)
def compile_expression(text: str) -> Evaluator:
    """Compile expression text to a function `f(params, model_functions) -> float`."""
    if len(text) > MAX_EXPRESSION_CHARS:
        raise ApdlError(f"expression longer than {MAX_EXPRESSION_CHARS} characters")
    compiled = _Parser(text).parse()
    if getattr(compiled, "constant", None) is not None:
        return compiled

    def checked(params: Mapping[str, float], funcs: Mapping[str, ModelFunction]) -> float:
        return _finite(compiled(params, funcs))

    return checked


def evaluate(
    text: str,
    params: Mapping[str, float] | None = None,
    functions: Mapping[str, ModelFunction] | None = None,
) -> float:
    """Evaluate an APDL expression; names are looked up upper-case in `params`."""
    return compile_expression(text)(params or {}, functions or {})
