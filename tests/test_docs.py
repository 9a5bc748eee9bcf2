"""The documentation site builds with warnings as errors and shows what it promises."""

from __future__ import annotations

import ast
import importlib
import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
BUILD_PACKAGES = ("sphinx", "myst_nb", "furo", "numpydoc")


def require_sphinx() -> None:
    """Skip without the ``docs`` extra on a developer machine; fail under CI, which has it."""
    missing = [name for name in BUILD_PACKAGES if importlib.util.find_spec(name) is None]
    if missing:
        if os.environ.get("CI"):
            pytest.fail(f"CI is set but {missing} are not installed (pip install '.[docs]')")
        pytest.skip(f"{missing} not installed (pip install '.[docs]'; CI runs this test)")


def documented_modules() -> set[str]:
    """Dotted names listed in the autosummary blocks of ``docs/api.rst``."""
    names = set()
    for line in (DOCS / "api.rst").read_text().splitlines():
        match = re.fullmatch(r"\s+(impactsym(\.\w+)*)\s*", line)
        if match:
            names.add(match.group(1))
    return names


def package_modules() -> set[str]:
    """Every public module of the package (private modules such as ``_files`` excluded)."""
    names = set()
    for path in (ROOT / "impactsym").rglob("*.py"):
        parts = path.relative_to(ROOT).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        if any(part.startswith("_") for part in parts):
            continue
        name = ".".join(parts)
        names.add(name)
    return names


def test_api_reference_lists_every_public_module_once():
    documented = documented_modules()
    assert documented == package_modules()
    listed = [line.strip() for line in (DOCS / "api.rst").read_text().splitlines() if line.strip()]
    assert all(listed.count(name) == 1 for name in documented)


def test_tests_named_in_the_docs_exist():
    defined = set()
    for path in (ROOT / "tests").rglob("test_*.py"):
        tree = ast.parse(path.read_text())
        defined |= {node.name for node in ast.walk(tree) if isinstance(node, ast.FunctionDef)}
    cited = set()
    for page in DOCS.glob("*.md"):
        cited |= set(re.findall(r"`(test_\w+)`", page.read_text()))
    assert len(cited) > 40  # the physics and paper-to-code pages cite the checks
    assert not sorted(cited - defined)


@pytest.mark.slow
def test_site_builds_without_warnings_and_shows_executed_notebooks(tmp_path):
    require_sphinx()
    html = tmp_path / "html"
    command = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-b", "html", "-q"]
    run = subprocess.run(
        [*command, str(DOCS), str(html)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=900,
        check=False,
    )
    assert run.returncode == 0, run.stderr[-5000:]
    for notebook in sorted((ROOT / "notebooks").glob("*.ipynb")):
        page = (html / "notebooks" / notebook.with_suffix(".html").name).read_text()
        assert "<img" in page, f"{notebook.name}: no figure on the executed page"
        assert "Traceback" not in page
    assert "<img" in (html / "getting_started.html").read_text()
    for module in documented_modules():
        assert (html / "api" / f"{module}.html").is_file()
    contact = (html / "api" / "impactsym.contact.html").read_text()
    # a lazily exported name links to the module that defines it
    assert 'href="impactsym.contact.api.html#impactsym.contact.api.contact_time"' in contact
