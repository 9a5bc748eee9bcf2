"""The one bridge from finished SymPy expressions to fast NumPy functions, and their source.

* :func:`lambdify` compiles with a fixed argument order, common-subexpression elimination
  and a docstring that lists the arguments and the formula; the result evaluates through
  :func:`broadcast_evaluate`.
* :func:`lambdified_source` is the NumPy-only Python source of what :func:`lambdify`
  compiled: the same statements (SymPy's generated code, its bare NumPy names written
  ``np.name``), so that an exported copy computes the same floats.
* :func:`package_source` cuts a function, class or constant out of a package module's
  source (optionally renamed, a keyword made required, a method replaced), and
  :func:`module_source` joins such pieces into one module that imports what they use.
  Why: ``impactsym export python`` writes the package's own kernels, not a second
  implementation of them, and refuses to write a module that uses an undefined name.
"""

from __future__ import annotations

import ast
import builtins
import inspect
import re
import symtable
import textwrap
from collections.abc import Sequence
from functools import cache
from types import ModuleType

import numpy as np
import sympy as sp

from impactsym import validation
from impactsym.numeric import roots
from impactsym.numeric.roots import ArrayFunction


def broadcast_evaluate(compiled: ArrayFunction, *values: np.ndarray) -> np.ndarray:
    """``compiled(*values)`` as float64 of the broadcast shape of ``values``.

    The shape is that of the arguments also where the expression does not depend on
    all of them; floating-point warnings are silenced because a ``Piecewise`` evaluates
    every branch, also where it is not taken.

    >>> broadcast_evaluate(lambda x, y: 2 * x, np.ones(2), np.zeros((3, 1))).shape
    (3, 2)
    """
    with np.errstate(all="ignore"):
        out = compiled(*values)
    shape = np.broadcast_shapes(*(np.shape(v) for v in values))
    return np.broadcast_to(np.asarray(out, dtype=np.float64), shape)


def lambdify(
    args: Sequence[sp.Symbol], expr: sp.Expr, *, name: str, doc: str = ""
) -> ArrayFunction:
    """Compile ``expr`` into a broadcasting NumPy function of ``args`` (in that order).

    The result always has the broadcast shape of the arguments, also where the
    expression does not depend on all of them, and its docstring names the
    arguments and shows the expression. The compiled SymPy function is kept as its
    attribute ``compiled`` (see :func:`lambdified_source`).

    >>> x, y = sp.symbols("x y")
    >>> fn = lambdify([x, y], sp.exp(-x) * sp.cos(y), name="damped_cos")
    >>> float(fn(0.0, np.pi))
    -1.0
    >>> fn(np.zeros(3), 0.0).shape
    (3,)
    >>> print(fn.__doc__.splitlines()[0])
    damped_cos(x, y)
    """
    args = list(args)
    free = expr.free_symbols - set(args)
    if free:
        names = ", ".join(sorted(str(s) for s in free))
        raise ValueError(f"expression for {name!r} has symbols not among the arguments: {names}")
    compiled = sp.lambdify(args, expr, modules="numpy", cse=True, docstring_limit=0)

    def function(*values: np.ndarray) -> np.ndarray:
        if len(values) != len(args):
            raise TypeError(
                f"{name}() takes {len(args)} arguments ({signature}), got {len(values)}"
            )
        return broadcast_evaluate(compiled, *values)

    signature = ", ".join(str(a) for a in args)
    function.__name__ = name
    function.__qualname__ = name
    function.__doc__ = f"{name}({signature})\n\n{doc}\n\nComputes ``{sp.sstr(expr)}``.".replace(
        "\n\n\n", "\n\n"
    )
    function.expr = expr  # type: ignore[attr-defined]
    function.args = tuple(args)  # type: ignore[attr-defined]
    function.compiled = compiled  # type: ignore[attr-defined]
    return function


class _QualifyNumpy(ast.NodeTransformer):
    """Write the global names of SymPy's generated code as ``np.<name>``."""

    def __init__(self, namespace: dict, local: set[str]) -> None:
        self.namespace, self.local = namespace, local

    def visit_Name(self, node: ast.Name) -> ast.AST:
        if node.id in self.local or not isinstance(node.ctx, ast.Load):
            return node
        value = self.namespace.get(node.id, getattr(builtins, node.id, None))
        attribute = node.id if getattr(np, node.id, None) is value else None
        if attribute is None:  # the same NumPy object under another name
            attribute = next((k for k, v in vars(np).items() if v is value), None)
        if attribute is None or value is None:
            raise ValueError(f"generated code uses {node.id!r}, which is not a NumPy name")
        return ast.copy_location(
            ast.Attribute(value=ast.Name("np", ast.Load()), attr=attribute, ctx=ast.Load()), node
        )


