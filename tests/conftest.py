"""Shared test set-up: the one LaTeX policy, and the independent references on the path.

``tests/`` is on ``sys.path`` (pytest's rootdir insertion for a directory without
``__init__.py``), so test modules import the references as ``references.<name>``.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from collections.abc import Callable
from pathlib import Path

import pytest


def require_latex() -> str:
    """Path of ``pdflatex`` for a test that compiles LaTeX.

    The one policy for every LaTeX test: without an engine the test is skipped on a
    developer machine, but fails when the ``CI`` environment variable is set (CI installs
    the engine, so a missing one there is a broken set-up, not a reason to skip).
    """
    engine = shutil.which("pdflatex")
    if engine is None:
        if os.environ.get("CI"):
            pytest.fail("CI is set but pdflatex is not installed (.ci/run installs it)")
        pytest.skip("pdflatex is not installed (CI installs it and runs this test)")
    return engine


@pytest.fixture
def pdflatex() -> str:
    """The LaTeX engine, under :func:`require_latex`'s skip-or-fail policy."""
    return require_latex()


@pytest.fixture
def compile_latex(pdflatex: str) -> Callable[[Path], subprocess.CompletedProcess]:
    """``compile_latex(tex)`` runs the engine on ``tex`` in its directory, stopping at the
    first error (never waiting for input); returns the completed process."""

    def run(tex: Path) -> subprocess.CompletedProcess:
        return subprocess.run(
            [pdflatex, "-interaction=nonstopmode", "-halt-on-error", tex.name],
            cwd=tex.parent,
            capture_output=True,
            text=True,
            check=False,
            stdin=subprocess.DEVNULL,
            timeout=120,
        )

    return run


#: A string that leaves the file ``PWNED`` behind if it is ever run as code: the probe of
#: every "no input runs code" test (``from conftest import CODE``).
CODE = "__import__('os').system('touch PWNED')"


@pytest.fixture
def no_code_runs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    """Run in an empty directory; afterwards no string may have been executed.

    Modules that feed :data:`CODE` to public functions use it for every test:
    ``pytestmark = pytest.mark.usefixtures("no_code_runs")``.
    """
    monkeypatch.chdir(tmp_path)
    yield
    assert not (tmp_path / "PWNED").exists(), "a string input was run as code"
