r"""The formulas of the nonlinear contact laws, labelled for ``impactsym latex NAME``.

Every formula is printed from the SymPy expression that :mod:`impactsym.contact.laws`
(the laws and their normalization, checked by substitution) and
:mod:`impactsym.contact.lawmaps` (the Hunt–Crossley closed form and the Tsuji map, checked
by their residuals) derive; nothing here is typed by hand except the words.
:mod:`impactsym.export` lists them as a section of the formula document.
"""

from __future__ import annotations

from impactsym.contact.lawmaps import HuntCrossleyClosedForm, TsujiMap
from impactsym.contact.laws import LAWS, contact_law
from impactsym.symbolic.typeset import latex

_WORDS = {
    "linear": "the linear spring-dashpot (paper section 2)",
    "hertz-linear": "a power-law spring with a linear dashpot",
    "hunt-crossley": "the Hunt-Crossley law",
    "tsuji": "a power-law spring with Tsuji's damping",
    "viscoelastic": "the viscoelastic Hertz law of Brilliantov et al.",
}


def typeset_formulas() -> list[tuple[str, str, str]]:
    r"""``(label, sentence, LaTeX)`` of the nonlinear-law formulas, in document order.

    >>> [label for label, _, _ in typeset_formulas()][-2:]
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
    return items