def lambdified_source(function: ArrayFunction, name: str, doc: str) -> str:
    """NumPy-only source of ``def name(...)``: the code :func:`lambdify` compiled.

    The statements are SymPy's own (the same operations in the same order, so the
    same floats); only its bare NumPy names become ``np.<name>``. The function
    returns what the compiled code returns; the caller broadcasts it
    (:func:`broadcast_evaluate`).

    >>> x = sp.Symbol("x")
    >>> print(lambdified_source(lambdify([x], sp.exp(x) + 1, name="e"), "e1", "e^x + 1."))
    def e1(x):
        \"\"\"e^x + 1.\"\"\"
        return np.exp(x) + 1
    """
    compiled = function.compiled  # type: ignore[attr-defined]
    (tree,) = ast.parse(textwrap.dedent(inspect.getsource(compiled))).body
    tree.name = name
    tree.body.insert(0, ast.Expr(ast.Constant(doc)))
    local = set(compiled.__code__.co_varnames)
    tree = _QualifyNumpy(compiled.__globals__, local).visit(tree)
    return ast.unparse(ast.fix_missing_locations(tree))


def _node(tree: ast.Module, name: str) -> ast.stmt:
    """The top-level statement of ``tree`` that defines ``name``."""
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)) and node.name == name:
            return node
        targets = (
            node.targets
            if isinstance(node, ast.Assign)
            else [node.target]
            if isinstance(node, ast.AnnAssign)
            else []
        )
        for target in targets:
            names = target.elts if isinstance(target, ast.Tuple) else [target]
            if any(isinstance(n, ast.Name) and n.id == name for n in names):
                return node
    raise ValueError(f"{name!r} is not defined at the top level of the module")


def _offset(lines: list[str], lineno: int, col: int) -> int:
    """Character offset in ``"".join(lines)`` of an AST position (``col`` in UTF-8 bytes)."""
    line = lines[lineno - 1]
    return sum(map(len, lines[: lineno - 1])) + len(line.encode()[:col].decode())


def _line_end(lines: list[str], lineno: int) -> int:
    """Character offset of the end of line ``lineno``, before its line break."""
    return _offset(lines, lineno, len(lines[lineno - 1].rstrip("\n").encode()))


@cache
def _parsed(module: ModuleType) -> tuple[list[str], ast.Module]:
    """The source lines of ``module`` and their syntax tree (parsed once per module)."""
    lines = inspect.getsource(module).splitlines(keepends=True)
    return lines, ast.parse("".join(lines))


def package_source(
    module: ModuleType,
    name: str,
    *,
    rename: str | None = None,
    required: Sequence[str] = (),
    replace: dict[str, str] | None = None,
) -> str:
    """The source of the top-level function, class or constant ``name`` of ``module``.

    A definition comes with its decorators, a constant with the ``#:`` comment lines
    above it.

    Parameters
    ----------
    module, name
        Where the definition is and what it defines.
    rename
        New name of a function or class, also where its source calls it by name.
    required
        Keyword parameters whose defaults are dropped (the caller must pass them).
    replace
        Methods of a class replaced by the given source (a ``def`` at indentation 0).

    >>> import impactsym.numeric.roots as roots
    >>> package_source(roots, "ArrayFunction")
    'ArrayFunction = Callable[..., np.ndarray]'
    """
    lines, tree = _parsed(module)
    node = _node(tree, name)
    first = min([node.lineno] + [d.lineno for d in getattr(node, "decorator_list", [])])
    while first > 1 and lines[first - 2].lstrip().startswith("#:"):
        first -= 1
    edits = []  # (start, end, text) in offsets of "".join(lines)
    if isinstance(node, ast.FunctionDef):
        arguments = node.args
        for arg, default in zip(arguments.kwonlyargs, arguments.kw_defaults, strict=True):
            if arg.arg in required and default is not None:
                end = arg.annotation or arg
                start = _offset(lines, end.end_lineno, end.end_col_offset)
                stop = _offset(lines, default.end_lineno, default.end_col_offset)
                edits.append((start, stop, ""))
    for method in getattr(node, "body", []) if replace else []:
        if isinstance(method, ast.FunctionDef) and method.name in replace:
            begin = min([method.lineno] + [d.lineno for d in method.decorator_list])
            start = _offset(lines, begin, 0)
            stop = _line_end(lines, method.end_lineno)
            indent = " " * method.col_offset
            edits.append((start, stop, textwrap.indent(replace[method.name], indent)))
    if not isinstance(node, (ast.FunctionDef, ast.ClassDef)) and (rename or required):
        raise ValueError(f"{name!r} is a constant: it cannot be renamed or take keywords")
    text = "".join(lines)
    base = _offset(lines, first, 0)
    end = _line_end(lines, node.end_lineno)
    for start, stop, new in sorted(edits, reverse=True):
        text = text[:start] + new + text[stop:]
        end += len(new) - (stop - start)
    piece = textwrap.dedent(text[base:end])
    if rename:
        piece = re.sub(rf"(?<![\w.]){re.escape(name)}\(", f"{rename}(", piece)
        piece = re.sub(rf"^(class|def) {re.escape(name)}\b", rf"\1 {rename}", piece, flags=re.M)
    return piece.rstrip("\n")


