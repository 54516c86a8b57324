"""The values the comments of the docs' Python blocks show, compared as the blocks run (the convention is
in tests/test_docs.py's docstring).  Standard library only: FreeCAD's own Python runs it too, for the blocks
of docs/freecad.md."""

from __future__ import annotations

import ast
import io
import numbers
import re
import tokenize
import warnings
from dataclasses import dataclass

# --------------------------------------------------------------------------- #
# Values the comments show (the convention is in the module's docstring)
# --------------------------------------------------------------------------- #

_VALUE = re.compile(r"""[-+]?\.?\d|['"\[({]|(?:True|False|None)(?!\w)|[A-Z]\w*\(""")
_REPR = re.compile(r"[A-Z]\w*\(")
_UNIT = re.compile(r"\s*(?:mm²|mm2|mm|cm|m|in|%|s|°)(?![\w²])")
_NUMBER = r"[-+]?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?"


@dataclass(frozen=True)
class _Number:
    """A number as a comment shows it: compared to the digits of ``text``."""

    text: str

    def __repr__(self):
        return self.text


@dataclass(frozen=True)
class _Text:
    """A repr as a comment shows it (``Model('cup.step', 4 panels, ...)``): matched against the value's text."""

    text: str

    def __repr__(self):
        return self.text


def _same_number(actual, text: str) -> bool:
    mantissa, _, exponent = text.lower().partition("e")
    digits = len(mantissa.partition(".")[2]) - int(exponent or 0)
    return round(float(actual), digits) == float(text)


def _literal(node, source: str):
    """The value a literal's syntax tree shows: numbers as :class:`_Number`, ``...`` as Ellipsis."""
    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)) and not isinstance(node.value, bool):
        return _Number(ast.get_source_segment(source, node))
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)) and \
            isinstance(node.operand, ast.Constant) and isinstance(node.operand.value, (int, float)):
        return _Number(ast.get_source_segment(source, node).replace(" ", ""))
    if isinstance(node, ast.Constant) and (node.value in (True, False, None, ...) or isinstance(node.value, str)):
        return node.value
    if isinstance(node, (ast.Tuple, ast.List)):
        items = [_literal(e, source) for e in node.elts]
        return tuple(items) if isinstance(node, ast.Tuple) else items
    if isinstance(node, ast.Dict) and None not in node.keys:
        return {ast.literal_eval(k): _literal(v, source) for k, v in zip(node.keys, node.values)}
    raise ValueError("not a literal")


def _one_value(text: str):
    """The value at the start of ``text`` and what follows it: the longest Python literal, or a repr."""
    if _REPR.match(text):
        depth, quote = 0, None
        for end, c in enumerate(text):
            if quote:
                quote = None if c == quote else quote
            elif c in "'\"":
                quote = c
            elif c in "([{":
                depth += 1
            elif c in ")]}":
                depth -= 1
                if depth == 0:
                    return _Text(text[:end + 1]), text[end + 1:]
        raise ValueError(f"the repr {text!r} is not closed")
    for end in range(len(text), 0, -1):
        chunk = text[:end]
        if chunk[-1].isspace() or chunk[-1] == ",":
            continue
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                node = ast.parse(chunk, mode="eval").body
            return _literal(node, chunk), text[end:]
        except (SyntaxError, ValueError):
            continue
    raise ValueError(f"{text!r} does not begin with a Python literal")


def shown_values(comment: str, many: bool = False):
    """The values a comment shows (a list: one, or a ``print``'s several), or None if it is prose.

    Raises ValueError for a comment that begins like a value but cannot be read as one."""
    text = comment.lstrip("#").strip()
    if not _VALUE.match(text):
        return None
    values, rest = [], text
    while True:
        value, rest = _one_value(rest)
        values.append(value)
        if not (many and _VALUE.match(rest.lstrip())):
            break
        rest = rest.lstrip()
    if unit := _UNIT.match(rest):
        rest = rest[unit.end():]
    if rest.strip() and not rest.lstrip().startswith((":", ";", ",")):
        raise ValueError(f"after the value {text[:len(text) - len(rest)].strip()!r} comes {rest.strip()!r}: "
                         f"a value comment goes on after ':', ';' or ',' (or write it as prose)")
    return values


