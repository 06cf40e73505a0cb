"""The code key of a source tree: what compiled code can depend on, hashed by meaning (issue 42).

A key is a hash of the package's modules that compiled code can depend on (:func:`compiled_closure`:
every module that uses numba and, transitively, every package module it imports), each digested as
its syntax tree without comments and docstrings (:func:`source_digest`). So an edit of a comment, a
docstring, or a module no compiled function reaches (the CLIs, the servers, the reports) keeps the
key and every cache; an edit of anything compiled code may bake in gives a new key. Keys and per-file
facts are remembered against each file's name, size, mtime, ctime and inode, so a process pays one
``stat`` per file, an edit re-parses only the files it touched, and an edit whose mtime was restored
(``cp -p``, ``rsync -t``, ``tar x``) is still seen (its ctime changed).
"""

from __future__ import annotations

import ast
import hashlib
import json
import os
from collections.abc import Callable
from pathlib import Path


def _py_files(path: Path) -> list[Path]:
    if path.is_file():
        return [path]
    out: list[Path] = []
    for dirpath, dirnames, filenames in os.walk(path):
        dirnames[:] = sorted(d for d in dirnames if d != "__pycache__" and not d.startswith("."))
        out.extend(Path(dirpath) / f for f in sorted(filenames) if f.endswith(".py"))
    return out


def _stat_line(f: Path, rel: Path) -> str:
    """What the memo of a key trusts of a file: name, size, mtime, *and* ctime and inode. ``cp -p``,
    ``rsync -t`` or ``tar x`` restore an edited file's mtime (and a same-size edit keeps its size), but
    they cannot restore its ctime: the memo then misses and the content is hashed again."""
    st = f.stat()
    return f"{f.relative_to(rel)}\0{st.st_mtime_ns}\0{st.st_ctime_ns}\0{st.st_ino}\0{st.st_size}\n"


def _strip_docstrings(tree: ast.AST) -> ast.AST:
    for node in ast.walk(tree):
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
                if isinstance(body[0].value.value, str):
                    node.body = body[1:] or [ast.Pass()]
    return tree


def source_digest(data: bytes) -> tuple[str, bool, ast.AST | None]:
    """What a source file *does*: (digest of its syntax tree without comments, docstrings, line numbers
    and layout, so an edit of a comment or a docstring keeps every key; whether it uses numba; the tree).
    A file that does not parse is digested as bytes and counted as compiled."""
    compiled = b"numba" in data or b"njit" in data
    try:
        tree = _strip_docstrings(ast.parse(data))
    except (SyntaxError, ValueError):
        return hashlib.blake2b(data, digest_size=16).hexdigest(), True, None
    return hashlib.blake2b(ast.dump(tree).encode(), digest_size=16).hexdigest(), compiled, tree


def _module_name(rel: str) -> str:
    parts = list(Path(rel).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _imported(tree: ast.AST, name: str, is_pkg: bool) -> list[str]:
    """Absolute names of the modules a module imports anywhere in its body (function-level imports too),
    each with its ``from X import y`` candidates ``X.y`` (a submodule or not: resolved by the caller)."""
    out: set[str] = set()
    pkg = name if is_pkg else name.rpartition(".")[0]
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                up = pkg.split(".")
                up = up[: len(up) - (node.level - 1)] if node.level > 1 else up
                base = ".".join([*up, base] if base else up)
            out.add(base)
            out.update(f"{base}.{a.name}" for a in node.names)
    return sorted(out)


def file_facts(path: Path, files: list[Path], memo_dir: Path, write: Callable[[Path, str], None]) -> dict[str, list]:
    """Per file (path relative to the folder's parent): [stat line, digest, uses numba, imported modules],
    remembered in ``<memo_dir>/files-<folder>.json`` against each file's stat line, so an edit re-reads
    and re-parses only the files it touched."""
    rel = path.parent
    memo = memo_dir / f"files-{hashlib.blake2b(str(path).encode(), digest_size=8).hexdigest()}.json"
    try:
        old = json.loads(memo.read_text())
    except (OSError, ValueError):
        old = {}
    facts: dict[str, list] = {}
    for f in files:
        try:
            line = _stat_line(f, rel)
            r = str(f.relative_to(rel))
            if isinstance(old.get(r), list) and old[r][0] == line:
                facts[r] = old[r]
                continue
            digest, compiled, tree = source_digest(f.read_bytes())
        except OSError:
            continue
        imports = _imported(tree, _module_name(r), f.name == "__init__.py") if tree is not None else []
        facts[r] = [line, digest, compiled, imports]
    if facts != old:
        write(memo, json.dumps(facts))
    return facts


def compiled_closure(facts: dict[str, list]) -> list[str]:
    """The files of a package that compiled code can depend on: every module that uses numba (its
    source names ``numba`` or ``njit``: laws, kernels, the code generators) and, transitively, every
    package module one of them imports (statically, anywhere in its body), with their parent packages'
    ``__init__.py``. Machine code can only bake in what these modules define (callees, module
    constants, generated source); an edit of any other module (a CLI, a server, a report) cannot
    change it, so it is left out of the key. An over-approximation: never too few files."""
    by_name = {_module_name(r): r for r in facts}
    todo = [n for n, r in by_name.items() if facts[r][2]]
    seen: set[str] = set()
    while todo:
        name = todo.pop()
        if name in seen or name not in by_name:
            continue
        seen.add(name)
        parts = name.split(".")
        todo.extend(".".join(parts[:i]) for i in range(1, len(parts)))  # parent packages run first
        todo.extend(m for m in facts[by_name[name]][3] if m in by_name)
    return sorted(by_name[n] for n in seen)


def tree_key(path: Path, memo_dir: Path, write: Callable[[Path, str], None], closure: bool = False) -> str:
    """Hash (16 hex digits) of the names and :func:`source_digest` of the ``.py`` files of a folder (or of
    one file); ``closure``: only the files compiled code can depend on (:func:`compiled_closure`, the
    package's own key).

    Remembered against the files' (name, mtime, ctime, inode, size) list in ``memo_dir`` (``write(path,
    text)`` stores a memo atomically): an unchanged
    tree costs one ``stat`` per file; a touched but unchanged tree (a reinstall) gets the same key back.
    """
    path = Path(path).resolve()
    files = _py_files(path)
    stats = hashlib.blake2b(f"{path}\0{closure}".encode(), digest_size=10)
    for f in files:
        try:
            stats.update(_stat_line(f, path.parent).encode())
        except OSError:
            continue
    memo = memo_dir / stats.hexdigest()
    try:
        key = memo.read_text()
        if len(key) == 16:
            return key
    except OSError:
        pass
    facts = file_facts(path, files, memo_dir, write)
    names = compiled_closure(facts) if closure else sorted(facts)
    h = hashlib.blake2b(digest_size=8)
    for r in names:
        h.update(f"{r}\0{facts[r][1]}\n".encode())
    key = h.hexdigest()
    write(memo, key)
    return key
