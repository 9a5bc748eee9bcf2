"""The nonlinear-law formulas of ``impactsym latex``: listed, printed, compiled, and read back
from their LaTeX by an independent reader, checked against independent references (the
NumPy normalization of ``impact``, mpmath roots of the energy balance, scipy's solve_ivp)."""

from __future__ import annotations

import re

import mpmath
import numpy as np
import pytest
import sympy as sp
from references import latex_reader
from scipy.integrate import solve_ivp

from impactsym.cli import main
from impactsym.contact.lawlatex import typeset_formulas
from impactsym.contact.laws import LAWS
from impactsym.contact.nonlinear import impact
from impactsym.export import formulas
from impactsym.results.documents import compile_latex

LABELS = [label for label, _, _ in typeset_formulas()]
FORMULAS = {label: text for label, _, text in typeset_formulas()}
READER_FUNCTIONS = {"LambertW": sp.LambertW, "log": sp.log}


@pytest.fixture
def reader(monkeypatch):
    """The test reader with the few names these formulas add."""
    for command, name in ((r"\zeta", "zeta"), (r"\beta", "beta"), (r"\lambda", "lam")):
        monkeypatch.setitem(latex_reader.NAMES, command, name)
    for command, name in ((r"\LambertW", "LambertW"), (r"\log", "log")):
        monkeypatch.setitem(latex_reader.FUNCTIONS, command, name)

    def read(text: str) -> sp.Expr:
        text = text.replace(r"W\left(", r"\LambertW\left(")
        text = re.sub(r"\\log\{(\\left\(.*?\\right\))\}", r"\\log\1", text)
        text = re.sub(r"\\sqrt\[(\d+)\]\{(.*?\})\}", r"\\left(\2\\right)^{\\frac{1}{\1}}", text)
        return latex_reader.read(f"y = {text}", READER_FUNCTIONS)["rhs"]

    return read


def evaluate(expr: sp.Expr, **values: float) -> float:
    with mpmath.workdps(30):
        return float(expr.subs({sp.Symbol(k): mpmath.mpf(v) for k, v in values.items()}).evalf(30))


def test_every_law_formula_is_listed_and_printed_by_the_command_line(capsys):
    assert [f"law-{law}-normalization" for law in LAWS] == LABELS[: len(LAWS)]
    assert "law-hunt-crossley-restitution" in LABELS
    assert "law-tsuji-map" in LABELS
    assert main(["latex", "--list"]) == 0
    listed = [line.split()[0] for line in capsys.readouterr().out.splitlines()]
    assert [name for name in listed if name.startswith("law-")] == LABELS
    assert main(["latex", "law-hunt-crossley-restitution"]) == 0
    assert capsys.readouterr().out.strip() == FORMULAS["law-hunt-crossley-restitution"]
    # the document's section is this module's list, unchanged
    (section,) = [items for title, items in formulas() if title == "Nonlinear contact laws"]
    assert section == typeset_formulas()


def test_the_law_formulas_compile_with_pdflatex(tmp_path, pdflatex):
    body = "\n".join(
        rf"\noindent {label}\begin{{equation}}{text}\end{{equation}}"
        for label, _, text in typeset_formulas()
    )
    tex = tmp_path / "laws.tex"
    tex.write_text(
        "\\documentclass{article}\\usepackage{amsmath}\\begin{document}\n"
        + body.replace("law-", "law:")
        + "\n\\end{document}\n"
    )
    assert compile_latex(tex, tmp_path).read_bytes().startswith(b"%PDF")


