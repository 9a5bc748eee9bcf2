"""docs/nonlinear_contact.md: its examples print what the code prints, its formulas are
those that ``impactsym latex`` prints, its table is formula_table's, and the site lists it."""

from __future__ import annotations

import doctest
import re
from pathlib import Path

import numpy as np

from impactsym.contact.lawformulas import LABELS, formula_table
from impactsym.contact.lawlatex import typeset_formulas

DOCS = Path(__file__).resolve().parents[1] / "docs"
PAGE = (DOCS / "nonlinear_contact.md").read_text()


def test_the_examples_print_what_the_code_prints():
    blocks = re.findall(r"^```pycon\n(.*?)^```", PAGE, flags=re.M | re.S)
    assert len(blocks) == 3
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE)
    globs: dict = {}
    for index, block in enumerate(blocks):
        test = doctest.DocTestParser().get_doctest(block, globs, f"example {index + 1}", None, 0)
        test.globs = globs  # one session over the page, as a reader runs it
        runner.run(test, clear_globs=False)
    result = runner.summarize(verbose=False)
    assert result.attempted >= 12
    assert result.failed == 0


def test_the_formulas_are_those_impactsym_latex_prints():
    latex = {label: text for label, _, text in typeset_formulas()}
    shown = re.findall(r"```\{math\}\n(.*?)\n\s*```", PAGE, flags=re.S)
    shown = [block.strip() for block in shown]
    names = ("linear", "hertz-linear", "hunt-crossley", "tsuji", "viscoelastic")
    for label in [f"law-{n}-normalization" for n in names] + [
        "law-hunt-crossley-restitution",
        "law-tsuji-map",
    ]:
        assert latex[label].strip() in shown, label
        assert f"`{label}`" in PAGE, label


def test_the_formula_table_is_the_computed_one():
    targets = [0.1, 0.2, 0.5, 0.8, 0.95]
    table = formula_table(targets)
    for formula, row in zip(table.formulas, table.delivered, strict=True):
        line = re.search(rf"^\| {re.escape(LABELS[formula])} \|(.*)\|$", PAGE, flags=re.M)
        shown = [float(v) for v in line.group(1).split("|")]
        np.testing.assert_array_equal(shown, np.round(row, 3))


def test_the_site_lists_the_page_and_its_figure():
    toctree = re.search(r"```\{toctree\}(.*?)```", (DOCS / "index.md").read_text(), re.S)
    assert "\nnonlinear_contact\n" in toctree.group(1)
    for image in re.findall(r"!\[[^\]]*\]\(([^)]+)\)", PAGE):
        assert (DOCS / image).is_file(), image
    assert "notebooks/06_nonlinear_contact" in (DOCS / "notebooks.md").read_text()
