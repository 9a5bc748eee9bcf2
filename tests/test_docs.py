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
BUILD_PACKAGES = ("sphinx", "myst_nb", "furo", "numpydoc", "sphinx-mathjax-offline")
README = (ROOT / "README.md").read_text()
#: a tag that loads a script, style sheet, font or image from another host
REMOTE = re.compile(r"<(?:script|link|img|iframe)\b[^>]*\b(?:src|href)=\"(?:https?:)?//", re.I)


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


def fenced(language: str, text: str) -> list[str]:
    """Bodies of the ```language fenced blocks of ``text``, in order."""
    return re.findall(rf"^```{language}\n(.*?)^```", text, flags=re.M | re.S)


def readme_section(title: str) -> str:
    """The README text under the ``## title`` heading, up to the next ``## ``."""
    start = README.index(f"\n## {title}")
    end = README.find("\n## ", start + 1)
    return README[start : end if end >= 0 else None]


def pip_commands(text: str) -> set[str]:
    """Every ``pip install ...`` command of ``text``, in code blocks or inline code."""
    blocks = [line for block in fenced("bash", text) for line in block.splitlines()]
    inline = re.findall(r"`(pip install [^`]+)`", text)
    return {line.strip() for line in blocks + inline if line.strip().startswith("pip install")}


def conf_value(name: str):
    """The literal assigned to ``name`` in ``docs/conf.py`` (read, not executed: importing
    the configuration copies the notebooks)."""
    tree = ast.parse((DOCS / "conf.py").read_text())
    for node in tree.body:
        targets = getattr(node, "targets", None) or [getattr(node, "target", None)]
        if any(isinstance(t, ast.Name) and t.id == name for t in targets) and node.value:
            return ast.literal_eval(node.value)
    raise KeyError(name)


def test_install_page_shows_the_readme_commands():
    # the README's set-up and documentation commands, verbatim and as commands to copy
    page = (DOCS / "getting_started.md").read_text()
    shown = fenced("bash", page)
    wanted = fenced("bash", readme_section("Set-up")) + fenced(
        "bash", readme_section("Documentation")
    )
    assert len(wanted) >= 3  # install + reproduce, install + tests, install + docs build
    for block in wanted:
        assert block in shown, f"getting_started.md lacks the README's command {block!r}"
    # and no page of the site shows an install command the README does not
    readme = pip_commands(README)
    for path in sorted(DOCS.glob("*.md")):
        stray = pip_commands(path.read_text()) - readme
        assert not stray, f"{path.name} shows {sorted(stray)}, which the README does not"


def test_front_page_lists_the_analyses_the_readme_lists():
    def rows(text: str) -> dict[str, set[str]]:
        """Numbered table rows: number -> the impactsym packages and names they cite."""
        found = {}
        for number, rest in re.findall(r"^\| (\d+)\. (.*)$", text, flags=re.M):
            packages = re.findall(r"impactsym\.\w+", rest)
            found[number] = set(packages) | set(re.findall(r"\b\w+_sequence\b", rest))
        return found

    readme, index = rows(README), rows((DOCS / "index.md").read_text())
    assert sorted(readme) == ["1", "2", "3", "4"]
    assert sorted(index) == sorted(readme)
    for number, names in readme.items():
        assert names <= index[number], f"row {number}: the front page lacks {names - index[number]}"
    assert "four analyses" in (DOCS / "index.md").read_text()


def test_site_uses_the_stored_notebook_outputs_and_a_local_mathjax():
    assert conf_value("nb_execution_mode") == "off"  # the test suite executes the notebooks
    assert "sphinx-mathjax-offline" in conf_value("extensions")
    path = conf_value("mathjax_path")
    assert not re.match(r"(https?:)?//", path)
    front = (DOCS / "getting_started.md").read_text().split("---")[1]
    assert "execution_mode: force" in front  # its cells have no stored outputs


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
    # nothing is loaded from another host: MathJax comes with the site
    pages = sorted(html.rglob("*.html"))
    remote = {p.name: REMOTE.findall(p.read_text()) for p in pages}
    assert not {name: hits for name, hits in remote.items() if hits}
    assert (html / "_static" / "mathjax" / "tex-chtml.js").is_file()
    physics = (html / "physics.html").read_text()
    assert '<script defer="defer" src="_static/mathjax/tex-chtml.js' in physics or (
        'src="_static/mathjax/tex-chtml.js' in physics
    )
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
