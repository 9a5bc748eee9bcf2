"""Writers for ``impactsym reproduce``: one module per analysis.

Each module exposes ``write(out, *, quick, progress) -> list[pathlib.Path]`` that
computes that analysis' results, draws them with :mod:`impactsym.plotting`, and writes
the figures (PNG and PDF with rasterized meshes, :mod:`impactsym.results.files`), tables
(CSV/JSON) and formula snippets into ``out``; it returns the files it wrote.
"""
