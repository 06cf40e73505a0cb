"""The import graph (issue 25): no cycle, counting imports inside functions; the core imports no
sibling package (it knows no vehicle, no file format, no command line)."""

from __future__ import annotations

from import_graph import cycles, edges

#: what oceangnc.core may import besides itself: the package's error types and version
CORE_MAY_IMPORT = {"oceangnc", "oceangnc.errors", "oceangnc._version", "oceangnc.units"}


def test_the_import_graph_has_no_cycle():
    found = cycles(edges())
    assert found == [], "import cycles (imports inside functions count):\n" + "\n".join(map(str, found))


def test_the_core_imports_no_sibling_package():
    bad = {
        (mod, target, line)
        for mod, targets in edges().items()
        if mod.startswith("oceangnc.core")
        for target, places in targets.items()
        if not target.startswith("oceangnc.core") and target not in CORE_MAY_IMPORT
        for line, _ in places
    }
    assert not bad, sorted(bad)


def test_the_graph_reader_sees_imports_inside_functions_and_cycles():
    """The reader itself: a function-level import is an edge, and a two-module loop is a cycle."""
    e = edges()
    # oceangnc.cli imports its subcommands inside functions
    assert any(inside for places in e["oceangnc.cli"].values() for _, inside in places)
    assert cycles({"a": {"b": []}, "b": {"a": []}, "c": {"a": []}}) == [["a", "b"]]
