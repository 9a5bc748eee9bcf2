"""Python source of package definitions, and NumPy-only modules made of them.

* :func:`package_source` cuts a function, class or constant out of a package module's
  source (optionally renamed, a keyword made required, a method replaced);
* :func:`collect` starts from such cuts (:class:`Cut`) and source written for the
  purpose (:class:`Text`) and adds every package definition they use, found by
  following the package's own imports, until nothing is missing;
* :func:`module_source` joins the pieces into one module that imports exactly what
  they use, and refuses a name that nothing defines.

Why: ``impactsym export python`` writes the package's own kernels, not a second
implementation of them; a definition that a kernel comes to use is exported with it.
"""

from __future__ import annotations

import ast
import builtins
import importlib
import inspect
import re
import symtable
import sys
import textwrap
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache
from types import ModuleType


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


def _import_bindings(piece: str) -> dict[str, tuple[str, str | None, str | None]] | None:
    """``{name: (module, attribute, alias)}`` if ``piece`` is only import statements."""
    tree = ast.parse(piece)
    if not tree.body or not all(isinstance(n, ast.Import | ast.ImportFrom) for n in tree.body):
        return None
    bindings = {}
    for node in tree.body:
        for alias in node.names:
            if isinstance(node, ast.Import):
                name = alias.asname or alias.name.split(".")[0]
                bindings[name] = (alias.name, None, alias.asname)
            else:
                bindings[alias.asname or alias.name] = (node.module, alias.name, alias.asname)
    return bindings


def _import_lines(needed: dict[str, tuple[str, str | None, str | None]]) -> str:
    """Import statements of ``needed`` in the order linters expect (standard library,
    then NumPy; plain imports before ``from`` imports, each sorted by module)."""
    groups = []
    for third_party in (False, True):
        chosen = {n: v for n, v in needed.items() if (v[0].split(".")[0] == "numpy") == third_party}
        plain = sorted({(m, a) for m, attr, a in chosen.values() if attr is None})
        froms: dict[str, list[str]] = {}
        for m, attr, a in chosen.values():
            if attr is not None:
                froms.setdefault(m, []).append(attr if a is None else f"{attr} as {a}")
        lines = [f"import {m}" + (f" as {a}" if a else "") for m, a in plain]
        lines += [f"from {m} import {', '.join(sorted(set(v)))}" for m, v in sorted(froms.items())]
        if lines:
            groups.append("\n".join(lines))
    return "\n\n".join(groups)


