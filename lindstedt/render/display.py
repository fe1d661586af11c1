"""Shared formatting of results for people: short ``__repr__`` text, Jupyter LaTeX and HTML tables.

Every result keeps one LaTeX export, its ``to_latex()``; :func:`jupyter_latex` turns that fragment into
what Jupyter's ``_repr_latex_`` must return (display math, no ``%`` comments).  :func:`labelled_repr`
writes a readable ``__repr__`` (labelled fields, numbers to ~10 significant digits, long values cut
with an ellipsis that says where the full value is) and :func:`html_table` / :func:`html_grid` the
compact ``_repr_html_`` tables of numerical results.

Only the standard library is imported here at module level (``import lindstedt`` stays light);
mpmath and numpy values are recognised by duck typing.

Examples
--------
>>> from lindstedt.render.display import format_number, labelled_repr, shorten
>>> format_number(0.51763809020504152469)
'0.5176380902'
>>> labelled_repr("Point", [("x", format_number(1 / 3)), ("ok", "True")])
'Point(x=0.3333333333, ok=True)'
>>> shorten("x" * 50, 20, "point.x")
'xxxxxxxxxxxxxxxxxxx… (50 characters; full: point.x)'
"""

from __future__ import annotations

import html
import math
import re
from collections.abc import Iterable, Sequence
from typing import Any

__all__ = [
    "format_number",
    "format_vector",
    "html_grid",
    "html_table",
    "jupyter_latex",
    "labelled_repr",
    "latex_text",
    "shorten",
]

DIGITS = 10
"""Significant digits of numbers in reprs and tables."""
LINE = 100
"""A repr longer than this puts one field per line."""
FIELD = 240
"""Longest text of one field in a repr before it is cut."""


def format_number(value: Any, digits: int = DIGITS) -> str:
    """A number as short text: ``digits`` significant digits (mpmath, numpy and Python numbers).

    Integers, booleans and None are shown as they are; complex numbers as ``a+bj``; anything else
    through ``str``.

    Examples
    --------
    >>> import mpmath
    >>> format_number(mpmath.mpf("0.5176380902050415246977976752")), format_number(3), format_number(float("nan"))
    ('0.5176380902', '3', 'nan')
    >>> format_number(complex(1, -1e-20), 4)
    '1-1e-20j'
    """
    if value is None or isinstance(value, (bool, int, str)):
        return str(value)
    module = type(value).__module__ or ""
    if module.startswith("mpmath"):
        import mpmath

        if isinstance(value, mpmath.mpc):
            return format_number(complex(value), digits)
        return mpmath.nstr(value, digits)
    if module.startswith("numpy") and getattr(value, "shape", None) == ():
        value = value.item()
        if isinstance(value, (bool, int)):
            return str(value)
    if isinstance(value, complex):
        real, imag = format_number(value.real, digits), format_number(abs(value.imag), digits)
        sign = "-" if value.imag < 0 or (value.imag == 0 and math.copysign(1.0, value.imag) < 0) else "+"
        return f"{real}{sign}{imag}j"
    if isinstance(value, float):
        return f"{value:.{digits}g}"
    try:
        return f"{float(value):.{digits}g}" if getattr(value, "is_Float", False) else str(value)
    except (TypeError, ValueError):  # pragma: no cover - defensive
        return str(value)


def format_vector(values: Any, digits: int = 6, limit: int = 8) -> str:
    """A vector (any iterable of numbers) as ``[a, b, …]``: at most ``limit`` entries shown.

    Examples
    --------
    >>> format_vector([1 / 3, 2.0]), format_vector(range(20), limit=3)
    ('[0.333333, 2]', '[0, 1, 2, … (20 entries)]')
    """
    if values is None:
        return "None"
    items = list(values.reshape(-1)) if hasattr(values, "reshape") else list(values)
    shown = [format_number(item, digits) for item in items[:limit]]
    if len(items) > limit:
        shown.append(f"… ({len(items)} entries)")
    return "[" + ", ".join(shown) + "]"


def shorten(text: str, limit: int, hint: str | None = None) -> str:
    """``text`` cut to ``limit`` characters with an ellipsis and where to find the full text.

    Examples
    --------
    >>> shorten("short", 10), shorten("0123456789abc", 10)
    ('short', '012345678… (13 characters)')
    """
    if len(text) <= limit:
        return text
    where = f"; full: {hint}" if hint else ""
    return text[: max(limit - 1, 1)] + f"… ({len(text)} characters{where})"


