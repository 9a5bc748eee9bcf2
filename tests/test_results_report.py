"""The report of ``impactsym reproduce`` (:mod:`impactsym.results.report`): ``index.html``
parsed with :mod:`html.parser`, ``report.md`` read as text; every figure shown with its
caption and links that resolve inside the output directory, tables rendered, nothing
fetched from a network, math without TeX."""

from __future__ import annotations

import importlib
import re
from html.parser import HTMLParser
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import pytest

from impactsym.reproduce import STEPS
from impactsym.results.files import save_figure, write_csv, write_text
from impactsym.results.report import caption_html, caption_markdown, png_size, write_report

matplotlib.use("Agg")


class Page(HTMLParser):
    """Every tag with its attributes, the text of each figcaption, table and h3."""

    def __init__(self) -> None:
        super().__init__()
        self.tags: list[tuple[str, dict[str, str | None]]] = []
        self.text: list[str] = []
        self.captions: dict[str, str] = {}
        self.tables: list[list[list[str]]] = []
        self._figure: str | None = None
        self._in_caption = False
        self._cell: list[str] | None = None

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        self.tags.append((tag, attrs))
        if tag == "figure":
            self._figure = attrs.get("id")
            self.captions[self._figure] = ""
        elif tag == "figcaption":
            self._in_caption = True
        elif tag == "table":
            self.tables.append([])
        elif tag == "tr":
            self.tables[-1].append([])
        elif tag in ("td", "th"):
            self._cell = []

    def handle_endtag(self, tag):
        if tag == "figcaption":
            self._in_caption = False
        elif tag in ("td", "th") and self._cell is not None:
            self.tables[-1][-1].append("".join(self._cell))
            self._cell = None

    def handle_data(self, data):
        self.text.append(data)
        if self._in_caption and self._figure is not None:
            self.captions[self._figure] += data
        if self._cell is not None:
            self._cell.append(data)

    def links(self) -> list[str]:
        return [
            value
            for _, attrs in self.tags
            for key, value in attrs.items()
            if key in ("href", "src") and value is not None
        ]


def parse(path: Path) -> Page:
    page = Page()
    page.feed(path.read_text(encoding="utf-8"))
    page.close()
    return page


def _check_links_stay_inside(out: Path, links: list[str]) -> None:
    for link in links:
        assert not re.match(r"[a-z][a-z0-9+.-]*:", link, re.IGNORECASE), link  # no URL
        if link.startswith("#"):
            continue
        assert "/" not in link, link
        assert "\\" not in link, link
        assert (out / link).is_file(), f"{link} does not resolve to a file in {out}"


def _markdown_links(text: str) -> list[str]:
    return re.findall(r"\]\(([^)]+)\)", text)


@pytest.fixture
def output(tmp_path):
    """A small output directory: a normal and a wide figure, two tables, a JSON file."""
    out = tmp_path / "out"
    out.mkdir()
    _, ax = plt.subplots(figsize=(4, 3))
    ax.plot([0, 1], [0, 1])
    files = save_figure(ax, out, "small_figure")
    _, ax = plt.subplots(figsize=(12, 3))
    ax.plot([0, 1], [1, 0])
    files += save_figure(ax, out, "wide_atlas")
    files.append(write_csv(out / "small.csv", ["x", "y"], [(i / 3, i**2) for i in range(20)]))
    files.append(write_csv(out / "atlas.csv", ["a"], [(1.0,)]))
    files.append(write_text(out / "designs.json", '{"k": 1}\n'))
    captions = {
        "small_figure": "A small figure of τ_{c} over D^{2} & <friends>.",
        "wide_atlas": "A wide atlas.",
        "small.csv": "Twenty rows.",
        "atlas.csv": "The atlas data.",
        "designs.json": "Designs.",
    }
    sections = [("First analysis", files[:2] + files[4:5]), ("Second one", files[2:4] + files[5:])]
    data = {"small_figure": ("small.csv", "designs.json"), "wide": ("atlas.csv",)}
    write_report(out, files, captions, sections=sections, data=data)
    return out, files, captions


