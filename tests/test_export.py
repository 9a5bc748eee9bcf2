"""Generated LaTeX compiles; the generated NumPy module works without SymPy or impactsym."""

from __future__ import annotations

import ast
import json
import pickle
import re
import shutil
import subprocess
import sys

import mpmath
import numpy as np
import pytest
import sympy as sp
from references import latex_reader

from impactsym import contact_time
from impactsym.contact import derivation
from impactsym.contact.kernel import kernels
from impactsym.export import (
    PAPER_EQUATIONS,
    SECTIONS,
    formula,
    formula_names,
    formulas,
    latex_document,
    python_module,
    typeset_formulas,
)
from impactsym.results.documents import LatexError, compile_latex
from impactsym.rod import contact_force, displacement
from impactsym.symbolic.typeset import Typeset


def test_formulas_document_compiles_with_pdflatex(tmp_path, pdflatex):
    tex = tmp_path / "formulas.tex"
    tex.write_text(latex_document())
    pdf = compile_latex(tex, tmp_path)
    assert pdf.read_bytes().startswith(b"%PDF")
    for name in ("rod-eq2", "sd-ridge-force-underdamped", "mb-reduced"):
        assert f"\\label{{eq:{name}}}" in tex.read_text()


# \resizebox (graphicx) logs the natural width of what it scales and the width it scales to
MEASURE_RESIZEBOX = r"""\let\realresizebox\resizebox
\renewcommand{\resizebox}[3]{\setbox0=\hbox{#3}\setlength{\dimen0}{#1}%
\typeout{RESIZEBOX \the\wd0\space -> \the\dimen0}\realresizebox{#1}{#2}{#3}}
"""


def compile_measuring_resizes(document: str, tmp_path, compile_latex) -> tuple[list[tuple], str]:
    """Compile ``document`` with every \\resizebox logged: ([(natural, target)], log)."""
    assert "\\scalebox" not in document  # scaling goes through \resizebox only
    tex = tmp_path / "measured.tex"
    tex.write_text(
        document.replace("\\begin{document}", MEASURE_RESIZEBOX + "\\begin{document}", 1)
    )
    run = compile_latex(tex)
    log = (tmp_path / "measured.log").read_text(errors="replace")
    assert run.returncode == 0, log[-2000:]
    sizes = re.findall(r"RESIZEBOX ([\d.]+)pt\s*->\s*([\d.]+)pt", log)
    assert len(sizes) == log.count("RESIZEBOX ")  # every scaling is measured
    return [(float(a), float(b)) for a, b in sizes], log


def test_formulas_are_set_at_text_size_never_scaled_up(tmp_path, compile_latex):
    resizes, log = compile_measuring_resizes(latex_document(), tmp_path, compile_latex)
    assert all(target <= natural for natural, target in resizes), resizes
    # and no display formula runs into the margin
    assert not re.search(r"Overfull \\hbox .* detected at line", log)


def test_a_formula_wider_than_the_line_is_scaled_down_to_it(tmp_path, compile_latex):
    wide = " + ".join(f"x_{{{i}}}^{{{i}}}" for i in range(80))
    document = latex_document().replace(
        "\\end{document}", f"\\[\\fitformula{{{wide}}}\\]\n\\end{{document}}"
    )
    resizes, log = compile_measuring_resizes(document, tmp_path, compile_latex)
    assert len(resizes) == 1
    natural, target = resizes[0]
    assert natural > 1.5 * target
    assert not re.search(r"Overfull \\hbox .* detected at line", log)


def test_a_latex_error_is_reported_not_ignored(tmp_path, pdflatex):
    tex = tmp_path / "broken.tex"
    tex.write_text("\\documentclass{article}\\begin{document}$\\frac{1}{$\\end{document}\n")
    with pytest.raises(LatexError, match="pdflatex failed"):
        compile_latex(tex, tmp_path)


def test_every_formula_is_labelled_and_retrievable():
    names = formula_names()
    assert len(names) == len(set(names))
    # the retrieved formula is the ridge of the critically damped contact, derived here
    # independently: dsolve the ODE at D = 1 and solve d g_force / d tau = 0
    tau, force = sp.symbols("tau f", positive=True)
    z = sp.Function("z")
    ode = z(tau).diff(tau, 2) + 2 * z(tau).diff(tau) + z(tau) - 2 * force
    initial = {z(0): 0, z(tau).diff(tau).subs(tau, 0): 1}
    solution = sp.dsolve(ode, ics=initial).rhs
    (ridge,) = sp.solve(
        sp.simplify((2 * solution.diff(tau) + solution).diff(tau) * sp.exp(tau)), tau
    )
    form = typeset("sd-ridge-force-critical")
    assert formula("sd-ridge-force-critical") == form.latex()
    assert formula("sd-ridge-force-critical") == (
        r"\tau_r = \frac{3 - 4 f}{1 - 2 f}, \qquad \text{for } f < \frac{1}{2}"
    )
    ((expr, where),) = form.branches
    assert sp.simplify(expr.subs(derivation.f, force) - ridge) == 0
    assert where == (derivation.f < sp.Rational(1, 2))  # where that time is a minimum
    with pytest.raises(ValueError, match="no formula named 'nope'"):
        formula("nope")


# -- every typeset formula against the expression it came from ------------------------

N_TERMS = 3
SYMBOLS = {
    "tau": (0, 12),
    "f": (0, 2.5),
    "alpha": (0.1, 5),
    "s": (0.3, 6),
    "t": (0, 12),
    "kappa": (0.5, 40),
    "xi": (0, 1),
}