@pytest.mark.parametrize("law", LAWS)
def test_normalization_read_back_is_the_numpy_normalization_of_impact(law, reader):
    # the rows "T = ..." and "delta = ..., f = ..." of the LaTeX against impact's fields
    rows = FORMULAS[f"law-{law}-normalization"].split(r" \\")
    time_row = rows[2].split("&=")[1].split(r",\quad")[0]
    damping_row, pressing_row = rows[3].split("&=")[1].split(r",\quad f =")
    T, delta, f = (reader(text) for text in (time_row, damping_row, pressing_row))
    rng = np.random.default_rng(len(law))
    k, m, v0, F, p = rng.uniform([1e2, 0.1, 0.5, 0.1, 1.0], [1e4, 3, 3, 1, 2.5], (3, 5)).T
    c = {"linear": 1.0, "hertz-linear": 1.0, "viscoelastic": 0.01}.get(law, 0.4) * rng.uniform(
        0.5, 1.5, 3
    )
    r = impact(law, stiffness=k, damping=c, mass=m, speed=v0, force=F, exponent=p,
               condition="position")  # fmt: skip
    for i in range(3):
        names = {"k": k[i], "m": m[i], "v_0": v0[i], "F_0": F[i], "p": p[i]}
        names |= dict.fromkeys(("c", "lam", "alpha", "A"), c[i])
        t_value = evaluate(T, **names)
        assert t_value == pytest.approx(r.time_scale[i], rel=1e-13)
        assert evaluate(delta, T=t_value, **names) == pytest.approx(r.damping_number[i], rel=1e-13)
        assert evaluate(f, T=t_value, **names) == pytest.approx(r.pressing_number[i], rel=1e-13)


def test_hunt_crossley_restitution_read_back_solves_the_energy_balance(reader):
    # G(-e) = G(1), G(w) = w/s - ln(1 + s w)/s^2: the exit of w dw/(1 + s w) = -z^p dz
    e_of = reader(FORMULAS["law-hunt-crossley-restitution"].split("=", 1)[1])
    for s_value in (0.05, 0.7, 2.083, 9.0):
        with mpmath.workdps(40):
            s = mpmath.mpf(s_value)

            def G(w, s=s):
                return w / s - mpmath.log(1 + s * w) / s**2

            root = mpmath.findroot(
                lambda e, s=s: G(-e) - G(1), (mpmath.mpf("1e-3"), 1 / s - 1e-9), solver="anderson"
            )
        assert evaluate(e_of, s=s_value) == pytest.approx(float(root), rel=1e-13)
    assert evaluate(e_of, s=2.083) == pytest.approx(0.3999, abs=1e-4)


def test_hunt_crossley_max_penetration_read_back_is_the_integrated_one(reader):
    z_max = reader(FORMULAS["law-hunt-crossley-max-penetration"].split("=", 1)[1])
    for s_value, p_value in ((0.4, 1.5), (2.0, 1.0), (1.0, 2.5)):

        def rhs(_t, y, s=s_value, p=p_value):
            return [y[1], -(max(y[0], 0.0) ** p) * (1 + s * y[1])]

        def top(_t, y):
            return y[1]

        top.terminal = True
        sol = solve_ivp(
            rhs, (0, 50), [0.0, 1.0], events=top, rtol=1e-12, atol=1e-14, method="DOP853"
        )
        want = sol.y_events[0][0][0]
        assert evaluate(z_max, s=s_value, p=p_value) == pytest.approx(want, rel=1e-9)


def test_tsuji_map_read_back_gives_the_integrated_restitution(reader):
    # the release speed of z'' = -z^p - alpha z^((p-1)/2) z' (position condition) is the
    # linear contact's exp(-zeta pi / sqrt(1 - zeta^2)) at the zeta read from the LaTeX
    zeta = reader(FORMULAS["law-tsuji-map"].split(r"\zeta =")[1])
    for alpha, p_value in ((0.5, 1.5), (1.2, 2.0), (0.3, 1.0)):

        def rhs(_t, y, a=alpha, p=p_value):
            z = max(y[0], 0.0)
            return [y[1], -(z**p) - a * z ** ((p - 1) / 2) * y[1]]

        def out(_t, y):
            return y[0] if _t > 1e-9 else 1.0

        out.terminal, out.direction = True, -1
        sol = solve_ivp(
            rhs, (0, 100), [0.0, 1.0], events=out, rtol=1e-12, atol=1e-14, method="DOP853"
        )
        e = -sol.y_events[0][0][1]
        z = evaluate(zeta, alpha=alpha, p=p_value)
        assert np.exp(-z * np.pi / np.sqrt(1 - z * z)) == pytest.approx(e, rel=1e-7)