def _plain(actual):
    """numpy scalars and arrays as Python's (an array matches a shown list or tuple)."""
    if hasattr(actual, "tolist") and not isinstance(actual, (str, bytes)):
        return actual.tolist(), hasattr(actual, "shape") and actual.shape != ()
    return actual, False


def _text_mismatch(shown: str, text: str) -> str | None:
    """Why ``text`` is not what ``shown`` shows (``...`` any text, numbers to their digits), or None."""
    parts = [p for p in re.split(rf"(\.\.\.|{_NUMBER})", shown) if p]
    pattern = "".join("(.*?)" if p == "..." else f"({_NUMBER})" if re.fullmatch(_NUMBER, p) else re.escape(p)
                      for p in parts)
    m = re.fullmatch(pattern, text, re.DOTALL)
    if m is None:
        return f"the text is {text!r}"
    holes = [p for p in parts if p == "..." or re.fullmatch(_NUMBER, p)]
    wrong = [f"{got} is not {want}" for want, got in zip(holes, m.groups())
             if want != "..." and not _same_number(got, want)]
    return "; ".join(wrong) or None


def _mismatch(shown, actual, text_of=repr) -> str | None:
    """Why ``actual`` is not the value ``shown`` (from :func:`shown_values`), or None if it is."""
    actual, array = _plain(actual)
    if shown is ...:
        return None
    if isinstance(shown, _Number):
        if isinstance(actual, bool) or not isinstance(actual, numbers.Real):
            return f"{actual!r} is not a number"
        return None if _same_number(actual, shown.text) else f"{actual!r} is not {shown.text}"
    if isinstance(shown, _Text):
        return _text_mismatch(shown.text, text_of(actual))
    if shown is None or isinstance(shown, bool):
        return None if actual is shown else f"{actual!r} is not {shown!r}"
    if isinstance(shown, str):
        if not isinstance(actual, str):
            return f"{actual!r} is not a string"
        pattern = ".*".join(re.escape(p) for p in shown.split("..."))
        return None if re.fullmatch(pattern, actual, re.DOTALL) else f"{actual!r} is not {shown!r}"
    if isinstance(shown, dict):
        if not isinstance(actual, dict) or set(actual) != set(shown):
            return f"{actual!r} is not a dict with the keys {sorted(shown)}"
        return next((f"[{k!r}]: {w}" for k in shown if (w := _mismatch(shown[k], actual[k]))), None)
    if not (array and isinstance(actual, list)) and type(shown) is not type(actual) and \
            not (isinstance(shown, tuple) and isinstance(actual, tuple)):
        return f"{actual!r} is a {type(actual).__name__}, not a {type(shown).__name__}"
    return _items_mismatch(list(shown), list(actual))


def _items_mismatch(shown: list, actual: list) -> str | None:
    if not shown:
        return None if not actual else f"{len(actual)} more items than shown"
    if shown[0] is ...:
        rest = shown[1:]
        if any(_items_mismatch(rest, actual[k:]) is None for k in range(len(actual) + 1)):
            return None
        return f"no run of items ends as shown: {rest!r}"
    if not actual:
        return "fewer items than shown"
    return _mismatch(shown[0], actual[0]) or _items_mismatch(shown[1:], actual[1:])


def _value_comments(code: str) -> dict[int, str]:
    """``{line: comment}`` of every comment after code on its line (line 1 the block's first)."""
    found = {}
    for tok in tokenize.generate_tokens(io.StringIO(code).readline):
        if tok.type == tokenize.COMMENT and tok.line[:tok.start[1]].strip():
            found[tok.start[0]] = tok.string
    return found