def typeset(name: str, n_terms: int = N_TERMS):
    for _, items in typeset_formulas(n_terms):
        for label, _, form in items:
            if label == name:
                return form
    raise KeyError(name)


def checked_forms():
    """(label, Typeset) of every formula typeset from an expression, rows included."""
    for _, items in typeset_formulas(N_TERMS):
        for label, _, form in items:
            for row in form if isinstance(form, list) else [form]:
                if isinstance(row, Typeset) and row.source is not None:
                    yield label, row


def truncated(expr: sp.Expr, n_terms: int) -> sp.Expr:
    """A series written as X_1 + sum_{n >= 2}: its first ``n_terms`` terms."""
    return expr.replace(
        lambda e: isinstance(e, sp.Sum),
        lambda e: sp.Sum(e.function, (e.limits[0][0], e.limits[0][1], n_terms)).doit(),
    )


def random_points(form: Typeset, symbols, rng, n=24):
    """Points of the formula's region: D from (0, 1), {1} and (1, 5), the rest uniform."""
    D = derivation.D
    candidates = {sym: rng.uniform(*SYMBOLS[sym.name], 4000) for sym in symbols if sym != D}
    candidates[D] = np.select(
        [rng.uniform(size=4000) < 0.4, rng.uniform(size=4000) < 0.3],
        [rng.uniform(0, 1, 4000), np.ones(4000)],
        rng.uniform(1, 5, 4000),
    )
    names = sorted(candidates, key=str)
    with np.errstate(invalid="ignore"):  # sqrt(D^2 - 1) outside D > 1: nan, not inside
        inside = sp.lambdify(names, form.domain, "numpy")(*(candidates[k] for k in names))
    chosen = np.flatnonzero(np.broadcast_to(inside, (4000,)))[:n]
    assert len(chosen) == n, f"too few points in {form.domain}"
    return [{sym: candidates[sym][i] for sym in names} for i in chosen]


@pytest.mark.parametrize(
    ("label", "form"), [pytest.param(label, form, id=label) for label, form in checked_forms()]
)
def test_typeset_formula_equals_its_source_at_random_points(label, form):
    expr = truncated(form.expression(), N_TERMS)
    assert not expr.free_symbols & {a.symbol for a in form.abbreviations}, label
    symbols = sorted(expr.free_symbols | form.source.free_symbols, key=str)
    assert {sym.name for sym in symbols} <= {*SYMBOLS, "D"}, symbols
    typeset_value = sp.lambdify(symbols, expr, "mpmath")
    source_value = sp.lambdify(symbols, form.source, "mpmath")
    rng = np.random.default_rng(sum(map(ord, label)))
    with mpmath.workdps(30):
        for point in random_points(form, symbols, rng):
            args = [mpmath.mpf(float(point[sym])) for sym in symbols]
            want, got = source_value(*args), typeset_value(*args)
            assert abs(got - want) <= 1e-12 * max(1, abs(want)), (label, point, got, want)


def read_back_cases():
    """(label, LaTeX of one formula or row, its Typeset, the LaTeX of the ridge time it uses)."""
    bodies = {label: body for _, items in formulas(N_TERMS) for label, _, body in items}
    ridge_text = None
    for _, items in typeset_formulas(N_TERMS):
        for label, _, form in items:
            body = bodies[label]
            if isinstance(form, list):  # aligned rows after the line that sums them
                inner = body.removeprefix(r"\begin{aligned}").removesuffix(r"\end{aligned}")
                rows = inner.split(r" \\ ")[1:]
                for text, row in zip(rows, form[1:], strict=True):
                    yield pytest.param(label, text, row, None, id=f"{label}-{row.lhs}")
            elif isinstance(form, Typeset):
                yield pytest.param(label, body, form, ridge_text, id=label)
                ridge_text = body if label.startswith("sd-ridge") else ridge_text


def read_formula(text: str, ridge_text: str | None) -> tuple[sp.Expr, sp.Boolean]:
    """The right side read from the LaTeX, every abbreviation (and the ridge time, read
    from its own formula) substituted, and the condition it states."""
    parsed = latex_reader.read(text, {})
    expr = parsed["rhs"]
    if ridge_text is not None:
        ridge, _ = read_formula(ridge_text, None)
        expr = expr.subs(sp.Symbol("tau_r"), ridge)
    condition = parsed["for"]
    for _ in range(3):  # definitions may use each other
        expr, condition = expr.subs(parsed["with"]), condition.subs(parsed["with"])
    expr = expr.subs(sp.Symbol("N_TERMS"), N_TERMS).doit()
    return expr, condition


@pytest.mark.parametrize(("label", "text", "form", "ridge_text"), list(read_back_cases()))
def test_latex_read_back_equals_the_derived_expression(label, text, form, ridge_text):
    # the LaTeX string itself, read by an independent reader, against the source
    expr, condition = read_formula(text, ridge_text)
    names = sorted({sym.name for sym in expr.free_symbols | form.source.free_symbols})
    assert set(names) <= {*SYMBOLS, "D"}, (label, names)
    source_symbols = {sym.name: sym for sym in form.source.free_symbols}
    arguments = [source_symbols.get(name, sp.Symbol(name)) for name in names]
    source_value = sp.lambdify(arguments, form.source, "mpmath")
    read_value = sp.lambdify([sp.Symbol(name) for name in names], expr, "mpmath")
    holds = sp.lambdify([sp.Symbol(name) for name in names], condition, "mpmath")
    rng = np.random.default_rng(sum(map(ord, text)))
    with mpmath.workdps(30):
        for point in random_points(form, arguments, rng):
            by_name = {sym.name: value for sym, value in point.items()}
            args = [mpmath.mpf(float(by_name[name])) for name in names]
            want, got = source_value(*args), read_value(*args)
            assert abs(got - want) <= 1e-12 * max(1, abs(want)), (label, by_name, got, want)
            assert bool(holds(*args)), (label, by_name, condition)


