"""The free flight after a release (impactsym.contact.flight): the SymPy derivation."""

from __future__ import annotations

import sympy as sp

from impactsym.contact.derivation import D, f
from impactsym.contact.flight import FreeFlight, r, s, u, x


def test_gap_is_body_minus_relaxing_element_and_reduces_to_psi():
    flight = FreeFlight()
    d = sp.Rational(3, 7)
    assert (
        sp.simplify(2 * d * sp.diff(flight.element.subs(D, d), s) + flight.element.subs(D, d)) == 0
    )
    assert sp.diff(flight.body, s, 2) == 2 * D * f
    assert flight.body.subs(s, 0) == flight.element.subs(s, 0)  # released together
    # the body leaves with the element's relaxation speed -u: tangent separation
    assert sp.simplify((sp.diff(flight.gap, s)).subs(s, 0)) == 0
    reduced = flight.reduced_gap.subs(r, 2 * D**2 * f / u)
    assert sp.simplify(flight.gap.subs(s, 2 * D * x) - reduced) == 0
