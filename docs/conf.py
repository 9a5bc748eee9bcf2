"""Sphinx configuration of the impactsym documentation site.

Build (README): ``sphinx-build -W --keep-going -b html docs docs/_build/html``.

* API reference: ``autosummary`` writes one page per module listed in ``api.md``
  (``docs/api/`` is generated, not committed); ``numpydoc`` renders the docstrings.
* Notebooks: the narrative notebooks live in the repository's ``notebooks/`` with their
  outputs stored (the test suite executes each from a clean kernel and checks that the
  stored outputs are current, ``tests/notebook_runner.py``). Sphinx reads sources from
  ``docs/`` only, so this file copies them into ``docs/notebooks/`` (generated, not
  committed) before the build reads any source, and myst-nb shows the stored outputs
  (``nb_execution_mode = "off"``): the notebooks are not executed a second time. The
  code cells of ``getting_started.md`` have no stored outputs; that page asks for
  execution in its own front matter.
* Math: MathJax is served from the site itself (``_static/mathjax``, copied from the
  ``sphinx-mathjax-offline`` package), never from a CDN, so the pages show typeset math
  offline; ``tests/test_docs.py`` checks that no built page loads anything from the web.
"""

from __future__ import annotations

import importlib
import os
import sys
import tempfile
import types
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent

# The package documented is the one in this checkout, also for the notebook kernels
# (they run in subprocesses and inherit the environment).
sys.path.insert(0, str(ROOT))
os.environ["PYTHONPATH"] = os.pathsep.join(
    p for p in (str(ROOT), os.environ.get("PYTHONPATH", "")) if p
)
# Figures inline in the executed notebooks, whatever backend the calling shell chose
# (an inherited MPLBACKEND=Agg would silently drop every figure from the pages).
os.environ["MPLBACKEND"] = "module://matplotlib_inline.backend_inline"

import impactsym  # noqa: E402


def _copy_notebooks() -> None:
    """Mirror ``notebooks/*.ipynb`` into ``docs/notebooks/``; unchanged files are kept.

    Each file is written to a temporary name and renamed, so two builds running at the
    same time never read a half-written notebook.
    """
    target = DOCS / "notebooks"
    target.mkdir(exist_ok=True)
    sources = sorted((ROOT / "notebooks").glob("*.ipynb"))
    for stale in set(target.glob("*.ipynb")) - {target / s.name for s in sources}:
        stale.unlink()
    for source in sources:
        destination = target / source.name
        data = source.read_bytes()
        if destination.is_file() and destination.read_bytes() == data:
            continue
        fd, tmp = tempfile.mkstemp(dir=target, suffix=".tmp")
        with os.fdopen(fd, "wb") as stream:
            stream.write(data)
        os.replace(tmp, destination)


_copy_notebooks()

# -- project -----------------------------------------------------------------------------
project = "impactsym"
author = "impactsym developers"
copyright = "2026, impactsym developers"
release = version = impactsym.__version__

# -- general -----------------------------------------------------------------------------
extensions = [
    "myst_nb",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx-mathjax-offline",  # MathJax 3 served from _static/mathjax: the site works offline
    "sphinx.ext.viewcode",
    "numpydoc",
]
source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".ipynb": "myst-nb"}
templates_path = ["_templates"]
exclude_patterns = ["_build", "**.ipynb_checkpoints", "notebooks/*.tmp", "README.md"]
root_doc = "index"

# -- API reference -----------------------------------------------------------------------
autosummary_generate = True
autosummary_imported_members = False
autosummary_ignore_module_all = False  # a module's __all__ is its public API
autodoc_default_options = {"members": True, "member-order": "bysource"}
autodoc_typehints = "signature"
autodoc_preserve_defaults = True
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

# -- MyST and notebooks ------------------------------------------------------------------
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3
nb_execution_mode = "off"  # stored outputs; getting_started.md executes (front matter)
nb_execution_timeout = 900
nb_execution_raise_on_error = True
nb_execution_show_tb = True
nb_merge_streams = True

# -- math ------------------------------------------------------------------------------
# the local copy of MathJax (the extension also sets this; stated here so it is visible)
mathjax_path = "mathjax/tex-chtml.js"

# -- HTML --------------------------------------------------------------------------------
html_theme = "furo"
html_title = f"impactsym {release}"
html_static_path: list[str] = []


# -- links to the lazily exported public names -------------------------------------------
def _lazy_targets() -> dict[str, str]:
    """``"impactsym.contact.contact_time" -> "impactsym.contact.api.contact_time"``, etc.

    A package exports its public names lazily (``_NAMES``: name -> defining module); the
    reference documents each object once, in its defining module, and a reference to the
    public path is redirected there. Every package of ``impactsym`` is asked.
    """
    targets = {}
    for init in sorted((ROOT / "impactsym").rglob("__init__.py")):
        package = ".".join(init.parent.relative_to(ROOT).parts)
        names = getattr(importlib.import_module(package), "_NAMES", {})
        targets.update({f"{package}.{n}": f"{module}.{n}" for n, module in names.items()})
    return targets


LAZY_TARGETS = _lazy_targets()


def _defining_path(name: str) -> str | None:
    """Where the public ``name`` -- or the object it is a member of -- is documented.

    >>> _defining_path("impactsym.rod.RodImpact.series")
    'impactsym.rod.derivation.RodImpact.series'
    """
    parts = name.split(".")
    for cut in range(len(parts), 1, -1):
        public = ".".join(parts[:cut])
        if public in LAZY_TARGETS:
            return ".".join([LAZY_TARGETS[public], *parts[cut:]])
    return None


def _resolve_lazy(app, env, node, contnode):
    """``missing-reference`` handler: retry a Python reference at its defining path."""
    if node.get("refdomain") != "py":
        return None
    target = node["reftarget"].lstrip(".~")
    candidates = [target]
    for context in (node.get("py:class"), node.get("py:module")):
        if context:
            candidates.append(f"{context}.{target}")
    for candidate in candidates:
        real = _defining_path(candidate)
        if real is not None:
            return env.get_domain("py").resolve_xref(
                env, node["refdoc"], app.builder, node["reftype"], real, node, contnode
            )
    return None


def _alias_signature(app, what, name, obj, options, signature, return_annotation):
    """A type alias (``DelayTerm = tuple[...]``) has no call signature.

    numpydoc takes a ``types.GenericAlias`` for a class and fails on its signature; the
    first handler to answer wins, so this one runs before numpydoc's.
    """
    if isinstance(obj, types.GenericAlias):
        return signature, return_annotation
    return None


def setup(app):
    app.connect("missing-reference", _resolve_lazy)
    app.connect("autodoc-process-signature", _alias_signature, priority=100)