@pytest.mark.parametrize("regime", ["critical", "overdamped"])
def test_ridge_conditions_are_the_derived_ones_over_the_regime(regime):
    # the condition read from the LaTeX (one bound) and the package's (a conjunction)
    # agree on a fine random sample of the regime, on both sides of the bound
    model = derivation.spring_damper(regime)
    _, condition = read_formula(formula(f"sd-ridge-force-{regime}"), None)
    assert len(sp.And.make_args(condition)) == 1
    rng = np.random.default_rng(7)
    Ds = np.ones(5000) if regime == "critical" else rng.uniform(1, 8, 5000)
    fs = rng.uniform(0, 1.5, 5000) / Ds  # the bound is 1/2 at D = 1, about 1/(4 D) beyond
    mine = sp.lambdify(sp.symbols("D f"), condition, "numpy")(Ds, fs)
    variables = (derivation.D, derivation.f)
    derived = sp.lambdify(variables, model.ridge_exists["force"], "numpy")(Ds, fs)
    assert np.array_equal(mine, derived)
    assert 0.02 < np.mean(mine) < 0.98  # both sides of the bound are sampled


@pytest.mark.parametrize("regime", ["under", "critical", "over"])
def test_typeset_solution_solves_the_oscillator(regime):
    # checked against the ODE itself, not against the derivation it came from
    z = typeset(f"sd-z-{regime}").expression()
    D, f, tau = derivation.D, derivation.f, derivation.tau
    if regime == "critical":
        z = z.subs(D, 1)
    residual = z.diff(tau, 2) + 2 * D * z.diff(tau) + z - 2 * D * f
    if regime == "critical":
        residual = residual.subs(D, 1)
    assert sp.simplify(residual) == 0
    assert sp.simplify(z.subs(tau, 0)) == 0
    assert sp.simplify(z.diff(tau).subs(tau, 0)) == 1


@pytest.mark.parametrize(
    ("condition", "D_value", "f_value"),
    [
        ("position", 0.3, 0.2),
        ("force", 0.4, 0.1),
        ("force", 0.9, 0.05),
        ("force", 0.6, 0.9),
        ("force", 2.0, 0.05),
    ],
)
def test_typeset_ridge_time_is_the_first_local_minimum_by_brute_force(condition, D_value, f_value):
    from scipy.optimize import brentq

    regime = derivation.regime_of(D_value)
    ridge = typeset(f"sd-ridge-{condition}-{regime}").expression()
    point = {derivation.D: D_value, derivation.f: f_value}
    tau_r = float(ridge.subs(point))
    # g' of the package's solution on a fine grid: the first sign change from - to +
    g_dot = sp.lambdify(
        derivation.tau, derivation.spring_damper(regime).g_dot[condition].subs(point), "numpy"
    )
    grid = np.linspace(1e-9, 40, 400001)
    values = g_dot(grid)
    first = np.flatnonzero((values[:-1] < 0) & (values[1:] >= 0))[0]
    reference = brentq(g_dot, grid[first], grid[first + 1], xtol=1e-15)
    assert tau_r == pytest.approx(reference, rel=1e-10)


def test_document_reads_like_an_appendix():
    document = latex_document()
    sections = re.findall(r"\\section\{([^}]*)\}", document)
    assert sections == list(SECTIONS)
    for label, number in PAPER_EQUATIONS.items():
        assert f"\\label{{eq:{label}}}\\tag{{{number}}}" in document
    assert "\\numberwithin{equation}{section}" in document
    # a stick/release test cites the ridge time it uses by its equation number
    assert "from eq.~\\eqref{eq:sd-ridge-force-critical}" in document
    # a sentence before every equation, ending in a full stop before the label
    for label in formula_names():
        sentence = document.split(f"\\formulalabel{{{label}}}")[0].rsplit("\\noindent ", 1)[1]
        assert sentence.rstrip().endswith("."), label
    for bad in ("Piecewise", "atan}_{2}", "\\left(\\right)", "\\wedge", "\\sqrt{1 - D^{2}}}{"):
        assert bad not in document, bad


PROBE = r"""
import json, sys
sys.modules["sympy"] = None      # importing SymPy or impactsym now fails
sys.modules["impactsym"] = None
sys.path.insert(0, sys.argv[1])
import numpy as np
import impactsym_numpy as m
points = json.loads(sys.argv[2])
t, D, f, tau = (np.array(points[k]) for k in ("t", "D", "f", "tau"))
print(json.dumps({
    "g_position": m.contact_function_position(tau, D, f).tolist(),
    "g_force": m.contact_function_force(tau, D, f).tolist(),
    "ridge_force": np.nan_to_num(m.ridge_time_force(D, f), nan=-1.0).tolist(),
    "boundary_force": m.boundary_force(D, f).tolist(),
    "boundary_position": m.boundary_position(D, f).tolist(),
    "y": m.rod_displacement(t, 2.0, 0.5).tolist(),
    "N": m.rod_contact_force(t, 0.3, 1.0).tolist(),
}))
"""