def test_every_figure_is_shown_with_its_caption_pdf_and_data(output):
    out, _, _ = output
    page = parse(out / "index.html")
    images = {attrs["src"] for tag, attrs in page.tags if tag == "img"}
    assert images == {"small_figure.png", "wide_atlas.png"}
    links = page.links()
    _check_links_stay_inside(out, links)
    for name in ("small_figure.pdf", "wide_atlas.pdf", "small.csv", "designs.json", "atlas.csv"):
        assert name in links
    assert "A small figure of τc over D2 & <friends>." in page.captions["small_figure"]
    assert "A wide atlas." in page.captions["wide_atlas"]
    # the figure links its own data, and the data link sits inside its figure
    html = (out / "index.html").read_text()
    small = html[html.index('<figure id="small_figure"') :]
    small = small[: small.index("</figure>")]
    assert 'href="small.csv"' in small
    assert 'href="designs.json"' in small
    assert 'href="atlas.csv"' not in small


def test_the_page_has_contents_style_and_nothing_from_a_network(output):
    out, _, _ = output
    text = (out / "index.html").read_text()
    page = parse(out / "index.html")
    assert not re.search(r"https?:|//[a-z]", text, re.IGNORECASE)
    assert not [tag for tag, _ in page.tags if tag in ("script", "link", "iframe")]
    assert [tag for tag, _ in page.tags if tag == "style"]
    contents = [attrs["href"] for tag, attrs in page.tags if tag == "a" and attrs.get("href", "")]
    ids = {attrs["id"] for _, attrs in page.tags if "id" in attrs}
    anchors = [h[1:] for h in contents if h.startswith("#")]
    assert {"first-analysis", "second-one", "small_figure", "wide_atlas"} <= set(anchors)
    assert set(anchors) <= ids


def test_only_wide_figures_get_an_in_place_zoom(output):
    out, _, _ = output
    width, height = png_size(out / "wide_atlas.png")
    assert width > 3 * height
    page = parse(out / "index.html")
    zooms = [attrs for tag, attrs in page.tags if tag == "details"]
    assert len(zooms) == 1
    html = (out / "index.html").read_text()
    zoom = html[html.index('<details class="zoom">') :]
    assert zoom[: zoom.index("</details>")].count('src="wide_atlas.png"') == 1


def test_tables_are_rendered_with_a_link_to_the_whole(output):
    out, _, _ = output
    page = parse(out / "index.html")
    assert len(page.tables) == 2
    small = page.tables[0]
    assert small[0] == ["x", "y"]
    assert small[2] == ["0.333333", "1"]  # 17 digits in the file, 6 in the report
    assert len(small) == 1 + 8
    assert "first 8 of 20 rows" in "".join(page.text)


def test_the_markdown_report_shows_the_same(output):
    out, _, _ = output
    text = (out / "report.md").read_text()
    _check_links_stay_inside(out, _markdown_links(text))
    assert "[![small_figure](small_figure.png)](small_figure.png)" in text
    assert "[PDF](small_figure.pdf)" in text
    assert "[data: small.csv](small.csv)" in text
    assert "τ<sub>c</sub> over D<sup>2</sup> & \\<friends\\>." in text
    assert "| x | y |" in text
    assert "| 0.333333 | 1 |" in text
    assert not re.search(r"https?:", text)


def test_caption_marks_become_sub_and_superscripts():
    assert caption_html("e^{−2/α} and t_{c}") == "e<sup>−2/α</sup> and t<sub>c</sub>"
    assert caption_markdown("m_{eff} = 2*x") == "m<sub>eff</sub> = 2\\*x"
    assert caption_html("a < b & c") == "a &lt; b &amp; c"


def _all_captions() -> dict[str, str]:
    captions = {}
    for _, name in STEPS:
        captions.update(getattr(importlib.import_module(name), "CAPTIONS", {}))
    return captions


def test_captions_carry_no_tex_to_render():
    # math is plain Unicode with _{...}/^{...} marks: nothing for MathJax or a CDN to do
    for key, text in _all_captions().items():
        assert "$" not in text, key
        assert "\\" not in text, key
        assert not re.search(r"\^(?!\{)", text), key
        assert not re.search(r"\b(sqrt|tau|omega|alpha|kappa|pi)\b", text), (key, text)


def test_every_figure_of_every_step_names_data_files_that_have_captions():
    for _, name in STEPS:
        module = importlib.import_module(name)
        for stem, names in getattr(module, "DATA", {}).items():
            assert names, stem
            for data in names:
                assert data.endswith((".csv", ".json")), data
                assert data in module.CAPTIONS or any(
                    data.startswith(key) for key in module.CAPTIONS
                ), data
