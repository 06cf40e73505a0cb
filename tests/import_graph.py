"""The package's import graph read from its sources (imports inside functions counted too)."""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"


def module_name(path: Path) -> str:
    parts = list(path.relative_to(SRC).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def modules() -> dict[str, Path]:
    return {module_name(p): p for p in sorted((SRC / "oceangnc").rglob("*.py"))}


def _resolve(mod: str, is_pkg: bool, level: int, target: str | None) -> str:
    base = mod.split(".") if is_pkg else mod.split(".")[:-1]
    if level > 1:
        base = base[: len(base) - (level - 1)]
    return ".".join([*base, target] if target else base)


def _imports(tree: ast.AST, mod: str, is_pkg: bool, mods) -> dict[str, list[tuple[int, bool]]]:
    found: dict[str, list[tuple[int, bool]]] = {}

    def visit(node, in_func: bool) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.If) and "TYPE_CHECKING" in ast.unparse(child.test):
                continue  # for type checkers only: not run
            f = in_func or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef))
            names: list[str] = []
            if isinstance(child, ast.Import):
                names = [a.name for a in child.names]
            elif isinstance(child, ast.ImportFrom):
                base = _resolve(mod, is_pkg, child.level, child.module) if child.level else (child.module or "")
                subs = [f"{base}.{a.name}" for a in child.names if f"{base}.{a.name}" in mods]
                names = subs or [base]  # ``from . import postproc`` imports postproc, not the package
            for n in names:
                parts = n.split(".")  # the longest prefix that is a module of the package
                while parts and ".".join(parts) not in mods:
                    parts.pop()
                t = ".".join(parts)
                if t and t != mod and t.startswith("oceangnc"):
                    found.setdefault(t, []).append((child.lineno, f))
            visit(child, f)

    visit(tree, False)
    return found


def edges() -> dict[str, dict[str, list[tuple[int, bool]]]]:
    """``{module: {imported oceangnc module: [(line, inside a function), ...]}}``."""
    mods = modules()
    return {
        mod: _imports(ast.parse(path.read_text()), mod, path.name == "__init__.py", mods) for mod, path in mods.items()
    }


def cycles(graph: dict[str, dict]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    res: list[list[str]] = []
    counter = [0]

    def strong(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph.get(v, {}):
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                res.append(sorted(comp))

    import sys

    sys.setrecursionlimit(10000)
    for v in graph:
        if v not in index:
            strong(v)
    return res