def test_generated_module_runs_without_sympy_and_matches_the_package(tmp_path):
    (tmp_path / "impactsym_numpy.py").write_text(python_module())
    rng = np.random.default_rng(3)
    D = np.concatenate([rng.uniform(0, 3, 30), [0.0, 1.0, 1.0 + 1e-9]])
    f = rng.uniform(0, 2, D.size)
    tau = rng.uniform(0, 8, D.size)
    t = np.linspace(-1, 60, 200)
    points = {"t": t.tolist(), "D": D.tolist(), "f": f.tolist(), "tau": tau.tolist()}
    run = subprocess.run(
        [sys.executable, "-c", PROBE, str(tmp_path), json.dumps(points)],
        capture_output=True,
        text=True,
        check=True,
    )
    got = {k: np.array(v) for k, v in json.loads(run.stdout).items()}
    for condition in ("position", "force"):
        k = kernels(condition=condition)
        np.testing.assert_allclose(got[f"g_{condition}"], k.g(tau, D, f), rtol=1e-13, atol=1e-15)
    # the sign of the exported boundary function decides sticking as the package does
    for condition in ("position", "force"):
        sticks = np.isinf(contact_time(D, f, condition=condition))
        assert np.array_equal(got[f"boundary_{condition}"] >= 0, sticks)
    # ridge times: where the package finds a minimum, the exported one is the same time
    from impactsym.contact import contact_surface

    _, _, ridge = contact_surface(D, f, condition="force")
    exported = got["ridge_force"]
    np.testing.assert_allclose(exported[~np.isnan(ridge)], ridge[~np.isnan(ridge)], rtol=1e-13)
    assert np.all(exported[np.isnan(ridge)] == -1.0)
    np.testing.assert_allclose(got["y"], displacement(t, 2.0, 0.5), atol=1e-10)
    np.testing.assert_allclose(got["N"], contact_force(t, 0.3, 1.0), atol=1e-10)


def test_generated_module_is_valid_python_with_docstrings():
    source = python_module()
    namespace: dict = {}
    exec(compile(source, "impactsym_numpy.py", "exec"), namespace)
    for name in (
        "contact_function_force",
        "ridge_time_position",
        "boundary_force",
        "rod_displacement",
        "rod_contact_force",
    ):
        doc = namespace[name].__doc__
        assert doc
        assert "paper" in doc.lower() or "eq" in doc.lower()


def test_latex_policy_skips_only_outside_ci(monkeypatch):
    from conftest import require_latex

    monkeypatch.setattr("shutil.which", lambda name: None)
    monkeypatch.delenv("CI", raising=False)
    with pytest.raises(pytest.skip.Exception, match="not installed"):
        require_latex()
    monkeypatch.setenv("CI", "true")
    with pytest.raises(pytest.fail.Exception, match="CI is set"):
        require_latex()


# -- the generated NumPy module refuses hostile input ----------------------------------

GENERATED_PROBE = r"""
import json, sys
sys.modules["sympy"] = None
sys.modules["impactsym"] = None
sys.path.insert(0, sys.argv[1])
import impactsym_numpy as m
CODE = "__import__('os').system('touch PWNED')"
calls = {
    "nan D": lambda: m.boundary_force(float("nan"), 0.2),
    "string f": lambda: m.boundary_position(0.5, CODE),
    "negative tau": lambda: m.contact_function_force(-1.0, 0.5, 0.2),
    "bool f": lambda: m.ridge_time_force(0.5, True),
    "complex D": lambda: m.contact_function_position(1.0, 0.5j, 0.2),
    "shapes": lambda: m.boundary_force([0.1, 0.2], [0.1, 0.2, 0.3]),
    "huge D": lambda: m.boundary_force(1e100, 0.0),
    "inf t": lambda: m.rod_displacement(float("inf"), 1.0, 0.0),
    "zero alpha": lambda: m.rod_contact_force(1.0, 0.0, 0.0),
    "string alpha": lambda: m.rod_displacement(1.0, CODE, 0.0),
    "list of strings": lambda: m.rod_displacement(["1"], 1.0, 0.0),
}
out = {}
for label, call in calls.items():
    try:
        out[label] = ["no error", repr(call())]
    except Exception as exc:
        out[label] = [type(exc).__name__, str(exc)]
out["fine"] = ["value", m.boundary_force(0.5, 0.2)]
print(json.dumps(out))
"""


def test_generated_module_validates_its_inputs_in_a_clean_interpreter(tmp_path):
    (tmp_path / "impactsym_numpy.py").write_text(python_module())
    run = subprocess.run(
        [sys.executable, "-c", GENERATED_PROBE, str(tmp_path)],
        capture_output=True,
        text=True,
        check=True,
        cwd=tmp_path,
    )
    got = json.loads(run.stdout)
    expected = {
        "nan D": ("ValueError", "D must be finite, got nan"),
        "string f": ("TypeError", "f must be a real number or array, got"),
        "negative tau": ("ValueError", "tau must be >= 0, got -1.0"),
        "bool f": ("TypeError", "f must be a real number or array of real numbers"),
        "complex D": ("TypeError", "D must be a real number or array of real numbers"),
        "shapes": ("ValueError", "D (shape (2,)) and f (shape (3,)) cannot be broadcast"),
        "huge D": ("ValueError", "D must be <= 1e+08"),
        "inf t": ("ValueError", "t must be finite, got inf"),
        "zero alpha": ("ValueError", "alpha must be > 0, got 0.0"),
        "string alpha": ("TypeError", "alpha must be a real number or array"),
        "list of strings": ("TypeError", "t must be a real number or array of real numbers"),
    }
    for label, (kind, start) in expected.items():
        assert got[label][0] == kind, (label, got[label])
        assert got[label][1].startswith(start), (label, got[label])
    assert 0 < got["fine"][1] < 1
    assert not (tmp_path / "PWNED").exists()


