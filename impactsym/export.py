"""Generated artifacts for papers and foreign code.

* :func:`latex_document` -- a standalone, compilable LaTeX document with every formula
  the package derives (paper eqs. (1), (2), the closed forms, series, inverted terms,
  the spring-damper solution, ridge times and boundary, the reduced multibody equation);
  :func:`formula` returns one of them for pasting, :func:`formula_descriptions` says what
  each is; :func:`typeset_formulas` gives the typeset objects
  (:mod:`impactsym.symbolic.typeset`), which keep the expression each formula came from.
* :func:`python_module` -- readable Python source that depends on NumPy only, with the
  rod time functions and the section-2 contact functions, ridge times and boundary
  equation, generated from the same SymPy expressions the package uses.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import sympy as sp
from sympy.printing.numpy import NumPyPrinter

from impactsym._files import write_text
from impactsym.contact import derivation
from impactsym.contact.derivation import NUMERIC_AUX, D, f, tau
from impactsym.symbolic.typeset import aligned

Formula = tuple[str, str, str]


def typeset_formulas(n_terms: int = 3) -> list[tuple[str, list[tuple[str, str, Any]]]]:
    """All derived formulas as ``(section title, [(label, sentence, form), ...])``.

    ``form`` is a :class:`~impactsym.symbolic.typeset.Typeset` (which keeps the
    expression it was typeset from, for checks) or, for an equation written by hand,
    the LaTeX string.

    >>> [label for label, _, _ in typeset_formulas()[1][1]][:2]
    ['sd-ode', 'sd-conditions']
    """
    from impactsym.multibody import reduction as multibody
    from impactsym.rod import derivation as rod

    return [
        (SECTIONS[0], rod.typeset_formulas(n_terms)),
        (SECTIONS[1], derivation.typeset_formulas()),
        (SECTIONS[2], multibody.typeset_formulas()),
    ]


#: Section titles of the formula document, one per analysis of the paper
SECTIONS = (
    "Rod impact (paper section 1)",
    "Spring-damper contact (paper section 2)",
    "Multibody penalty contact (paper section 3)",
)


def formulas(n_terms: int = 3) -> list[tuple[str, list[Formula]]]:
    """All derived formulas as ``(section title, [(label, caption, LaTeX body), ...])``.

    >>> [title for title, _ in formulas()][1]
    'Spring-damper contact (paper section 2)'
    """
    return [
        (title, [(label, caption, _body(form)) for label, caption, form in items])
        for title, items in typeset_formulas(n_terms)
    ]


def _body(form: Any) -> str:
    """LaTeX of a formula: written by hand, one typeset formula, or aligned rows."""
    if isinstance(form, str):
        return form
    return aligned(form) if isinstance(form, list) else form.latex()


def formula(name: str, n_terms: int = 3) -> str:
    r"""The LaTeX body of the formula labelled ``name`` (see :func:`formula_names`).

    >>> print(formula("sd-conditions"))
    g_\mathrm{position} = z, \qquad g_\mathrm{force} = 2 D z' + z
    """
    for _, items in formulas(n_terms):
        for label, _, body in items:
            if label == name:
                return body
    raise ValueError(f"no formula named {name!r}; known: {', '.join(formula_names(n_terms))}")


def formula_names(n_terms: int = 3) -> list[str]:
    """Labels of all formulas, in document order.

    >>> names = formula_names()
    >>> names[0], "mb-reduced" in names
    ('rod-bvp', True)
    """
    return [label for _, items in formulas(n_terms) for label, _, _ in items]


def formula_descriptions(n_terms: int = 3) -> list[tuple[str, str]]:
    """``(label, one-line description)`` of every formula, in document order, as plain
    text (the sentence of the document up to its first colon, without LaTeX).

    >>> formula_descriptions()[0]
    ('rod-bvp', "The transformed boundary-value problem of the paper's eq. (1)")
    """
    return [
        (label, _plain(re.split(r": |; ", caption)[0]).rstrip("."))
        for _, items in formulas(n_terms)
        for label, caption, _ in items
    ]


def _plain(text: str) -> str:
    r"""Inline LaTeX as plain text: ``$\tau_r(D, f)$`` -> ``tau_r(D, f)``."""
    text = re.sub(r"\\operatorname\{(\w+)\}", r"\1", text.replace("$", ""))
    text = re.sub(r"\\to\b", "->", text).replace(r"\infty", "inf")
    text = re.sub(r"\\([A-Za-z]+)\s+(?=\w)", r"\1 ", text)
    text = re.sub(r"\\([A-Za-z]+)", r"\1", text)
    return re.sub(r"\s+", " ", text.replace("{", "").replace("}", "")).strip()


def _escape_text(text: str) -> str:
    """Escape LaTeX specials in caption text, leaving ``$...$`` math alone."""
    parts = text.split("$")
    for i in range(0, len(parts), 2):
        parts[i] = re.sub(r"([_&%#^])", r"\\\1", parts[i])
    return "$".join(parts)


#: LaTeX preamble lines defining ``\fitformula{body}``: the body in display style at
#: text size, scaled down (never up) to the line width less room for the equation number
#: when it is wider
_FIT_FORMULA = (
    r"\newsavebox{\formulabox}",
    r"\newlength{\formulawidth}",
    r"\newcommand{\fitformula}[1]{\setlength{\formulawidth}{\dimexpr\linewidth-3em\relax}%",
    r"  \sbox{\formulabox}{$\displaystyle #1$}%",
    r"  \ifdim\wd\formulabox>\formulawidth",
    r"    \resizebox{\formulawidth}{!}{\usebox{\formulabox}}%",
    r"  \else\usebox{\formulabox}\fi}",
)


#: The paper's own equation numbers, set as the equations' tags in the document
PAPER_EQUATIONS = {"rod-bvp": "1", "rod-eq2": "2", "mb-penalty": "3, 4", "mb-reduced": "5"}

#: What each section of the document is about, set before its first formula
_SECTION_INTRO = (
    r"A striker of mass ratio $\alpha$, pressed by the force $f$, hits the free end of an "
    r"elastic rod fixed at its other end, through a contact spring of stiffness $\kappa$ "
    r"(rigid contact: $\kappa \to \infty$). Time is measured in wave travel times over the "
    r"rod, $s$ is the Laplace variable of $t$ and $\xi$ the position along the rod.",
    r"A body hits a unilateral spring-damper contact. In the normalized time $\tau$ the "
    r"penetration $z$ obeys a damped oscillator with Lehr's damping ratio $D$ and the "
    r"pressing force $f$; contact ends at the first sign change of the contact function $g$. "
    r"The ridge time $\tau_r$ is where the surface $g(\tau, D, f) = 0$ folds "
    r"($\partial g/\partial\tau = 0$); the sign of $g$ there decides between release and "
    r"sticking.",
    r"A multibody system with a penalty contact is reduced, for the short duration of an "
    r"impact, to the contact oscillator of section~B. The projection and the corrections "
    r"to the paper's eq.~(5) are derived and checked in the documentation of impactsym.",
)


def latex_document(n_terms: int = 3) -> str:
    """A standalone LaTeX document (pdflatex + amsmath) with every labelled formula.

    Set like the appendix of a paper: a section per analysis, every formula with a
    sentence saying what it is, numbered by section (A.1, ...) except the paper's own
    equations, which keep the paper's numbers (:data:`PAPER_EQUATIONS`).

    >>> document = latex_document()
    >>> document.splitlines()[0], "{eq:rod-eq2}" in document, r"\\tag{2}" in document
    ('\\\\documentclass[10pt]{article}', True, True)
    """
    lines = [
        r"\documentclass[10pt]{article}",
        r"\ifdefined\pdftrailerid \pdftrailerid{} \pdfinfoomitdate=1 \fi % reproducible PDF",
        r"\usepackage[margin=2cm]{geometry}",
        r"\usepackage{amsmath,amssymb,graphicx}",
        *_FIT_FORMULA,
        r"\renewcommand{\thesection}{\Alph{section}}",
        r"\numberwithin{equation}{section}",
        # the label at the right end of the sentence's last line, or of a line of its own
        r"\newcommand{\formulalabel}[1]{{\unskip\nobreak\hfil\penalty50\hskip1em\hbox{}"
        r"\nobreak\hfil\footnotesize\texttt{#1}\parfillskip=0pt\finalhyphendemerits=0\par}}",
        r"\title{Appendix: the formulas of Waltersberger, Keppler and Wauer (PAMM 2004) "
        r"as derived by impactsym}",
        r"\author{generated by impactsym}",
        r"\date{}",
        r"\begin{document}",
        r"\maketitle",
        r"\noindent Every formula below was derived with SymPy and typeset from the derived "
        r"expression; each typeset form is checked against that expression at random points "
        r"of its region. Equations (1)--(5) carry the paper's numbers; the others are "
        r"numbered by section. The name at the right of each sentence is the formula's label "
        r"for \texttt{impactsym latex NAME}. Primes denote derivatives with respect to the "
        r"normalized time, except in eq.~(1), where they are derivatives in $\xi$.",
    ]
    for (title, items), intro in zip(formulas(n_terms), _SECTION_INTRO, strict=True):
        lines += [rf"\section{{{title}}}", intro]
        ridge = None
        for label, caption, body in items:
            tag = PAPER_EQUATIONS.get(label)
            sentence = _escape_text(caption)
            if ridge is not None:  # the boundary cites the ridge time by its number
                sentence = sentence.replace("the ridge time above", rf"eq.~\eqref{{eq:{ridge}}}")
            ridge = label if label.startswith("sd-ridge") else ridge
            lines += [
                "",
                rf"\noindent {sentence}\formulalabel{{{_escape_text(label)}}}",
                r"\begin{equation}",
                rf"\label{{eq:{label}}}" + (rf"\tag{{{tag}}}" if tag else ""),
                rf"\fitformula{{{body}}}",
                r"\end{equation}",
            ]
    lines.append(r"\end{document}")
    return "\n".join(lines) + "\n"


# -- NumPy-only Python module ------------------------------------------------------------

_PRINTER = NumPyPrinter({"fully_qualified_modules": True, "allow_unknown_functions": False})


def _function_source(name: str, args: list[sp.Symbol], expr: sp.Expr, doc: str) -> str:
    """``def name(args)`` computing ``expr`` with common subexpressions hoisted."""
    replacements, (reduced,) = sp.cse(
        sp.sympify(expr, strict=True), symbols=sp.numbered_symbols("c")
    )
    body = [f"    {s} = {_PRINTER.doprint(e)}" for s, e in replacements]
    body.append(f"    return {_PRINTER.doprint(reduced)}")
    code = "\n".join([f"def {name}({', '.join(map(str, args))}):", f'    """{doc}"""', *body])
    return code.replace("numpy.", "np.")


_SECTION2_HEADER = '''
# -- spring-damper contact (paper section 2) ------------------------------------------
# z'' + 2 D z' + z = 2 D f, z(0) = 0, z'(0) = 1; tau = omega0 t, D = d / (2 sqrt(k m)),
# f = F / (d v0). Contact functions: g_position = z, g_force = 2 D z' + z.


def _aux_underdamped(D):
    return (np.sqrt((1.0 - D) * (1.0 + D)),)


def _aux_critical(D):
    return ()


def _aux_overdamped(D):
    sigma = np.sqrt((D - 1.0) * (D + 1.0))
    return (sigma, D + sigma)


def _damping(D):
    # beyond D = 1e8 the over-damped exponentials lose accuracy (impactsym switches to
    # its far over-damped limit there)
    return _real("D", D, lower=0.0, upper=1e8)


_AUX = {"underdamped": _aux_underdamped, "critical": _aux_critical,
        "overdamped": _aux_overdamped}


def _by_regime(functions, leading, D, critical_separate):
    """Evaluate per damping regime on the broadcast arguments (leading args, D, f)."""
    args = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in leading))
    D = args[-2]
    if critical_separate:
        masks = {"underdamped": D < 1, "critical": D == 1, "overdamped": D > 1}
    else:  # the under-damped forms hold at D = 1 (sinc at omega = 0)
        masks = {"underdamped": D <= 1, "overdamped": D > 1}
    out = np.full(D.shape, np.nan)
    with np.errstate(all="ignore"):
        for regime, mask in masks.items():
            if mask.any():
                sub = [a[mask] for a in args]
                out[mask] = functions[regime](*sub, *_AUX[regime](sub[-2]))
    return out if out.ndim else float(out)
'''

_PUBLIC_SECTION2 = '''

def contact_function_{c}(tau, D, f):
    """Contact function g_{c}(tau; D, f) of the spring-damper contact (paper section 2).

    {what}. Arguments: tau (normalized time omega0 t >= 0), D (Lehr's damping, 0 to
    1e8), f (pressing force F / (d v0) >= 0); NumPy arrays broadcast.
    """
    tau, D, f = _real("tau", tau, lower=0.0), _damping(D), _real("f", f, lower=0.0)
    _shape(tau=tau, D=D, f=f)
    return _by_regime(_G_{c}, (tau, D, f), D, critical_separate=False)


def ridge_time_{c}(D, f):
    """Closed-form ridge time tau_r(D, f) of the {c} condition: the first local minimum of
    g after impact, from dg/dtau = 0 (paper section 2, the fold of Fig. 1a); NaN where g
    has no minimum. Arguments: D, f as in contact_function_{c}.
    """
    D, f = _damping(D), _real("f", f, lower=0.0)
    _shape(D=D, f=f)
    D_, f_ = np.broadcast_arrays(D, f)
    exists = _by_regime(_RIDGE_EXISTS_{c}, (D_, f_), D_, critical_separate=True)
    ridge = _by_regime(_RIDGE_{c}, (D_, f_), D_, critical_separate=True)
    return np.where(np.asarray(exists) > 0.5, ridge, np.nan)[()]


def boundary_{c}(D, f):
    """Boundary function G(D, f) = g_{c}(tau_r(D, f), D, f) of the {c} condition
    (paper section 2, Fig. 1b): the body releases where G < 0 and sticks where G >= 0;
    where g has no minimum G is its infimum 2 D f. Arguments: D, f as above.
    """
    ridge = np.asarray(ridge_time_{c}(D, f))
    D_, f_ = np.broadcast_arrays(_damping(D), _real("f", f, lower=0.0))
    value = np.asarray(contact_function_{c}(np.where(np.isnan(ridge), 0.0, ridge), D_, f_))
    return np.where(np.isnan(ridge), 2.0 * D_ * f_, value)[()]
'''

_WHAT = {
    "position": "The penetration z; contact lasts while g > 0",
    "force": "The normalized contact force 2 D z' + z; contact lasts while g > 0",
}


def _section2_source() -> str:
    parts = [_SECTION2_HEADER]
    for c in ("position", "force"):
        tables = {"G": {}, "RIDGE": {}, "RIDGE_EXISTS": {}}
        for regime in derivation.REGIMES:
            forms = derivation.spring_damper(regime).numeric_forms
            aux = list(NUMERIC_AUX[regime])
            if regime != "critical":  # the under-damped form covers D = 1
                name = f"_g_{c}_{regime}"
                parts.append(
                    _function_source(
                        name, [tau, D, f, *aux], forms[f"g_{c}"], f"g_{c} for the {regime} regime."
                    )
                )
                tables["G"][regime] = name
            for key, form in (("RIDGE", "ridge"), ("RIDGE_EXISTS", "ridge_exists")):
                name = f"_{form}_{c}_{regime}"
                expr = forms[f"{form}_{c}"]
                if form == "ridge_exists":  # a boolean: 1.0 where g has a minimum
                    expr = sp.Piecewise((1.0, expr), (0.0, True))
                parts.append(
                    _function_source(
                        name, [D, f, *aux], expr, f"{form} of the {c} condition, {regime} regime."
                    )
                )
                tables[key][regime] = name
        for key, table in tables.items():
            entries = ", ".join(f'"{r}": {n}' for r, n in table.items())
            parts.append(f"_{key}_{c} = {{{entries}}}")
        parts.append(_PUBLIC_SECTION2.format(c=c, what=_WHAT[c]))
    return "\n\n".join(parts)


def python_module() -> str:
    """Source of a NumPy-only module with the rod and spring-damper time functions.

    >>> source = python_module()
    >>> "import sympy" in source, "def contact_function_force(tau, D, f):" in source
    (False, True)
    """
    from impactsym.rod.codegen import numpy_source

    header = '''"""Formulas of impactsym as plain NumPy functions (generated; needs NumPy only).

Waltersberger, Keppler and Wauer, PAMM 2004: rod impact (section 1) and unilateral
spring-damper contact (section 2). Regenerate with ``impactsym export python FILE``.
Inputs are checked as impactsym checks them (real numbers or arrays only, finite, in
range, broadcastable); errors name the argument.
"""

import numpy as np
'''
    rod = numpy_source().split("import numpy as np\n", 1)[1]  # its functions, not its header
    return (
        "\n".join(
            [header, "# -- rod impact (paper section 1) " + "-" * 52, rod, _section2_source()]
        ).rstrip()
        + "\n"
    )


def write_python_module(path: str | Path) -> Path:
    """Write :func:`python_module` to ``path``.

    >>> import tempfile, pathlib
    >>> path = write_python_module(pathlib.Path(tempfile.mkdtemp()) / "m.py")
    >>> path.read_text().count("def contact_function_")
    2
    """
    return write_text(path, python_module())


def write_latex_document(path: str | Path, n_terms: int = 3) -> Path:
    """Write :func:`latex_document` to ``path``.

    >>> import tempfile, pathlib
    >>> write_latex_document(pathlib.Path(tempfile.mkdtemp()) / "f.tex").suffix
    '.tex'
    """
    return write_text(path, latex_document(n_terms))
