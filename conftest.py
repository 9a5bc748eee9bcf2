"""Shared by the tests and the doctests of ``impactsym/`` (``--doctest-modules``).

Every test and doctest closes the figures it opened: doctests draw with pyplot and
never close, and past 20 open figures pyplot warns (an error under the warning filters).
"""

import sys

import pytest


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    pyplot = sys.modules.get("matplotlib.pyplot")  # only if something drew
    if pyplot is not None:
        pyplot.close("all")