# -- the exported module is the package: same numbers, same refusals, NumPy only -------

#: Runs in a fresh interpreter with SymPy, mpmath, SciPy and impactsym unimportable:
#: every call of the JSON list ``[label, function, args, kwargs]`` and what it gave.
BLOCKED_PROBE = r"""
import importlib.abc, inspect, json, pickle, sys
BLOCKED = ("sympy", "mpmath", "scipy", "impactsym")
BEFORE = set(sys.modules)  # the interpreter's start-up (site hooks) is not the module's


class Refuse(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in BLOCKED:
            raise ImportError(f"{name} is blocked in this test")
        return None


sys.meta_path.insert(0, Refuse())
for name in BLOCKED:
    sys.modules[name] = None
sys.path.insert(0, sys.argv[1])
import numpy as np
import impactsym_numpy as m


def encode(value):
    if type(value) is float:
        return ["float", [], [value]]
    array = np.asarray(value)
    return [type(value).__name__, list(array.shape), array.ravel().tolist()]


out = {"results": {}}
for label, function, args, kwargs in pickle.loads(open(sys.argv[2], "rb").read()):
    args = [np.array(a) if isinstance(a, list) and len(a) and isinstance(a[0], list) else a
            for a in args]
    try:
        value = getattr(m, function)(*args, **kwargs)
        if hasattr(value, "__dataclass_fields__"):
            value = {k: encode(getattr(value, k)) for k in ("D", "f", "omega0",
                     "normalized_contact_time", "contact_time", "restitution")}
            out["results"][label] = ["record", value]
        else:
            out["results"][label] = ["value", encode(value)]
    except Exception as exc:
        out["results"][label] = ["error", type(exc).__name__, str(exc)]
out["loaded"] = sorted(
    {k.split(".")[0] for k, v in sys.modules.items() if v is not None and k not in BEFORE}
    - set(sys.stdlib_module_names) - {"impactsym_numpy"}
)
out["required"] = {
    name: inspect.signature(getattr(m, name)).parameters["condition"].default
    is inspect.Parameter.empty
    for name in ("contact_time", "restitution", "stick_boundary", "ridge_time",
                 "contact_surface", "physical_contact", "rod_contact_time")
}
print(json.dumps(out))
"""


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    """The directory holding the module ``impactsym export python`` writes."""
    from impactsym.cli import main

    folder = tmp_path_factory.mktemp("exported")
    assert main(["export", "python", str(folder / "impactsym_numpy.py")]) == 0
    return folder


def run_blocked(folder, calls) -> dict:
    """Run ``calls`` on the exported module with SymPy, mpmath, SciPy, impactsym blocked."""
    (folder / "calls.pickle").write_bytes(pickle.dumps(calls))
    run = subprocess.run(
        [sys.executable, "-c", BLOCKED_PROBE, str(folder), str(folder / "calls.pickle")],
        capture_output=True,
        text=True,
        check=True,
        cwd=folder,
    )
    return json.loads(run.stdout)


def section2_points() -> tuple[np.ndarray, np.ndarray]:
    """(D, f) pairs over every regime and limit of the section-2 contact."""
    rng = np.random.default_rng(23)
    n = 40
    D = np.concatenate(
        [
            rng.uniform(0.0, 1.0, n),  # under-damped
            np.ones(8),  # critically damped, exactly
            rng.uniform(1.0, 4.0, n),  # over-damped
            10 ** rng.uniform(0.0, 8.0, n),  # far over-damped, up to the closed forms' end
            10 ** rng.uniform(8.1, 12.0, 6),  # beyond: the far over-damped limit
            rng.uniform(0.01, 1.0, 6),  # 2 D f > 1e4, clearly sticking: decided by a limit
        ]
    )
    f = np.concatenate(
        [
            np.where(rng.uniform(size=n) < 0.2, 0.0, rng.uniform(0.0, 3.0, n)),
            [0.0, 0.0, 0.1, 0.5, 1.0, 2.0, 1e-6, 10.0],
            np.where(rng.uniform(size=n) < 0.2, 0.0, rng.uniform(0.0, 0.5, n)),
            np.where(rng.uniform(size=n) < 0.3, 0.0, 10 ** rng.uniform(-40.0, -1.0, n)),
            [0.0, 0.0, 0.0, 1e-6, 1e-3, 1.0],  # D > 1e8: f = 0 releases, f > 0 sticks here
            rng.uniform(1e6, 1e7, 6),
        ]
    )
    return D, f


def package_ridge_time(D, f, *, condition):
    from impactsym.contact.kernel import flat_inputs, ridge

    (damping, force), shape, scalar = flat_inputs(condition=condition, D=D, f=f)
    out = ridge(damping, force, condition=condition).reshape(shape)
    return float(out) if scalar else out


