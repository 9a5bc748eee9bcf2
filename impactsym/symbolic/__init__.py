"""Symbolic machinery shared by the analyses.

* :mod:`~impactsym.symbolic.laplace` -- delay series in :math:`e^{-sT}` and their exact
  term-by-term inverse Laplace transform;
* :mod:`~impactsym.symbolic.rational` -- exact inverse transform of one rational term from
  its partial fractions;
* :mod:`~impactsym.symbolic.series` -- the division-free truncated power series behind it;
* :mod:`~impactsym.symbolic.transform` -- the forward transform of exponential
  polynomials, for round-trip checks;
* :mod:`~impactsym.symbolic.typeset` -- the derived formulas as LaTeX an author would keep.
"""