def _checked_lines(code: str, filename: str, first_line: int):
    """The block's syntax tree and ``{line: (statement, kind, shown values, comment)}`` of its value comments.

    ``kind`` is ``"print"``, ``"value"`` (an expression) or ``"assign"``.  Raises ValueError naming the
    line of a value comment that cannot be read or sits where no value can be taken."""
    tree = ast.parse(code, f"{filename}:{first_line}")
    simple = [n for n in ast.walk(tree) if isinstance(n, ast.stmt) and not hasattr(n, "body")]
    checks = {}
    for line, comment in _value_comments(code).items():
        stmt = max((s for s in simple if s.lineno <= line <= s.end_lineno), default=None,
                   key=lambda s: (s.lineno, s.col_offset))  # the last on the line
        is_print = isinstance(stmt, ast.Expr) and isinstance(stmt.value, ast.Call) and \
            isinstance(stmt.value.func, ast.Name) and stmt.value.func.id == "print"
        where = f"{filename}:{first_line + line}"
        try:
            values = shown_values(comment, many=is_print)
        except ValueError as exc:
            raise ValueError(f"{where}: {comment!r}: {exc}") from None
        if values is None:
            continue
        kind = "print" if is_print else "value" if isinstance(stmt, ast.Expr) else \
            "assign" if isinstance(stmt, (ast.Assign, ast.AnnAssign)) and stmt.value is not None else None
        if kind is None:
            raise ValueError(f"{where}: {comment!r} shows a value on a line that has none "
                             f"(write it as prose)")
        if any(c[0] is stmt for c in checks.values()):
            raise ValueError(f"{where}: a second value comment on one statement")
        if kind != "print" and len(values) != 1:
            raise ValueError(f"{where}: {comment!r}: one value expected")
        checks[line] = (stmt, kind, values, comment)
    return tree, checks


class _Values:
    """The comparisons of one block, called from its instrumented code."""

    def __init__(self, checks, lines, where):
        self.checks, self.lines, self.where = checks, lines, where
        self.done, self.wrong = set(), []

    def _compare(self, line, actual, text_of):
        if line in self.done:
            return
        self.done.add(line)
        _, _, values, comment = self.checks[line]
        if len(values) != len(actual):
            why = f"it prints {len(actual)} values, the comment shows {len(values)}"
        else:
            why = next((w for v, a in zip(values, actual) if (w := _mismatch(v, a, text_of))), None)
        if why:
            shown = " ".join(map(repr, actual)) if text_of is str else repr(actual[0])
            self.wrong.append(f"{self.where(line)}: `{self.lines[line - 1].strip()}`\n"
                              f"    shows {comment.lstrip('#').strip()}\n    but   {shown}\n    ({why})")

    def value(self, line, actual):
        self._compare(line, [actual], repr)
        return actual

    def print(self, line, *args, **keywords):
        print(*args, **keywords)
        self._compare(line, list(args), str)

    def verdict(self):
        missed = [self.where(line) for line in self.checks if line not in self.done]
        if self.wrong:
            raise AssertionError("values that are not what the comments show:\n" + "\n".join(self.wrong))
        if missed:
            raise AssertionError(f"value comments on lines that never ran: {missed}")


class _Instrument(ast.NodeTransformer):
    """Passes the value of every checked line through ``__doc_values__``."""

    def __init__(self, checks):
        self.by_stmt = {id(stmt): (line, kind) for line, (stmt, kind, _, _) in checks.items()}

    def _call(self, method, line, args, keywords=(), at=None):
        func = ast.Attribute(ast.Name("__doc_values__", ast.Load()), method, ast.Load())
        return ast.copy_location(ast.Call(func, [ast.Constant(line), *args], list(keywords)), at)

    def generic_visit(self, node):
        node = super().generic_visit(node)
        if (found := self.by_stmt.get(id(node))) is None:
            return node
        line, kind = found
        if kind == "print":
            node.value = self._call("print", line, node.value.args, node.value.keywords, node.value)
        else:
            node.value = self._call("value", line, [node.value], at=node.value)
        return node


def run_python_block(namespace: dict, code: str, filename: str, first_line: int) -> int:
    """Run one Python block of a markdown file in ``namespace``, comparing every value its comments show
    with the value of its line; return how many were compared.  ``first_line``: the markdown line of the
    fence.  (Also called inside FreeCAD, by the code :func:`_freecad_block` writes.)"""
    name = f"{filename}:{first_line}"
    tree, checks = _checked_lines(code, filename, first_line)
    tree = ast.fix_missing_locations(_Instrument(checks).visit(tree))
    values = _Values(checks, code.splitlines(), lambda line: f"{filename}:{first_line + line}")
    namespace["__doc_values__"] = values
    exec(compile(tree, name, "exec"), namespace)  # noqa: S102 - the docs' own code
    values.verdict()
    return len(checks)