def package_function(name):
    """The package function an exported name stands for."""
    from impactsym import contact, rod

    table = {
        "contact_time": contact.contact_time,
        "restitution": contact.restitution,
        "stick_boundary": contact.stick_boundary,
        "ridge_time": package_ridge_time,
        "contact_surface": contact.contact_surface,
        "physical_contact": contact.physical_contact,
        "rod_displacement": rod.displacement,
        "rod_contact_force": rod.contact_force,
        "rod_contact_time": rod.contact_time,
    }
    return table[name]


def comparison_calls() -> list:
    """``[label, function, args, kwargs]``: every exported function on random inputs."""
    D, f = section2_points()
    calls = []
    for c in ("position", "force"):
        cond = {"condition": c}
        for name in ("contact_time", "restitution"):
            calls.append([f"{name} {c} arrays", name, [D.tolist(), f.tolist()], cond])
            grid = [D[:12, None].tolist(), f[40:45].tolist()]  # broadcast to (12, 5)
            calls.append([f"{name} {c} grid", name, grid, cond])
            for d_, f_ in ((1.0, 0.0), (1.0, 0.3), (0.0, 1.0), (0.5, 0.0), (3.0, 0.05)):
                calls.append([f"{name} {c} {d_} {f_}", name, [d_, f_], cond])
        forces = np.concatenate(
            [[0.0, 1e-40, 6e-34, 1e-20, 1e-3, 1.0, 1e12, 2e12, 1e15], 10 ** np.linspace(-8, 8, 25)]
        )
        calls.append([f"stick_boundary {c}", "stick_boundary", [forces.tolist()], cond])
        for value in (0.0, 0.5, 1e13):
            calls.append([f"stick_boundary {c} {value}", "stick_boundary", [value], cond])
        closed = (D <= 1e8) & (2 * D * f <= 1e4)
        pair = [D[closed].tolist(), f[closed].tolist()]
        calls.append([f"ridge_time {c}", "ridge_time", pair, cond])
        calls.append([f"ridge_time {c} scalar", "ridge_time", [1.0, 0.0], cond])
        calls.append([f"contact_surface {c}", "contact_surface", pair, cond])
        calls.append(
            [
                f"physical_contact {c}",
                "physical_contact",
                [2.0, 800.0, [0.0, 4.0, 80.0], 1.0],
                {"F": [0.0, 3.0, 1.0], **cond},
            ]
        )
        calls.append(
            [
                f"physical_contact {c} undamped",
                "physical_contact",
                [1.0, 1.0, 0.0, 1.0],
                {"F": 0.5, **cond},
            ]
        )
    t = np.linspace(-1.0, 100.0, 503).tolist()
    for a, force in ((0.05, 0.0), (1.0, 2.0), (50.0, 5.0)):
        for name in ("rod_displacement", "rod_contact_force"):
            calls.append([f"{name} {a} {force}", name, [t, a, force], {}])
    calls.append(["rod_contact_force scalar", "rod_contact_force", [3.0, 0.3, 1.0], {}])
    calls.append(
        ["rod_displacement mixed", "rod_displacement", [[[2.5], [7.0]], [0.2, 3.0], 0.4], {}]
    )
    rng = np.random.default_rng(5)
    alpha, force = 10 ** rng.uniform(-1.5, 1.5, 12), rng.uniform(0.0, 2.5, 12)
    for c in ("position", "force"):
        pairs = [alpha.tolist(), force.tolist()]
        calls.append([f"rod_contact_time {c}", "rod_contact_time", pairs, {"condition": c}])
        calls.append(
            [f"rod_contact_time {c} 0.5", "rod_contact_time", [0.5, 0.0], {"condition": c}]
        )
    calls.append(
        [
            "rod_contact_time t_max",
            "rod_contact_time",
            [[0.3, 3.0], 0.5],
            {"condition": "force", "t_max": 9.0},
        ]
    )
    return calls


def decode(encoded):
    kind, shape, data = encoded
    return float(data[0]) if kind == "float" else np.array(data, dtype=float).reshape(shape)


def test_exported_module_gives_the_package_numbers_bit_for_bit(exported):
    calls = comparison_calls()
    got = run_blocked(exported, calls)
    assert got["loaded"] == ["numpy"]  # nothing but NumPy (and the standard library)
    assert all(got["required"].values()), got["required"]  # condition= has no default
    for label, name, args, kwargs in calls:
        result = got["results"][label]
        args = [
            np.array(a) if isinstance(a, list) and a and isinstance(a[0], list) else a for a in args
        ]
        expected = package_function(name)(*args, **kwargs)
        assert result[0] != "error", (label, result)
        if result[0] == "record":
            for field, encoded in result[1].items():
                want = getattr(expected, field)
                assert np.array_equal(decode(encoded), want, equal_nan=True), (label, field)
            continue
        value = decode(result[1])
        if isinstance(expected, tuple):  # contact_surface: three arrays, flattened here
            expected = np.array(expected)
            value = value.reshape(expected.shape)
        assert type(value) is type(expected) or isinstance(expected, np.ndarray), label
        assert np.shape(value) == np.shape(expected), label
        assert np.array_equal(value, expected, equal_nan=True), (label, value, expected)
    # the calls cover every regime, both verdicts and the limits
    times = decode(got["results"]["contact_time force arrays"][1])
    assert np.isinf(times).any()
    assert np.isfinite(times).any()


