"""A small, safe expression language for design targets over performance columns.

Examples of valid targets::

    axialstiff60 < 6000
    Zstiff > 800 & Xstiff > 600 & error < 0.1
    700 < bendstiff90 < 1600
    Zsnap == 1 | (Zstiff > 3e3 & error <= .08)
    `axial stiff` >= 1.5e4

Grammar (``&`` binds tighter than ``|``)::

    expr       := and_expr ("|" and_expr)*
    and_expr   := atom ("&" atom)*
    atom       := "(" expr ")" | comparison
    comparison := operand (OP operand)+          # chained: a < b < c means a < b & b < c
    operand    := NUMBER | ["+" | "-"] NUMBER | NAME | `quoted name`
    OP         := "<" | "<=" | ">" | ">=" | "==" | "!="

Every comparison chain must involve at least one column. The expression is tokenised and
parsed by hand (recursive descent); nothing is ever passed to ``eval`` or ``DataFrame.query``.
"""

from __future__ import annotations

import operator
import re
from dataclasses import dataclass, field

import numpy as np

__all__ = ["TargetError", "Target", "Reach", "parse_target"]


class TargetError(ValueError):
    """A target expression is malformed or names an unknown column."""


_OPS = {
    "<": operator.lt,
    "<=": operator.le,
    ">": operator.gt,
    ">=": operator.ge,
    "==": operator.eq,
    "!=": operator.ne,
}

_TOKEN_RE = re.compile(
    r"""
    (?P<ws>\s+)
  | (?P<number>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)
  | (?P<name>[A-Za-z_][A-Za-z0-9_.]*)
  | (?P<quoted>`[^`]*`)
  | (?P<op><=|>=|==|!=|<|>)
  | (?P<punct>[&|()+-])
    """,
    re.VERBOSE,
)


@dataclass(frozen=True)
class _Token:
    kind: str  # "number", "name", "op", "punct", "end"
    text: str
    pos: int
    value: object = None


def _tokenize(expr: str) -> list[_Token]:
    tokens: list[_Token] = []
    pos = 0
    while pos < len(expr):
        m = _TOKEN_RE.match(expr, pos)
        if m is None:
            raise TargetError(
                f"unexpected character {expr[pos]!r} at position {pos} in target {expr!r}"
            )
        kind = m.lastgroup
        text = m.group(kind)
        if kind == "number":
            value = float(text)
            if not np.isfinite(value):  # 1e999: inf would render as a column name
                raise TargetError(
                    f"number {text!r} at position {pos} in target {expr!r} is not finite "
                    "(beyond 1.8e308)"
                )
            tokens.append(_Token("number", text, pos, value))
        elif kind == "name":
            tokens.append(_Token("name", text, pos, text))
        elif kind == "quoted":
            name = text[1:-1]
            if not name:
                raise TargetError(f"empty quoted column name at position {pos} in {expr!r}")
            tokens.append(_Token("name", text, pos, name))
        elif kind in ("op", "punct"):
            tokens.append(_Token(kind, text, pos))
        pos = m.end()
    tokens.append(_Token("end", "end of expression", len(expr)))
    return tokens


# ---- syntax tree: plain frozen dataclasses --------------------------------------------------


@dataclass(frozen=True)
class _Column:
    name: str
    pos: int


@dataclass(frozen=True)
class _Number:
    value: float


@dataclass(frozen=True)
class _Compare:
    operands: tuple  # (_Column | _Number, ...), len = len(ops) + 1
    ops: tuple  # (str, ...)


@dataclass(frozen=True)
class _BoolOp:
    op: str  # "&" or "|"
    args: tuple


#: longest target expression accepted, characters (a target is a handful of comparisons)
MAX_LENGTH = 10_000
#: deepest nesting of parentheses accepted (the parser recurses once per level)
MAX_DEPTH = 50


