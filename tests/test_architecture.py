"""The package's shape is a contract: layers that depend only downward, no import cycles, no
private names imported from a peer module, every public module declaring ``__all__`` with names
that exist, and every docstring example run (against the installed package). The lab
(``designkit_lab``: benchmarks' instruments, the paper's report) sits above the core's library
layers: it imports the core, the core never imports it (only the CLI loads it, when its command runs)."""

from __future__ import annotations

import ast
import doctest
import importlib
import importlib.util
import pkgutil
from pathlib import Path

import pytest

import designkit
import designkit_lab

PKG = Path(designkit.__file__).resolve().parent
ROOTS = {"designkit": PKG, "designkit_lab": Path(designkit_lab.__file__).resolve().parent}

# Layers, lowest first. A module may import from its own layer and the layers below, never above.
LAYERS = [
    {"designkit._validation", "designkit._schemas", "designkit._io", "designkit._resources",
     "designkit._workers", "designkit._numbers"},
    {"designkit.properties", "designkit.sensor", "designkit.scene", "designkit.materials", "designkit.objects",
     "designkit.figures"},
    {"designkit.models", "designkit.rig"},
    {"designkit.simulation"},
    {"designkit.recognition"},
    {"designkit.tables"},
    {"designkit.sweep"},
    {"designkit.query", "designkit.io_batch"},
    {"designkit.export", "designkit.calibration", "designkit.design"},
    {"designkit_lab"},
    {"designkit.cli", "designkit.__main__", "designkit_lab.cli"},
]


def _modules() -> list[str]:
    names = list(ROOTS)
    for root, folder in ROOTS.items():
        names.extend(info.name for info in pkgutil.walk_packages([str(folder)], prefix=root + "."))
    return sorted(names)


def _file(mod: str) -> Path:
    """Where ``mod`` would live (a folder for a package), whether or not it exists."""
    root, *rel = mod.split(".")
    return ROOTS[root].joinpath(*rel)


def _path(mod: str) -> Path:
    p = _file(mod)
    return p / "__init__.py" if p.is_dir() else p.with_suffix(".py")


def _imports(mod: str) -> list[tuple[str, list[str], int]]:
    """(imported module, names, line) for every designkit import in ``mod``, relative ones resolved."""
    path = _path(mod)
    tree = ast.parse(path.read_text(encoding="utf-8"))
    pkg = mod if path.name == "__init__.py" else mod.rpartition(".")[0]
    typing_only = {id(n) for block in ast.walk(tree) if isinstance(block, ast.If)
                   and "TYPE_CHECKING" in ast.unparse(block.test) for n in ast.walk(block)}
    out = []
    for node in ast.walk(tree):
        if id(node) in typing_only:  # annotations only: never imported at run time
            continue
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = pkg.split(".")[: len(pkg.split(".")) - (node.level - 1)]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target.split(".")[0] in ROOTS:
                out.append((target, [a.name for a in node.names], node.lineno))
        elif isinstance(node, ast.Import):
            out.extend((a.name, [], node.lineno) for a in node.names if a.name.split(".")[0] in ROOTS)
    return out


def _layer(mod: str) -> int:
    """The layer of ``mod``: that of the longest prefix in :data:`LAYERS` it falls under."""
    if mod == "designkit":
        return 0  # the top-level namespace loads its nouns lazily (PEP 562)
    found = [(len(prefix), i) for i, layer in enumerate(LAYERS) for prefix in layer
             if mod == prefix or mod.startswith(prefix + ".")]
    if not found:
        raise AssertionError(f"{mod} is in no layer: add it to LAYERS in {__file__}")
    return max(found)[1]


MODULES = _modules()


def test_every_module_is_in_a_layer_and_imports_only_downward():
    bad = []
    for mod in MODULES:
        for target, names, line in _imports(mod):
            targets = [target] + [f"{target}.{n}" for n in names if importlib.util.find_spec(target) and
                                  (_file(f"{target}.{n}").is_dir() or _file(f"{target}.{n}").with_suffix(".py").is_file())]
            for t in targets:
                if t == "designkit" and names == ["__version__"]:
                    continue
                if _layer(t) > _layer(mod):
                    bad.append(f"{mod}:{line} imports {t} (a higher layer)")
    assert not bad, "\n".join(bad)


