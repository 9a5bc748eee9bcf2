"""Symbolic machinery shared by the analyses.

* :mod:`~impactsym.symbolic.laplace` -- delay series in :math:`e^{-sT}` and their exact
  term-by-term inverse Laplace transform.
"""