def module_source(doc: str, pieces: Sequence[str], *, exports: Sequence[str] = ()) -> str:
    """A module with docstring ``doc`` made of ``pieces`` (source text, in order).

    A piece given twice with the same text is written once; two different pieces that
    define the same name are an error, and so is a name the pieces use but nothing
    defines. The imports are exactly the ones the pieces use: those of :data:`IMPORTS`,
    and pieces that are import statements (standard library or NumPy only), which go to
    the top. ``exports`` becomes ``__all__`` (sorted).

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
    hoisted: dict[str, tuple[str, str | None, str | None]] = {}
    code = []
    for piece in unique:
        bindings = _import_bindings(piece)
        if bindings is None:
            code.append(piece)
            continue
        tops = {m.split(".")[0] for m, _, _ in bindings.values()}  # collections.abc
        if tops - set(sys.stdlib_module_names) - {"numpy"}:
            raise ValueError(
                f"the generated module may import the standard library and "
                f"NumPy only, got {piece!r}"
            )
        hoisted.update(bindings)
    owner: dict[str, str] = {}
    for piece in code:
        for name in _definitions(ast.parse(piece)):
            if name in owner or name in hoisted:
                raise ValueError(f"two pieces of the generated module define {name!r}")
            owner[name] = piece
    body = "\n\n\n".join(code)
    free = _free_names(body) - set(hoisted)
    missing = free - set(IMPORTS)
    if missing:
        raise ValueError(f"the generated module uses undefined names: {sorted(missing)}")
    undefined = [n for n in exports if n not in owner]
    if undefined:
        raise ValueError(f"exported names not defined: {undefined}")
    needed = dict(hoisted)
    for name in free & set(IMPORTS):
        module, attribute = IMPORTS[name]
        needed[name] = (module, attribute, "np" if name == "np" else None)
    header = f'"""{doc}"""\n\nfrom __future__ import annotations\n\n{_import_lines(needed)}\n'
    if exports:
        # sorted as linters expect: constants, classes, then functions
        order = sorted(exports, key=lambda n: (not n.isupper(), not n[:1].isupper(), n))
        listed = "".join(f'    "{n}",\n' for n in order)
        header += f"\n__all__ = [\n{listed}]\n"
    return header + "\n\n" + body + "\n"


@dataclass(frozen=True)
class Cut:
    """A definition to cut from a package module (the options of :func:`package_source`;
    ``replace`` as ``((method, source), ...)``)."""

    module: ModuleType
    name: str
    rename: str | None = None
    required: tuple[str, ...] = ()
    replace: tuple[tuple[str, str], ...] = ()

    def source(self) -> str:
        """The cut source."""
        replace = dict(self.replace) or None
        return package_source(
            self.module, self.name, rename=self.rename, required=self.required, replace=replace
        )


@dataclass(frozen=True)
class Text:
    """Source written for the generated module; the names it uses are resolved through
    the imports of ``context`` (``None``: it uses none of the package's)."""

    source: str
    context: ModuleType | None = None


def _origin(module: ModuleType, name: str) -> ModuleType | None:
    """The package module that defines ``name`` as ``module`` sees it (through its
    module-level ``from impactsym... import``), or ``None``."""
    tree = _parsed(module)[1]
    try:
        _node(tree, name)
        return module
    except ValueError:
        pass
    statements = list(tree.body)
    statements += [s for node in tree.body if isinstance(node, ast.If) for s in node.body]
    for node in statements:
        if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            for alias in node.names:
                if (alias.asname or alias.name) != name:
                    continue
                if alias.name != name or not node.module.startswith("impactsym"):
                    return None  # renamed on import, or not the package's
                return _origin(importlib.import_module(node.module), name)
    return None


def _import_of(module: ModuleType, name: str) -> str | None:
    """The module-level import of ``name`` in ``module`` if it is from the standard
    library or NumPy (as one statement), else ``None``."""
    for node in _parsed(module)[1].body:
        if not isinstance(node, ast.Import | ast.ImportFrom) or getattr(node, "level", 0):
            continue
        for alias in node.names:
            if isinstance(node, ast.Import):
                bound, top = alias.asname or alias.name.split(".")[0], alias.name
            else:
                bound, top = alias.asname or alias.name, node.module or ""
            top = top.split(".")[0]
            if bound == name and (top in sys.stdlib_module_names or top == "numpy"):
                single = type(node)(**{**vars(node), "names": [alias]})
                return ast.unparse(single)
    return None


def collect(items: Sequence[Cut | Text | str]) -> list[str]:
    """The pieces of a module: the imports, every package definition ``items`` need (by
    module, the most basic module first, each in source order), then ``items`` in order
    (a ``str`` is written as it is, e.g. a comment). Definitions come first because a
    class base, a decorator or a default value is evaluated when the module is loaded.

    A name the items use and do not define is looked up where their module (a cut's, a
    text's ``context``) gets it from; its definition is cut there, and so on for the
    names that one uses. Names of :data:`IMPORTS` are imports, not definitions.

    >>> import impactsym.validation as validation
    >>> pieces = collect([Cut(validation, "finish")])
    >>> pieces[0].splitlines()[0], len(pieces)
    ('def finish(result: np.ndarray, is_scalar: bool) -> float | np.ndarray:', 1)
    """
    given: list[str] = []
    imports: list[str] = []
    defined: dict[str, str] = {}
    queue: list[tuple[ModuleType | None, str]] = []

    def define(piece: str, context: ModuleType | None) -> None:
        for name in _definitions(ast.parse(piece)):
            if defined.get(name, piece) != piece:
                raise ValueError(f"two pieces of the generated module define {name!r}")
            defined[name] = piece
        queue.extend((context, n) for n in sorted(_free_names(piece)))

    for item in items:
        if isinstance(item, str):
            given.append(item)
            continue
        piece = item.source() if isinstance(item, Cut) else item.source
        if piece not in given:
            given.append(piece)
            define(piece, item.module if isinstance(item, Cut) else item.context)
    groups: dict[str, list[tuple[int, str]]] = {}
    while queue:
        context, name = queue.pop(0)
        if name in defined or name in IMPORTS:
            continue
        origin = None if context is None else _origin(context, name)
        statement = None if context is None or origin else _import_of(context, name)
        if statement is not None:  # the standard library or NumPy, as the package imports it
            imports.insert(0, statement)
            defined[name] = statement
            continue
        if origin is None:
            where = "the written source" if context is None else context.__name__
            raise ValueError(f"the generated module uses {name!r} ({where}), not a package name")
        piece = package_source(origin, name)
        groups.setdefault(origin.__name__, []).append(
            (_node(_parsed(origin)[1], name).lineno, piece)
        )
        define(piece, origin)
    used: list[str] = []
    for module, pieces in reversed(groups.items()):
        used += [f"# -- {module}: definitions used below", *(p for _, p in sorted(pieces))]
    return imports + used + given
