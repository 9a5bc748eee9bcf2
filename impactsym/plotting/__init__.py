"""Matplotlib figures, one module per analysis.

Plotting draws and never computes: every figure function takes the result objects or
arrays the caller computed (the analyses, :mod:`impactsym.results`, a notebook) and an
optional ``ax`` (or ``axes``), and returns the axes; no plotting module imports an
analysis. A result object's ``.plot()`` method is the one call from an analysis up into
plotting. Matplotlib is imported by the plotting modules only.
"""