#: The designated homes of shared private helpers (pvlib's tools.py): importing from them is the point.
SHARED = {"designkit._validation", "designkit._schemas", "designkit._io", "designkit._resources", "designkit.cli._app",
          "designkit._numbers",
          "designkit.cli._options", "designkit_lab.reproduce._report"}


def test_no_module_imports_a_private_name_from_a_peer():
    bad = []
    for mod in MODULES:
        for target, names, line in _imports(mod):
            if target in SHARED:
                continue
            for n in names:
                if f"{target}.{n}" in SHARED:
                    continue  # the designated module itself, imported by name
                if n.startswith("_") and not n.startswith("__"):
                    bad.append(f"{mod}:{line} imports {n} from {target}")
    assert not bad, "\n".join(bad)


def test_no_import_cycles_between_modules():
    graph: dict[str, set[str]] = {m: set() for m in MODULES}
    for mod in MODULES:
        for target, names, _ in _imports(mod):
            for t in [target] + [f"{target}.{n}" for n in names]:
                if t in graph and t != mod and not mod.startswith(t + "."):
                    graph[mod].add(t)
    # a package's __init__ importing its own submodules is not a cycle; drop the parent -> child edges
    for mod in graph:
        graph[mod] = {t for t in graph[mod] if not t.startswith(mod + ".")}
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(m: str) -> None:
        state[m] = 1
        stack.append(m)
        for n in sorted(graph[m]):
            if state.get(n) == 1:
                raise AssertionError("import cycle: " + " -> ".join(stack[stack.index(n):] + [n]))
            if n not in state:
                visit(n)
        stack.pop()
        state[m] = 2

    for m in sorted(graph):
        if m not in state:
            visit(m)


@pytest.mark.parametrize("mod", [m for m in MODULES if not m.rsplit(".", 1)[-1].startswith("_")
                                 and not m.startswith(("designkit.cli", "designkit_lab.cli"))])
def test_public_modules_declare_all_with_names_that_exist(mod):
    module = importlib.import_module(mod)
    assert hasattr(module, "__all__"), f"{mod} declares no __all__"
    missing = [n for n in module.__all__ if not hasattr(module, n)
               and importlib.util.find_spec(f"{mod}.{n}") is None]  # a submodule may be listed
    assert not missing, f"{mod}.__all__ names what it does not define: {missing}"


@pytest.mark.parametrize("mod", [m for m in MODULES if m != "designkit.__main__"])  # importing it runs the CLI
def test_docstring_examples_run(mod):
    module = importlib.import_module(mod)
    finder = doctest.DocTestFinder(exclude_empty=True)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    tests = [t for t in finder.find(module, mod) if t.examples]
    for t in tests:
        runner.run(t, out=lambda s: None)
    res = runner.summarize(verbose=False)
    assert res.failed == 0, f"{res.failed} of {res.attempted} docstring examples of {mod} fail (run " \
                            f"python -m pytest --doctest-modules on it to see them)"


def test_the_core_never_imports_the_lab():
    """The installed core answers a user's questions without the lab: no core module imports
    ``designkit_lab``, and the core's CLI does not even name it (the lab's commands reach ``designkit`` through
    the ``designkit.commands`` entry points, :data:`designkit.cli.ENTRY_POINT_GROUP`)."""
    bad = [f"{mod}:{line} imports {t}" for mod in MODULES if mod.split(".")[0] == "designkit"
           for t, _, line in _imports(mod) if t.split(".")[0] == "designkit_lab"]
    assert not bad, "\n".join(bad)
    named = [f"{p.relative_to(PKG.parent)}:{i}" for p in sorted((PKG / "cli").glob("*.py"))
             for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1) if "designkit_lab" in line]
    assert not named, f"the core's CLI names the lab (import_module strings too): {named}"