CODE = "__import__('os').system('touch PWNED')"
#: ``[label, function, args, kwargs, argument the message must name]``
BAD_CALLS = [
    ["string D", "contact_time", [CODE, 0.2], {"condition": "force"}, "D"],
    ["negative f", "contact_time", [0.5, -1.0], {"condition": "position"}, "f"],
    ["nan D", "restitution", [float("nan"), 0.2], {"condition": "force"}, "D"],
    ["bool f", "restitution", [0.5, True], {"condition": "position"}, "f"],
    ["complex D", "contact_time", [0.5j, 0.2], {"condition": "force"}, "D"],
    ["shapes", "contact_time", [[0.1, 0.2], [0.1, 0.2, 0.3]], {"condition": "force"}, "D"],
    ["unknown condition", "contact_time", [0.5, 0.2], {"condition": "pos"}, "condition"],
    ["condition not a string", "restitution", [0.5, 0.2], {"condition": 1}, "condition"],
    ["far D releasing", "contact_time", [1e9, 1e-40], {"condition": "force"}, "D"],
    ["unresolved stick", "contact_time", [5.2e-9, 1e12], {"condition": "force"}, "D"],
    ["string f", "stick_boundary", [CODE], {"condition": "force"}, "f"],
    ["negative f boundary", "stick_boundary", [-1.0], {"condition": "position"}, "f"],
    ["list with bool", "stick_boundary", [[0.5, True]], {"condition": "force"}, "f"],
    ["surface beyond", "contact_surface", [1e9, 0.0], {"condition": "force"}, "D"],
    ["zero mass", "physical_contact", [0.0, 1.0, 1.0, 1.0], {"condition": "force"}, "m"],
    ["string k", "physical_contact", [1.0, CODE, 1.0, 1.0], {"condition": "force"}, "k"],
    ["alpha range", "rod_displacement", [1.0, 2e6, 0.0], {}, "alpha"],
    ["zero alpha", "rod_contact_force", [1.0, 0.0, 0.0], {}, "alpha"],
    ["t beyond", "rod_displacement", [2e4, 2.0, 0.5], {}, "t"],
    ["inf t", "rod_contact_force", [float("inf"), 2.0, 0.5], {}, "t"],
    ["negative f rod", "rod_contact_force", [1.0, 0.5, -0.1], {}, "f"],
    ["string alpha", "rod_contact_time", [CODE, 0.0], {"condition": "force"}, "alpha"],
    ["t_max beyond", "rod_contact_time", [0.5, 0.0], {"condition": "force", "t_max": 2e4}, "t_max"],
    [
        "t_max array",
        "rod_contact_time",
        [0.5, 0.0],
        {"condition": "force", "t_max": [1, 2]},
        "t_max",
    ],
    ["rod condition", "rod_contact_time", [0.5, 0.0], {"condition": "both"}, "condition"],
]


def test_exported_module_refuses_what_the_package_refuses_with_its_words(exported):
    calls = [call[:4] for call in BAD_CALLS]
    got = run_blocked(exported, calls)["results"]
    for label, name, args, kwargs, argument in BAD_CALLS:
        with pytest.raises((TypeError, ValueError)) as caught:
            package_function(name)(*args, **kwargs)
        assert got[label] == ["error", type(caught.value).__name__, str(caught.value)], label
        assert re.search(rf"\b{argument}\b", got[label][2]), (label, got[label])
    assert not (exported / "PWNED").exists()


def test_exported_module_has_its_own_refusals(exported):
    """Where it differs from the package: condition= is required everywhere, a finite
    kappa needs impactsym, ridge_time ends with the closed forms at D = 1e8."""
    calls = [
        ["no condition", "contact_time", [0.5, 0.2], {}],
        ["no condition rod", "rod_contact_time", [0.5, 0.2], {}],
        ["no condition boundary", "stick_boundary", [0.5], {}],
        ["finite kappa", "rod_displacement", [1.0, 0.5, 0.0], {"kappa": 3.0}],
        ["finite kappa time", "rod_contact_time", [0.5, 0.0], {"condition": "force", "kappa": 3.0}],
        ["ridge beyond", "ridge_time", [[0.5, 1e9], 0.1], {"condition": "force"}],
    ]
    got = run_blocked(exported, calls)["results"]
    for label in ("no condition", "no condition rod", "no condition boundary"):
        kind, message = got[label][1:]
        assert kind == "TypeError"
        assert "required keyword-only argument: 'condition'" in message
    for label in ("finite kappa", "finite kappa time"):
        assert got[label][1:] == ["ValueError", got[label][2]]
        assert got[label][2].startswith("kappa must be inf (rigid contact) in this module, got 3.0")
    assert got["ridge beyond"][1:] == [
        "ValueError",
        "D must be <= 1e+08 (the range of these closed forms), got 1000000000.0",
    ]


