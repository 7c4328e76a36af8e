"""Structure of the code base: no import cycles among the project's own modules.

The check reads the source (``tools/import_cycles.py``): every import counts, function-local
ones included, so a lazy import cannot hide a cycle.  A planted cycle proves it can fail.
"""

from __future__ import annotations

import importlib.util
import textwrap
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def load_tool():  # noqa: ANN201 - the tool module
    path = ROOT / "tools" / "import_cycles.py"
    spec = importlib.util.spec_from_file_location("import_cycles", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_project_has_no_import_cycles():
    tool = load_tool()
    assert tool.cycles(tool.import_graph(ROOT)) == []


def test_a_function_local_import_closing_a_cycle_is_found(tmp_path):
    tool = load_tool()
    package = tmp_path / "twin"
    (package / "fem").mkdir(parents=True)
    (tmp_path / "apdl_like").mkdir()
    (package / "__init__.py").write_text("")
    (package / "fem" / "__init__.py").write_text("from twin.fem.thermal import step\n")
    (package / "fem" / "thermal.py").write_text(
        textwrap.dedent(
            """
            def step():
                from twin.fem import forms  # runs twin/fem/__init__: a cycle
                return forms
            """
        )
    )
    (package / "fem" / "forms.py").write_text("")
    found = tool.cycles(tool.import_graph(tmp_path))
    assert found == [["twin.fem", "twin.fem.thermal"]]