def labelled_repr(name: str, fields: Sequence[tuple[str, str]], *, field_limit: int = FIELD) -> str:
    """``Name(label=value, …)``, one field per line when it would be longer than :data:`LINE`.

    Every value is cut to ``field_limit`` characters (:func:`shorten`), so a repr is never
    longer than about ``len(fields) * field_limit`` characters.

    Examples
    --------
    >>> print(labelled_repr("Run", [("success", "True"), ("message", "'reached t_end'"), ("n", "3" * 90)]))
    Run(
      success=True,
      message='reached t_end',
      n=333333333333333333333333333333333333333333333333333333333333333333333333333333333333333333,
    )
    """
    parts = [f"{label}={shorten(value, field_limit)}" for label, value in fields]
    line = f"{name}(" + ", ".join(parts) + ")"
    if len(line) <= LINE and "\n" not in line:
        return line
    return f"{name}(\n" + "".join(f"  {part},\n" for part in parts) + ")"


def latex_text(text: str) -> str:
    r"""``text`` escaped for ``\text{…}`` (the characters TeX gives a meaning to).

    Examples
    --------
    >>> latex_text("a0 is declared positive, 100% & more")
    'a0 is declared positive, 100\\% \\& more'
    """
    replacements = {
        "\\": r"\textbackslash{}", "{": r"\{", "}": r"\}", "_": r"\_", "%": r"\%", "&": r"\&",
        "#": r"\#", "$": r"\$", "^": r"\^{}", "~": r"\~{}",
    }
    return "".join(replacements.get(character, character) for character in text)


_ALIGN = re.compile(r"\\begin\{align\*\}(.*?)\\end\{align\*\}", re.DOTALL)


def jupyter_latex(fragment: str) -> str:
    r"""What ``_repr_latex_`` returns for a ``to_latex()`` fragment.

    ``%`` comment lines are dropped (they are text outside math) and every ``align*`` block becomes
    ``$$\begin{aligned}…\end{aligned}$$`` (display math that MathJax, KaTeX and LaTeX all accept);
    sentences with inline ``$…$`` math are kept as they are.

    Examples
    --------
    >>> print(jupyter_latex("% a comment\n\\begin{align*}\nx &= 1\n\\end{align*}\n"))
    $$\begin{aligned}
    x &= 1
    \end{aligned}$$
    """
    lines = [line for line in fragment.splitlines() if not line.lstrip().startswith("%")]
    text = "\n".join(lines).strip()
    return _ALIGN.sub(lambda match: "$$\\begin{aligned}" + match.group(1) + "\\end{aligned}$$", text)


def html_table(title: str, rows: Iterable[tuple[str, Any]], *, note: str | None = None) -> str:
    """A two-column HTML table (label, value) with a caption; everything escaped.

    Examples
    --------
    >>> html_table("Run", [("success", True), ("message", "a < b")])
    '<table class="lindstedt"><caption style="text-align:left"><b>Run</b></caption><tr><th style="text-align:left">success</th><td style="text-align:left">True</td></tr><tr><th style="text-align:left">message</th><td style="text-align:left">a &lt; b</td></tr></table>'
    """
    body = "".join(
        f'<tr><th style="text-align:left">{html.escape(str(label))}</th>'
        f'<td style="text-align:left">{html.escape(str(value))}</td></tr>'
        for label, value in rows
    )
    foot = f'<tr><td colspan="2" style="text-align:left"><i>{html.escape(note)}</i></td></tr>' if note else ""
    return (
        f'<table class="lindstedt"><caption style="text-align:left"><b>{html.escape(title)}</b></caption>'
        + body + foot + "</table>"
    )


def html_grid(title: str, header: Sequence[str], rows: Sequence[Sequence[Any]], *, note: str | None = None) -> str:
    """An HTML table with a header row (a summary of many records: give only the rows to show).

    Examples
    --------
    >>> html_grid("B", ["k", "ω"], [[0, "1.0"]])
    '<table class="lindstedt"><caption style="text-align:left"><b>B</b></caption><tr><th>k</th><th>ω</th></tr><tr><td>0</td><td>1.0</td></tr></table>'
    """
    head = "<tr>" + "".join(f"<th>{html.escape(str(cell))}</th>" for cell in header) + "</tr>"
    body = "".join("<tr>" + "".join(f"<td>{html.escape(str(cell))}</td>" for cell in row) + "</tr>" for row in rows)
    foot = f'<tr><td colspan="{len(header)}" style="text-align:left"><i>{html.escape(note)}</i></td></tr>' if note else ""
    return (
        f'<table class="lindstedt"><caption style="text-align:left"><b>{html.escape(title)}</b></caption>'
        + head + body + foot + "</table>"
    )
