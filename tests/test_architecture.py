"""The architecture holds: layers, no import cycles, a light ``import avar``, lint.

The layers contract lives in ``pyproject.toml`` (``[tool.importlinter]``) and
``docs/architecture.md`` draws it. These tests fail on any new upward import,
any cycle among the package's modules, a heavy top-level import or a ruff
finding.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "src" / "avar"



def plot_edges() -> set[tuple[str, str]]:
    """The lazy ``.plot()`` imports, the only edges allowed to point upward: the
    ``ignore_imports`` of the contract in pyproject.toml (one place to list them)."""
    text = (ROOT / "pyproject.toml").read_text()
    block = re.search(r"ignore_imports = \[(.*?)\]", text, re.S).group(1)
    edges = {tuple(part.strip() for part in edge.split("->")) for edge in re.findall(r'"([^"]+)"', block)}
    assert edges and all(target == "avar.plotting" for _, target in edges)
    return edges


PLOT_EDGES = plot_edges()

HEAVY = ("numpy", "scipy", "pandas", "matplotlib", "numba", "dask", "pyarrow", "rosbags", "yaml")


def test_layers_contract_is_kept():
    importlinter_cli = pytest.importorskip("importlinter.cli")
    assert importlinter_cli.lint_imports(config_filename=str(ROOT / "pyproject.toml")) == 0


def strongly_connected_components(edges: dict[str, set[str]]) -> list[list[str]]:
    """Tarjan's algorithm, iterative: every component of more than one module is a cycle."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    components = []
    counter = 0
    for root in edges:
        if root in index:
            continue
        work = [(root, iter(sorted(edges[root])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(edges.get(child, ())))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    components.append(sorted(component))
    return components


def test_scc_finder_finds_a_planted_cycle():
    edges = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert strongly_connected_components(edges) == [["a", "b", "c"]]
    assert strongly_connected_components({"a": {"b"}, "b": set()}) == []


def test_no_import_cycles_among_modules():
    grimp = pytest.importorskip("grimp")
    graph = grimp.build_graph("avar")
    edges: dict[str, set[str]] = {}
    for module in graph.modules:
        targets = set()
        for target in graph.find_modules_directly_imported_by(module):
            if any(module.startswith(a) and target.startswith(b) for a, b in PLOT_EDGES):
                continue
            # A package's __init__ re-exporting its children is not a cycle of ideas.
            if target.startswith(module + "."):
                continue
            targets.add(target)
        edges[module] = targets
    assert strongly_connected_components(edges) == []


def test_import_avar_loads_no_heavy_dependency():
    code = "import sys, json, avar; print(json.dumps(sorted(sys.modules)))"
    loaded = json.loads(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                                       check=True).stdout)
    heavy = sorted({m.split(".")[0] for m in loaded} & set(HEAVY))
    assert heavy == []
    assert [m for m in loaded if m.startswith("avar.")] == []


def test_allan_variance_of_an_array_loads_no_pandas():
    # pandas (and the pyarrow it loads) is ~100 MB of resident memory: only tables and pandas inputs need it
    code = ("import sys, numpy as np, avar; x = np.random.default_rng(0).standard_normal(5000); "
            "avar.avar(x); avar.avar(x, type='to', ci='chi2'); print(sorted({m.split('.')[0] for m in sys.modules}))")
    loaded = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert "'numpy'" in loaded and "'pandas'" not in loaded and "'pyarrow'" not in loaded


def test_public_names_resolve_lazily():
    import avar

    for name in avar.__all__:
        assert getattr(avar, name) is not None, name
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        avar.nope  # noqa: B018


def test_no_module_over_about_400_lines():
    sizes = {str(p.relative_to(PACKAGE)): len(p.read_text().splitlines()) for p in PACKAGE.rglob("*.py")}
    assert {name: n for name, n in sizes.items() if n > 450} == {}


def test_ruff_is_clean():
    ruff = shutil.which("ruff")
    if ruff is None:
        pytest.skip("ruff is not installed (the test extra installs it)")
    result = subprocess.run([ruff, "check", str(ROOT)], capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
