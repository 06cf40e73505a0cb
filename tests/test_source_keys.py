"""The code key keeps what compiled code can depend on, by meaning (issue 42; oceangnc.core.source_keys).

Each edit is made on a copy of the package and keyed with a memo folder of its own, in-process: a
comment, a docstring or a module no compiled function reaches keeps the key; a law, a module constant
read by compiled code, or an edit whose mtime was restored (cp -p, rsync -t, tar x) gives a new one. That
a new key recompiles and the old key brings the old machine code back is tests/test_caches.py's."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

from oceangnc.core import source_keys

SRC = Path(__file__).resolve().parents[1] / "src" / "oceangnc"


def _write(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)


@pytest.fixture
def pkg(tmp_path):
    dst = tmp_path / "oceangnc"
    shutil.copytree(SRC, dst, ignore=shutil.ignore_patterns("__pycache__"))
    return dst


def _key(pkg: Path) -> str:
    return source_keys.tree_key(pkg, pkg.parent / "memo", _write, closure=True)


def _edit(path: Path, old: str, new: str) -> None:
    src = path.read_text()
    assert old in src, (path, old)
    path.write_text(src.replace(old, new, 1))


def test_comments_docstrings_and_unreached_modules_keep_the_key(pkg):
    k0 = _key(pkg)
    assert _key(pkg) == k0
    rot = pkg / "core" / "rotations.py"  # compiled laws
    rot.write_text(rot.read_text() + "\n# a comment appended to a compiled module\n")
    _edit(rot, '"""', '"""Docstring edited. ')
    assert _key(pkg) == k0
    cli = pkg / "mavlink" / "cli.py"  # no compiled function reaches it: even a code edit keeps the key
    cli.write_text(cli.read_text() + "\n\nUNUSED_BY_COMPILED_CODE = 1\n")
    assert _key(pkg) == k0
    closure = set(
        source_keys.compiled_closure(source_keys.file_facts(pkg, source_keys._py_files(pkg), pkg.parent / "m2", _write))
    )
    assert "oceangnc/core/rotations.py" in closure and "oceangnc/mavlink/cli.py" not in closure


def test_a_law_and_a_module_constant_change_the_key(pkg):
    k0 = _key(pkg)
    rot = pkg / "core" / "rotations.py"
    src = rot.read_text()
    rot.write_text(src + "\n\n@njit(cache=True)\ndef wrap2(a):\n    return 2.0 * a\n")
    k1 = _key(pkg)
    assert k1 != k0
    rot.write_text(src)
    assert _key(pkg) == k0  # undone: the old key
    # a constant of a module without numba, imported by compiled code (the signal defaults of the plants)
    sig = pkg / "core" / "signals.py"
    assert "numba" not in sig.read_text() and "njit" not in sig.read_text()
    sig.write_text(sig.read_text() + "\n\nA_NEW_CONSTANT = 3.0\n")
    assert _key(pkg) != k0


def test_an_edit_with_its_mtime_restored_is_seen(pkg):
    """``cp -p`` / ``rsync -t`` / ``tar x`` put an edited file's old mtime back; with the same size the
    (name, mtime, size) memo gave the old key (and the old machine code) back. The ctime cannot be restored."""
    rot = pkg / "core" / "rotations.py"
    k0 = _key(pkg)
    st = rot.stat()
    src = rot.read_text()
    i = src.index("2.0 * np.pi") if "2.0 * np.pi" in src else None
    edited = src.replace("2.0", "3.0", 1) if i is not None else src.replace("0.5", "0.7", 1)
    assert edited != src and len(edited) == len(src)
    rot.write_text(edited)
    os.utime(rot, ns=(st.st_atime_ns, st.st_mtime_ns))
    assert rot.stat().st_mtime_ns == st.st_mtime_ns and rot.stat().st_size == st.st_size
    assert _key(pkg) != k0