class _Parser:
    def __init__(self, expr: str, tokens: list[_Token]):
        self.expr = expr
        self.tokens = tokens
        self.i = 0
        self.depth = 0

    @property
    def tok(self) -> _Token:
        return self.tokens[self.i]

    def error(self, what: str, tok: _Token | None = None) -> TargetError:
        tok = tok or self.tok
        shown = tok.text if tok.kind == "end" else repr(tok.text)
        return TargetError(f"{what}, got {shown} at position {tok.pos} in target {self.expr!r}")

    def parse(self):
        node = self.parse_or()
        if self.tok.kind != "end":
            raise self.error("expected '&', '|' or the end of the target")
        return node

    def parse_or(self):
        return self.parse_chain("|", self.parse_and)

    def parse_and(self):
        return self.parse_chain("&", self.parse_atom)

    def parse_chain(self, op: str, parse_part):
        """``part (op part)*``: the one part, or their ``_BoolOp`` (``op`` ``|`` or ``&``)."""
        args = [parse_part()]
        while self.tok.kind == "punct" and self.tok.text == op:
            self.i += 1
            args.append(parse_part())
        return args[0] if len(args) == 1 else _BoolOp(op, tuple(args))

    def parse_atom(self):
        if self.tok.kind == "punct" and self.tok.text == "(":
            self.depth += 1
            if self.depth > MAX_DEPTH:
                raise self.error(f"parentheses nested deeper than {MAX_DEPTH} levels")
            self.i += 1
            node = self.parse_or()
            self.depth -= 1
            if not (self.tok.kind == "punct" and self.tok.text == ")"):
                raise self.error("expected ')'")
            self.i += 1
            return node
        start = self.tok
        operands = [self.parse_operand()]
        ops = []
        while self.tok.kind == "op":
            ops.append(self.tok.text)
            self.i += 1
            operands.append(self.parse_operand())
        if not ops:
            raise self.error("expected a comparison operator (<, <=, >, >=, ==, !=)")
        if not any(isinstance(o, _Column) for o in operands):
            raise TargetError(
                f"comparison at position {start.pos} in target {self.expr!r} involves no column"
            )
        return _Compare(tuple(operands), tuple(ops))

    def parse_operand(self):
        tok = self.tok
        if tok.kind == "punct" and tok.text in "+-":
            nxt = self.tokens[self.i + 1]
            if nxt.kind != "number":
                raise self.error("expected a number after the sign", nxt)
            self.i += 2
            return _Number(-nxt.value if tok.text == "-" else nxt.value)
        if tok.kind == "number":
            self.i += 1
            return _Number(tok.value)
        if tok.kind == "name":
            self.i += 1
            return _Column(tok.value, tok.pos)
        raise self.error("expected a column name or a number")


def _columns_of(node, out: list[_Column]) -> None:
    if isinstance(node, _BoolOp):
        for a in node.args:
            _columns_of(a, out)
    elif isinstance(node, _Compare):
        out.extend(o for o in node.operands if isinstance(o, _Column))


def _eval(node, frame) -> np.ndarray:
    if isinstance(node, _BoolOp):
        parts = [_eval(a, frame) for a in node.args]
        func = np.logical_and if node.op == "&" else np.logical_or
        return func.reduce(parts)
    values = [_operand(o, frame) for o in node.operands]
    result = None
    for k, op in enumerate(node.ops):
        part = np.asarray(_OPS[op](values[k], values[k + 1]), dtype=bool)
        result = part if result is None else result & part
    return result


def _operand(o, frame) -> np.ndarray | float:
    return np.asarray(frame[o.name], dtype=float) if isinstance(o, _Column) else o.value


def _text(o) -> str:
    if isinstance(o, _Column):
        return o.name if re.fullmatch(r"[A-Za-z_][A-Za-z0-9_.]*", o.name) else f"`{o.name}`"
    return f"{o.value:g}"


def _pairs(node):
    """The comparisons of a chain, one (left, op, right) per operator."""
    return [(node.operands[k], op, node.operands[k + 1]) for k, op in enumerate(node.ops)]


