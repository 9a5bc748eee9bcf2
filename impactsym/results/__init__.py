"""Writers for ``impactsym reproduce``: one module per analysis.

Each module exposes ``write(out, *, quick, progress) -> list[pathlib.Path]`` that
writes that analysis' figures (PNG and PDF), tables (CSV/JSON) and formula
snippets into ``out`` and returns the files it wrote.
"""
