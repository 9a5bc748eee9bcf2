r"""The formulas of the nonlinear contact laws, labelled for ``impactsym latex NAME``.

Every formula is printed from the SymPy expression that :mod:`impactsym.contact.laws`
(the laws and their normalization, checked by substitution) and
:mod:`impactsym.contact.lawmaps` (the Hunt–Crossley closed form and the Tsuji map, checked
by their residuals) derive; nothing here is typed by hand except the words.
:mod:`impactsym.export` lists them as a section of the formula document.
"""

from __future__ import annotations

import sympy as sp

from impactsym.contact.lawmaps import HuntCrossleyClosedForm, TsujiMap
from impactsym.contact.laws import LAWS, contact_law
from impactsym.contact.viscoseries import (
    C1_UNIVERSAL,
    KAPPA,
    delayed_recovery_coefficients,
    position_polynomials,
)
from impactsym.symbolic.typeset import AuthorLatexPrinter, latex

_WORDS = {
    "linear": "the linear spring-dashpot (paper section 2)",
    "hertz-linear": "a power-law spring with a linear dashpot",
    "hunt-crossley": "the Hunt-Crossley law",
    "tsuji": "a power-law spring with Tsuji's damping",
    "viscoelastic": "the viscoelastic Hertz law of Brilliantov et al.",
}


def typeset_formulas() -> list[tuple[str, str, str]]:
    r"""``(label, sentence, LaTeX)`` of the nonlinear-law formulas, in document order.

    >>> [label for label, _, _ in typeset_formulas()][-5:-3]
    ['law-hunt-crossley-contact-time', 'law-tsuji-map']
    >>> print(typeset_formulas()[5][2])
    e = \frac{W\left(\left(- s - 1\right) e^{- s - 1}\right) + 1}{s}
    """
    items = [
        (
            f"law-{name}-normalization",
            f"Normalization of {_WORDS[name]}: the force, the normalized equation, the time "
            f"scale, the damping number ${latex(contact_law(name).number)}$ and the pressing "
            "number $f$.",
            contact_law(name).latex(),
        )
        for name in LAWS
    ]
    hc = HuntCrossleyClosedForm()
    items += [
        (
            "law-hunt-crossley-restitution",
            r"Restitution of the Hunt-Crossley contact without pressing force: for $s = "
            r"\lambda v_0$ and every $k$ and $p$ ($W$ the principal branch $W_0$ of "
            r"Lambert's function), the root other than $-1$ of the energy balance in the "
            r"phase plane.",
            rf"e = {latex(hc.restitution)}",
        ),
        (
            "law-hunt-crossley-max-penetration",
            "Maximum penetration of the Hunt-Crossley contact without pressing force.",
            rf"z_\mathrm{{max}} = {latex(hc.max_penetration)}",
        ),
        (
            "law-hunt-crossley-contact-time",
            "Contact time of the Hunt-Crossley contact without pressing force: a "
            "quadrature over the rate $w$ from touch ($w = 1$) to release ($w = -e$).",
            rf"\tau_c = \int_{{-e}}^{{1}} {latex(hc.contact_time_integrand)}\, dw",
        ),
        (
            "law-tsuji-map",
            r"Map of a power-law spring with Tsuji's damping onto the linear contact "
            r"(Antypov and Elliott 2011): with $x$ for $z$ the phase-plane equation is the "
            r"linear contact's at damping ratio $\zeta$, so the release speed (either "
            r"condition, no pressing force) is the linear contact's.",
            TsujiMap().latex(),
        ),
    ]
    return items + viscoelastic_formulas()


def viscoelastic_formulas() -> list[tuple[str, str, str]]:
    r"""``(label, sentence, LaTeX)`` of the viscoelastic restitution series
    (:mod:`impactsym.contact.viscoseries`): its exact terms and the delayed recovery.

    >>> print(viscoelastic_formulas()[0][2])
    e = 1 - C_{1} \beta + \frac{3 C_{1}^{2} \beta^{2}}{5} + \mathcal{O}\left(\beta^{5/2}\right)
    """
    beta, C_1, e_p = sp.symbols("beta C_1 e_p", positive=True)
    c_1, kappa = sp.symbols("c_1 kappa")
    exact = sp.Add(
        *(h.subs(c_1, C_1 / kappa) * beta**k for k, h in enumerate(position_polynomials(2))),
        evaluate=False,
    )
    g = delayed_recovery_coefficients(2)
    t = beta ** sp.Rational(5, 2) * sp.sqrt(e_p)
    ascending = AuthorLatexPrinter({"order": "none"}).doprint  # the terms as given
    recovery = sp.Add(
        *(sp.Rational(x.numerator, x.denominator) * t**n for n, x in enumerate(g)),
        evaluate=False,
    )
    return [
        (
            "law-viscoelastic-restitution-series",
            r"Restitution of the viscoelastic contact without pressing force, either "
            r"condition, as a series in $\beta = \tfrac32 A (k/m)^{2/5} v_0^{1/5}$: the "
            r"terms exact in Gamma functions (Ram\'irez et al. 1999, $C_2 = \tfrac35 "
            r"C_1^2$); from $\beta^3$ on the coefficients are iterated integrals; the remainder "
            r"is $\mathcal{O}(\beta^3)$ under the position condition, and the force "
            r"condition adds $\tfrac{4}{15}\beta^{5/2}$.",
            rf"e = {ascending(exact)} + \mathcal{{O}}\left(\beta^{{5/2}}\right)",
        ),
        (
            "law-viscoelastic-c1",
            r"The constant $C_1$ of the viscoelastic restitution series: $\kappa c_1$ with "
            r"$c_1 = \tfrac25 B(\tfrac35, \tfrac32)$, $\kappa = 2 (5/4)^{3/5}$.",
            rf"C_{{1}} = {latex(sp.expand(KAPPA * C1_UNIVERSAL))}",
        ),
        (
            "law-viscoelastic-delayed-recovery",
            r"Restitution of the viscoelastic contact under the force condition (delayed "
            r"recovery: the force vanishes at $z = \beta |z'|$) from the position "
            r"condition's $e_p$, with rational coefficients.",
            rf"e = e_{{p}} \left({ascending(recovery)} + \mathcal{{O}}\left(\beta^{{15/2}}"
            r"\right)\right)",
        ),
    ]