def _tail_rarity(x: np.ndarray, t: float, up: bool) -> float:
    """Fraction of designs beyond ``t`` (above when ``up``) extrapolated from the top of ``x``
    (finite values, none beyond ``t``) with an exponential tail; see :meth:`Target.reach`."""
    n = len(x)
    if n < 5:
        return float("nan")
    if (x > 0).all() and t > 0:
        x, t = np.log(x), float(np.log(t))
    if not up:
        x, t = -x, -t
    k = max(2, n // 4)
    top = np.sort(x)[::-1][:k]
    beta = (top[0] - top[-1]) / float(np.sum(1.0 / np.arange(1, k)))
    if beta <= 0:
        return 0.0
    return float(k / n * np.exp(-(t - top[-1]) / beta))


def _pair_margin(a, op, b, frame) -> np.ndarray:
    """Signed margin of ``a op b`` per row of ``frame``, normalised by the threshold (>= 0
    where it holds); (len(frame),) even for a pair of two numbers (``1 < 2 < Zstiff``)."""
    va, vb = _operand(a, frame), _operand(b, frame)
    if op in ("==", "!="):
        holds = np.asarray(_OPS[op](va, vb), bool)
        out = np.where(holds, np.inf, -np.inf)
    else:
        ref = vb if isinstance(b, _Number) or not isinstance(a, _Number) else va
        scale = np.abs(np.asarray(ref, dtype=float))
        scale = np.where(scale > 0, scale, 1.0)
        diff = (va - vb) if op in (">", ">=") else (vb - va)
        out = np.asarray(diff / scale, dtype=float)
    return np.broadcast_to(out, (len(frame),))


def _margin(node, frame) -> np.ndarray:
    if isinstance(node, _BoolOp):
        parts = [_margin(a, frame) for a in node.args]
        return (np.minimum if node.op == "&" else np.maximum).reduce(parts)
    return np.minimum.reduce([_pair_margin(a, op, b, frame) for a, op, b in _pairs(node)])


def _conditions(node, out: list) -> None:
    if isinstance(node, _BoolOp):
        for a in node.args:
            _conditions(a, out)
    else:
        out.extend(_pairs(node))


def _has_or(node) -> bool:
    if isinstance(node, _BoolOp):
        return node.op == "|" or any(_has_or(a) for a in node.args)
    return False


def _render(node) -> str:
    if isinstance(node, _BoolOp):
        inner = f" {node.op} ".join(
            f"({_render(a)})" if isinstance(a, _BoolOp) else _render(a) for a in node.args
        )
        return inner
    parts = []
    for k, o in enumerate(node.operands):
        if k:
            parts.append(node.ops[k - 1])
        if isinstance(o, _Column):
            ok = re.fullmatch(r"[A-Za-z_][A-Za-z0-9_.]*", o.name)
            parts.append(o.name if ok else f"`{o.name}`")
        else:
            parts.append(f"{o.value:g}")
    return " ".join(parts)


@dataclass(frozen=True)
class Reach:
    """How far a sample of designs is from one condition of a target.

    Attributes
    ----------
    condition : str
        The comparison, as text (``"axialstiff30 > 33000"``).
    column : str
        Its column.
    threshold : float
        The number it is compared with, in the column's unit.
    best : float
        The sample's value nearest to meeting it (largest for ``>``), in the column's unit.
    meeting : int
        Designs of the sample that meet it.
    rarity : float
        The fraction of designs estimated to meet it: the observed fraction when some do;
        otherwise an extrapolation of the sample's top tail (see :meth:`Target.reach`);
        NaN when it cannot be estimated (fewer than 5 finite values, or a condition between two
        columns).
    """

    condition: str
    column: str
    threshold: float
    best: float
    meeting: int
    rarity: float


@dataclass(frozen=True)
class Target:
    """A parsed target expression.

    Attributes
    ----------
    expression : str
        The source text.
    columns : tuple of str
        The column names used, in order of first appearance.
    """

    expression: str
    columns: tuple[str, ...]
    _tree: object = field(repr=False, compare=False)

    def evaluate(self, frame) -> np.ndarray:
        """Evaluate on a table.

        Parameters
        ----------
        frame : pandas.DataFrame or mapping of str to array of shape (n_rows,)
            Must hold every column of :attr:`columns`.

        Returns
        -------
        ndarray of bool, shape (n_rows,)
            True where the row meets the target (comparisons with NaN are False, except ``!=``).
        """
        available = list(frame.keys())
        missing = [c for c in self.columns if c not in available]
        if missing:
            raise TargetError(
                f"unknown column {missing[0]!r} in target {self.expression!r}; "
                f"available columns: {', '.join(map(str, available))}"
            )
        return np.asarray(_eval(self._tree, frame), dtype=bool)

    def __str__(self) -> str:
        return _render(self._tree)

    @property
    def conditions(self) -> tuple[str, ...]:
        """The single comparisons of the target, as text (``"Zstiff > 100"``), in order."""
        out: list = []
        _conditions(self._tree, out)
        return tuple(f"{_text(a)} {op} {_text(b)}" for a, op, b in out)

    @property
    def conjunctive(self) -> bool:
        """True when every condition must hold (no ``|``): the target is missed whenever one
        condition is."""
        return _has_or(self._tree) is False

    def margins(self, frame) -> dict[str, np.ndarray]:
        """Per condition, the signed margin of every row, normalised by its threshold.

        ``col > t`` gives ``(col - t) / |t|``, ``col < t`` gives ``(t - col) / |t|`` (|t| = 1
        for t = 0): >= 0 where the condition holds, the fraction by which it could change
        before it fails. ``==`` / ``!=`` give +inf where they hold and -inf where not.
        """
        self.evaluate(frame)  # checks the columns
        out: list = []
        _conditions(self._tree, out)
        return {f"{_text(a)} {op} {_text(b)}": _pair_margin(a, op, b, frame) for a, op, b in out}

    def reach(self, frame) -> tuple[Reach, ...]:
        """Per condition between a column and a number, how far ``frame``'s designs are from it.

        Where no design meets a condition, its rarity is extrapolated from the top of the
        sample, with an exponential tail beyond the k-th best value (k = a quarter of the finite
        values, at least 2): the spacing of the k best values gives the tail's scale
        ``beta = (best - x_k) / H_(k-1)`` (the mean spacing of exponential order statistics,
        H the harmonic number), and ``rarity = (k / n) exp(-(t - x_k) / beta)``. Values and
        threshold are taken on a log scale when all are positive (stiffnesses, masses: a
        multiplicative spread). A target out of a uniform range's reach gets a tiny rarity (its
        top values bunch below the bound); a rare one in a long tail gets about its true
        frequency.
        """
        self.evaluate(frame)
        out: list = []
        _conditions(self._tree, out)
        reach = []
        for a, op, b in out:
            if op in ("==", "!=") or isinstance(a, _Column) == isinstance(b, _Column):
                continue
            col, num, up = (a, b, op in (">", ">=")) if isinstance(a, _Column) else (
                b, a, op in ("<", "<="))  # fmt: skip
            x = np.asarray(frame[col.name], dtype=float)
            x = x[np.isfinite(x)]
            t = float(num.value)
            holds = np.asarray(_OPS[op](x, t) if col is a else _OPS[op](t, x), bool)
            best = float((x.max() if up else x.min()) if len(x) else np.nan)
            rarity = float(holds.mean()) if holds.any() else _tail_rarity(x, t, up)
            reach.append(Reach(f"{_text(a)} {op} {_text(b)}", col.name, t, best,
                               int(holds.sum()), rarity))  # fmt: skip
        return tuple(reach)

    def margin(self, frame) -> np.ndarray:
        """(n_rows,) worst-case margin: the minimum over ``&``, the maximum over ``|``."""
        self.evaluate(frame)
        return np.asarray(_margin(self._tree, frame), dtype=float)


def parse_target(expr: str, columns=None) -> Target:
    """Parse a target expression.

    Parameters
    ----------
    expr : str
        The target, e.g. ``"Zstiff > 800 & Xstiff > 600 & error < 0.1"``.
    columns : iterable of str, optional
        The allowed column names; when given, an unknown name raises at parse time with its
        position.

    Returns
    -------
    Target

    Raises
    ------
    TargetError
        (a ValueError) naming the bad token or unknown column and its position.
    """
    if not isinstance(expr, str):
        raise TargetError(f"a target must be a string, got {type(expr).__name__}")
    if not expr.strip():
        raise TargetError("the target expression is empty")
    if len(expr) > MAX_LENGTH:
        raise TargetError(
            f"the target expression has {len(expr)} characters; at most {MAX_LENGTH} are read"
        )
    tree = _Parser(expr, _tokenize(expr)).parse()
    used: list[_Column] = []
    _columns_of(tree, used)
    if columns is not None:
        allowed = [str(c) for c in columns]
        for col in used:
            if col.name not in allowed:
                raise TargetError(
                    f"unknown column {col.name!r} at position {col.pos} in target {expr!r}; "
                    f"available columns: {', '.join(allowed)}"
                )
    names = tuple(dict.fromkeys(c.name for c in used))
    return Target(expr, names, tree)
