"""Matplotlib figures, one module per analysis. Every figure function takes an
optional ``ax`` (or ``fig``) and returns it; Matplotlib is imported only here."""
