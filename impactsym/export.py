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

from impactsym._files import write_text
from impactsym.contact import derivation
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
    from impactsym.contact import lawlatex
    from impactsym.multibody import reduction as multibody
    from impactsym.rod import derivation as rod

    return [
        (SECTIONS[0], rod.typeset_formulas(n_terms)),
        (SECTIONS[1], derivation.typeset_formulas()),
        (SECTIONS[2], multibody.typeset_formulas()),
        (SECTIONS[3], lawlatex.typeset_formulas()),
    ]


#: Section titles of the formula document, one per analysis of the paper
SECTIONS = (
    "Rod impact (paper section 1)",
    "Spring-damper contact (paper section 2)",
    "Multibody penalty contact (paper section 3)",
    "Nonlinear contact laws",
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
    r"A body of mass $m$ hits a contact element at speed $v_0$ under a constant pressing "
    r"force $F_0$ ($d$ the overlap); each law is normalized with the time $T$ at which spring "
    r"and inertia balance and the length $L = v_0 T$, which leaves a damping number and a "
    r"pressing number $f$ ($z = d/L$, $w = z'$, primes on $z$ derivatives in $t/T$).",
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

#: The docstring of the exported module.
_MODULE_DOC = """impactsym's section-1 and section-2 results as NumPy functions (generated).

Waltersberger, Keppler and Wauer, PAMM 2004. Written by ``impactsym export python FILE``
(impactsym {version}) from the package's own source: its kernels, root finders and input
checks, and the closed forms it derived with SymPy; it needs NumPy only. The functions
give the package's numbers, check their inputs as it does (errors name the argument)
and need ``condition=`` where the two contact conditions differ.

* Spring-damper contact (section 2): ``contact_time``, ``restitution``,
  ``stick_boundary``, ``ridge_time``, ``contact_surface``, ``physical_contact``; the
  contact functions, ridge times and boundary function of each condition
  (``contact_function_force``, ``ridge_time_force``, ``boundary_force``, ...).
* Rod impact, rigid contact (section 1): ``rod_displacement``, ``rod_contact_force``,
  ``rod_contact_time`` (a finite contact stiffness needs impactsym itself).
"""


def python_module() -> str:
    """Source of a NumPy-only module with the section-2 contact and the rigid rod functions.

    :func:`impactsym.contact.codegen.contact_items` and
    :func:`impactsym.rod.codegen.rod_items` with everything they use
    (:func:`impactsym.numeric.pysource.collect`), in one module
    (:func:`impactsym.numeric.pysource.module_source`).

    >>> source = python_module()
    >>> "import sympy" in source, "def stick_boundary(f: ArrayLike, *, condition: str)" in source
    (False, True)
    """
    from impactsym import __version__
    from impactsym.contact.codegen import CONTACT_EXPORTS, contact_items
    from impactsym.numeric.pysource import collect, module_source
    from impactsym.rod.codegen import ROD_EXPORTS, rod_items

    return module_source(
        _MODULE_DOC.format(version=__version__),
        collect([*contact_items(), *rod_items()]),
        exports=(*CONTACT_EXPORTS, *ROD_EXPORTS),
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