#: The imports a generated module may need, by the name its code uses: the standard
#: library and NumPy, nothing else.
IMPORTS = {
    "np": ("numpy", None),
    **{m: (m, None) for m in ("itertools", "math", "numbers")},
    **{n: ("collections.abc", n) for n in ("Callable", "Sequence")},
    "dataclass": ("dataclasses", "dataclass"),
    **{n: ("functools", n) for n in ("cache", "partial")},
}


def _definitions(tree: ast.Module) -> list[str]:
    """Names bound at the top level of ``tree``."""
    names = []
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.append(node.name)
        elif isinstance(node, (ast.Assign, ast.AnnAssign)):
            for target in node.targets if isinstance(node, ast.Assign) else [node.target]:
                names += [n.id for n in ast.walk(target) if isinstance(n, ast.Name)]
    return names


def _free_names(source: str) -> set[str]:
    """Global names that module ``source`` reads but does not bind (builtins excluded).

    From the compiler's symbol tables (each scope as Python resolves it), plus the
    names in annotations, which it does not see under ``from __future__ import
    annotations`` but a linter does.
    """
    table = symtable.symtable(source, "<generated>", "exec")
    read, stack = set(), [table]
    while stack:
        scope = stack.pop()
        stack += scope.get_children()
        read |= {s.get_name() for s in scope.get_symbols() if s.is_global() and s.is_referenced()}
    for node in ast.walk(ast.parse(source)):
        annotations = []
        if isinstance(node, ast.arg | ast.AnnAssign):
            annotations.append(node.annotation)
        elif isinstance(node, ast.FunctionDef):
            annotations.append(node.returns)
        for annotation in filter(None, annotations):
            read |= {n.id for n in ast.walk(annotation) if isinstance(n, ast.Name)}
    bound = {s.get_name() for s in table.get_symbols() if s.is_assigned() or s.is_imported()}
    return read - bound - set(dir(builtins))


def module_source(doc: str, pieces: Sequence[str], *, exports: Sequence[str] = ()) -> str:
    """A module with docstring ``doc`` made of ``pieces`` (source text, in order).

    A piece given twice with the same text is written once; two different pieces that
    define the same name are an error, and so is a name the pieces use but nothing
    defines. The imports (:data:`IMPORTS`) are exactly the ones the pieces use.
    ``exports`` becomes ``__all__`` (sorted).

    >>> print(module_source("Demo.", ["def two():\\n    return np.float64(2)"]))
    \"\"\"Demo.\"\"\"
    <BLANKLINE>
    from __future__ import annotations
    <BLANKLINE>
    import numpy as np
    <BLANKLINE>
    <BLANKLINE>
    def two():
        return np.float64(2)
    <BLANKLINE>
    """
    unique = list(dict.fromkeys(p.strip("\n") for p in pieces))
    owner: dict[str, str] = {}
    for piece in unique:
        for name in _definitions(ast.parse(piece)):
            if name in owner:
                raise ValueError(f"two pieces of the generated module define {name!r}")
            owner[name] = piece
    body = "\n\n\n".join(unique)
    free = _free_names(body)
    missing = free - set(IMPORTS)
    if missing:
        raise ValueError(f"the generated module uses undefined names: {sorted(missing)}")
    used = free & set(IMPORTS)
    undefined = [n for n in exports if n not in owner]
    if undefined:
        raise ValueError(f"exported names not defined: {undefined}")
    modules = sorted({IMPORTS[n][0] for n in used if IMPORTS[n][1] is None})
    froms: dict[str, list[str]] = {}
    for n in sorted(used):
        if IMPORTS[n][1] is not None:
            froms.setdefault(IMPORTS[n][0], []).append(n)
    stdlib = [f"import {m}" for m in modules if m != "numpy"] + [
        f"from {m} import {', '.join(names)}" for m, names in sorted(froms.items())
    ]
    imports = "\n".join(stdlib) + ("\n\n" if stdlib else "") + "import numpy as np"
    if "np" not in used:
        imports = "\n".join(stdlib)
    header = f'"""{doc}"""\n\nfrom __future__ import annotations\n\n{imports}\n'
    if exports:
        # sorted as linters expect: constants, classes, then functions
        order = sorted(exports, key=lambda n: (not n.isupper(), not n[:1].isupper(), n))
        listed = "".join(f'    "{n}",\n' for n in order)
        header += f"\n__all__ = [\n{listed}]\n"
    return header + "\n\n" + body + "\n"


def shared_pieces() -> list[str]:
    """Pieces every exported module needs: the input checks of :mod:`impactsym.validation`
    and :func:`impactsym.numeric.roots.bracketed_newton`, under a banner."""
    banner = (
        "# -- input checks (impactsym.validation) and the bracketed root finder "
        "(impactsym.numeric.roots)"
    )
    names = ("_BYTES_OR_TEXT", "CONDITIONS", "check_condition", "real_array", "_where")
    return [
        banner,
        *(package_source(validation, n) for n in (*names, "finish", "broadcast")),
        *(package_source(roots, n) for n in ("ArrayFunction", "bracketed_newton")),
    ]