def load_exported(folder):
    """The exported module imported in this process (it imports nothing of impactsym)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("impactsym_numpy", folder / "impactsym_numpy.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["impactsym_numpy"] = module  # dataclasses look their module up
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize(
    ("D", "f", "condition"),
    [
        (0.2, 0.5, "force"),
        (0.2, 0.5, "position"),
        (0.0, 1.0, "force"),
        (1.0, 0.0, "force"),
        (1.0, 0.02, "force"),
        (0.5, 0.02, "position"),
        (2.0, 0.0, "force"),
    ],
)
def test_module_contact_time_and_restitution_match_the_mpmath_oscillator(exported, D, f, condition):
    """Against the 40-digit matrix exponential of references.oscillator (no closed form)."""
    from references import oscillator

    m = load_exported(exported)
    expected = float(oscillator.first_root(D, f, condition, t_max=20.0, samples=400))
    assert m.contact_time(D, f, condition=condition) == pytest.approx(expected, rel=1e-13)
    z_dot = float(oscillator.state(expected, D, f)[1])
    assert m.restitution(D, f, condition=condition) == pytest.approx(-z_dot, rel=1e-12)


def reference_minimum(D, f, condition, guess):
    """The first minimum of g by the mpmath oscillator (a root of g' near ``guess``)."""
    import mpmath as mp
    from references import oscillator

    def slope(t):
        z, v = oscillator.state(t, D, f)
        return v if condition == "position" else 2 * D * (2 * D * f - 2 * D * v - z) + v

    with mp.workdps(40):
        return oscillator.contact_function(mp.findroot(slope, guess), D, f, condition)


def test_module_stick_boundary_separates_release_from_sticking_in_the_reference(exported):
    m = load_exported(exported)
    for f, condition in ((0.5, "position"), (0.2, "force"), (0.02, "force")):
        d_star = m.stick_boundary(f, condition=condition)
        for D, sign in ((d_star * (1 - 1e-6), -1), (d_star * (1 + 1e-6), 1)):
            guess = m.ridge_time(D, f, condition=condition)
            assert sign * reference_minimum(D, f, condition, guess) > 0, (f, condition, D)
    assert m.stick_boundary([0.0], condition="position").tolist() == [1.0]


def test_module_rod_contact_time_is_the_classical_rigid_striker(exported):
    m = load_exported(exported)
    a = np.array([0.05, 0.5, 1.0, 1.5])
    expected = 2 + a * (1 + np.exp(-2 / a) / 2)  # f = 0: N vanishes on (2, 4)
    got = m.rod_contact_time(a, 0.0, condition="force")
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12)


def test_exported_module_is_lint_clean_and_documented(exported):
    source = (exported / "impactsym_numpy.py").read_text()
    tree = ast.parse(source)
    m = load_exported(exported)
    public = [
        node.name
        for node in tree.body
        if isinstance(node, ast.FunctionDef | ast.ClassDef) and not node.name.startswith("_")
    ]
    assert set(m.__all__) <= set(public)
    undocumented = [name for name in public if not (getattr(m, name).__doc__ or "").strip()]
    assert undocumented == []
    for word in ("sympy", "mpmath", "scipy", "impactsym"):
        assert not re.search(rf"^\s*(import|from) {word}\b", source, re.M), word
    ruff = shutil.which("ruff")
    if ruff is None:
        pytest.skip("ruff is not installed")
    # pyflakes (undefined or unused names), syntax, import order, bugbear, upgrades
    lint = subprocess.run(
        [
            ruff,
            "check",
            "--isolated",
            "--no-cache",
            "--select",
            "F,E9,I,B,UP,RUF022",
            "--target-version",
            "py310",
            str(exported / "impactsym_numpy.py"),
        ],
        capture_output=True,
        text=True,
    )
    assert lint.returncode == 0, lint.stdout


def test_typeset_eq1_is_solved_by_the_derived_closed_form():
    # eq. (1) is written by hand: read its LaTeX back (a few fixed notations) and
    # substitute the closed form W, Y of finite kappa into every equation
    from sympy.parsing.sympy_parser import (
        implicit_multiplication_application,
        parse_expr,
        standard_transformations,
    )

    from impactsym.rod import RodImpact

    rod = RodImpact(sp.Symbol("kappa", positive=True))
    s, xi = rod.s, rod.xi
    W = rod.W
    values = {
        "Wxx": W.diff(xi, 2),
        "Wx0": W.diff(xi).subs(xi, 0),
        "W1": W.subs(xi, 1),
        "W0": W.subs(xi, 0),
        "Wxs": W,
        "Ys": rod.Y,
    }
    text = formula("rod-bvp")
    for latex_text, name in (
        (r"\begin{gathered}", ""),
        (r"\end{gathered}", ""),
        (r"W''(\xi, s)", " Wxx "),
        (r"W'(0, s)", " Wx0 "),
        (r"W(\xi, s)", " Wxs "),
        (r"W(1, s)", " W1 "),
        (r"W(0, s)", " W0 "),
        (r"Y(s)", " Ys "),
        (r"\frac{f}{s}", " (f/s) "),
        ("^{2}", "**2"),
        (r"\alpha", " alpha "),
        (r"\kappa", " kappa "),
    ):
        text = text.replace(latex_text, name)
    rows = [row for part in text.split(r"\\") for row in part.split(r", \qquad")]
    assert len(rows) == 4
    symbols = {"alpha": rod.alpha, "f": rod.f, "s": s, "kappa": rod.kappa}
    transformations = (*standard_transformations, implicit_multiplication_application)
    rng = np.random.default_rng(1)
    for row in rows:
        lhs, rhs = row.strip().rstrip(",").split("=")
        assert rhs.strip() == "0"
        local = {**symbols, **{k: sp.Symbol(k) for k in values}}
        equation = parse_expr(lhs, local_dict=local, transformations=transformations)
        residual = equation.subs({sp.Symbol(k): v for k, v in values.items()})
        for _ in range(5):
            point = {
                rod.alpha: sp.Float(rng.uniform(0.1, 5), 30),
                rod.f: sp.Float(rng.uniform(0, 2), 30),
                s: sp.Float(rng.uniform(0.3, 5), 30),
                rod.kappa: sp.Float(rng.uniform(0.5, 40), 30),
                xi: sp.Float(rng.uniform(0, 1), 30),
            }
            assert abs(complex(residual.subs(point).evalf(30))) < 1e-20, row
