r"""Read the LaTeX of impactsym's typeset formulas back into SymPy, independently of the
printer: a small reader of the notation the formulas use (``\frac``, ``\sqrt``, ``^{}``,
``\left( \right)``, ``\cos``, ``\arctan``, ``\operatorname{atan2}``, ``e^{}``, Greek
letters with subscripts, ``\sum_{n \ge 2}``, ``\text{with }``/``\text{for }`` clauses).

Only the characters of the LaTeX string go in; the formula objects are never consulted.
"""

from __future__ import annotations

import re

import sympy as sp

#: LaTeX commands read as plain names
NAMES = {
    r"\omega": "omega",
    r"\tau": "tau",
    r"\alpha": "alpha",
    r"\kappa": "kappa",
    r"\xi": "xi",
    r"\pi": "pi",
    r"\Delta": "Delta",
}
FUNCTIONS = {
    r"\operatorname{atan2}": "atan2",
    r"\operatorname{artanh}": "atanh",
    r"\arctan": "atan",
    r"\cosh": "cosh",
    r"\sinh": "sinh",
    r"\cos": "cos",
    r"\sin": "sin",
    r"\sqrt": "sqrt",
}


def _group(text: str, start: int) -> tuple[str, int]:
    """The content of the brace group opening at ``text[start]`` and the index after it."""
    assert text[start] == "{", text[start:]
    depth = 0
    for i in range(start, len(text)):
        depth += {"{": 1, "}": -1}.get(text[i], 0)
        if depth == 0:
            return text[start + 1 : i], i + 1
    raise ValueError(f"unbalanced braces in {text!r}")


def to_python(text: str) -> str:
    """One LaTeX expression as Python source with explicit operators."""
    out = []
    i = 0
    while i < len(text):
        rest = text[i:]
        if rest.startswith(r"\frac"):
            numerator, i = _group(text, i + 5)
            denominator, i = _group(text, i)
            out.append(f"(({to_python(numerator)})/({to_python(denominator)}))")
        elif rest.startswith(r"\sqrt"):
            body, i = _group(text, i + 5)
            out.append(f"sqrt({to_python(body)})")
        elif rest.startswith("e^{"):
            body, i = _group(text, i + 2)
            out.append(f"exp({to_python(body)})")
        elif rest.startswith("^"):
            body, i = _group(text, i + 1)
            out.append(f"**({to_python(body)})")
        elif rest.startswith(r"\sum_"):
            limits, i = _group(text, i + 5)
            n, low = (part.strip() for part in limits.split(r"\ge"))
            out.append(f"Sum({to_python(text[i:])}, ({n}, {low}, N_TERMS))")
            i = len(text)
        elif rest.startswith(r"\left(") or rest.startswith(r"\right)"):
            out.append("(" if rest[1] == "l" else ")")
            i += 6 if rest[1] == "l" else 7
        elif rest.startswith("{\\lambda}'_{"):
            sub, i = _group(text, i + len("{\\lambda}'_"))
            out.append(f"lambdaprime_{sub}")
        elif function := next((f for f in FUNCTIONS if rest.startswith(f)), None):
            i += len(function)
            name = FUNCTIONS[function]
            if text[i] == " ":  # \sinh s: a single symbol as argument
                match = re.match(r" ([A-Za-z]+)", text[i:])
                out.append(f"{name}({match.group(1)})")
                i += match.end()
            else:
                out.append(name)
        elif name := next(
            (n for n in NAMES if re.match(re.escape(n) + r"(?![A-Za-z])", rest)), None
        ):
            i += len(name)
            token = NAMES[name]
            if text[i : i + 2] == "_{":
                sub, i = _group(text, i + 1)
                token += f"_{sub}"
            out.append(token)
        elif match := re.match(r"[A-Za-z](_\{[A-Za-z0-9]+\})?", rest):
            out.append(match.group(0).replace("{", "").replace("}", ""))
            i += match.end()
        elif match := re.match(r"\d+", rest):
            out.append(f"Integer({match.group(0)})")
            i += match.end()
        elif rest[0] in "+-(),/":
            out.append(rest[0])
            i += 1
        elif rest[0] == " ":
            i += 1
        else:
            raise ValueError(f"cannot read {rest[:30]!r}")
    return _multiply(out)


def _multiply(tokens: list[str]) -> str:
    """Join tokens, writing the implicit products out: ``2 D f`` -> ``2*D*f``."""
    functions = {*FUNCTIONS.values(), "exp", "Sum", "Integer"}
    out = ""
    previous = None
    for token in tokens:
        operand_end = previous is not None and (
            previous[-1] in ")" or (previous[-1].isalnum() and previous not in functions)
        )
        starts_operand = token[0] in "(" or token[0].isalnum()
        if operand_end and starts_operand and not token.startswith("**"):
            out += "*"
        out += token
        previous = token
    return out


def read(text: str, symbols: dict[str, sp.Symbol]) -> dict:
    """A typeset formula ``lhs = rhs[, \\qquad \\text{for } cond][, \\qquad \\text{with }
    a = A, \\quad ...]`` as ``{"rhs": expr, "for": condition, "with": {symbol: expr}}``
    (aligned two-line forms are read too)."""
    text = re.sub(r"\\begin\{aligned\}&|\\end\{aligned\}|\\\\ &", " ", text)
    text = text.replace("&=", "=")
    parts = re.split(r",\s*\\qquad\s*", text)
    _, rhs = parts[0].split("=", 1)
    out: dict = {"rhs": _parse(rhs, symbols), "for": sp.true, "with": {}}
    for part in parts[1:]:
        if part.startswith(r"\text{for }"):
            out["for"] = _parse(part[len(r"\text{for }") :], symbols)
        elif part.startswith(r"\text{with }"):
            for definition in re.split(r",\s*\\quad\s*", part[len(r"\text{with }") :]):
                name, value = definition.split("=")
                out["with"][_parse(name, symbols)] = _parse(value, symbols)
        else:
            raise ValueError(f"cannot read the clause {part!r}")
    return out


class _Names(dict):
    """Names of a formula: SymPy's functions and constants, every other name a symbol."""

    def __missing__(self, key: str) -> sp.Symbol:
        return self.setdefault(key, sp.Symbol(key))


FUNCTION_NAMES = (
    "sqrt",
    "exp",
    "cos",
    "sin",
    "cosh",
    "sinh",
    "atan",
    "atan2",
    "atanh",
    "Sum",
    "Integer",
)


def _parse(text: str, symbols: dict[str, sp.Symbol]) -> sp.Basic:
    if "<" in text:
        left, right = text.split("<")
        return sp.StrictLessThan(_parse(left, symbols), _parse(right, symbols))
    names = _Names({name: getattr(sp, name) for name in FUNCTION_NAMES})
    names.update(pi=sp.pi, **symbols)
    return eval(to_python(text.strip()), {"__builtins__": {}}, names)  # our own LaTeX only
