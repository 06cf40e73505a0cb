"""Rules of the test suite itself (issue 26)."""

from __future__ import annotations

import re
from pathlib import Path

TESTS = Path(__file__).parent

#: a skip conditioned on one of the project's own modules (an import error would turn into a silent skip)
OWN_SKIP = re.compile(r"""(importorskip|find_spec|_module)\(\s*["']oceangnc\b""")


def test_only_optional_third_party_packages_may_skip_a_test():
    """``importorskip``/``skipif`` on ``oceangnc.*`` hid an import error as a skip: the project's own
    modules are imported directly, so a broken one fails its tests."""
    found = [
        f"{p.name}:{n}: {line.strip()}"
        for p in sorted(TESTS.rglob("*.py"))
        if p.name != Path(__file__).name
        for n, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
        if OWN_SKIP.search(line)
    ]
    assert not found, found
