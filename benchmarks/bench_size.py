"""Size of the installed core (``designkit/``; the lab, ``designkit_lab/``, excluded) against issue 33's targets.

Run from the repository root::

    python benchmarks/bench_size.py                       # this tree
    python benchmarks/bench_size.py --rev c8fe4cc         # a commit too, in the same run (git archive)
    python benchmarks/bench_size.py --rev c8fe4cc --list  # and name every module, function and import counted

Figures (all from the source, nothing imported):

- **lines**: every line of every ``.py`` file under ``designkit/`` (blank lines and docstrings included:
  what a reader and the wheel carry).
- **modules over 800 lines**.
- **function bodies over 80 lines**: ``def`` (methods and nested functions included), from the first
  statement after the docstring to the last line (signature and docstring excluded: the issue's count,
  25 on c8fe4cc).
- **private names imported across modules**: ``from x import _y`` where ``x`` is another designkit module,
  and ``m._y`` where ``m`` is a designkit module imported under that name; each (importing module, name)
  once. Names in the designated shared modules (``_validation``, ``_io`` ... whose names are private to
  the package, not to a module: tests/test_architecture.py's ``SHARED``) are counted apart.
"""

from __future__ import annotations

import argparse
import ast
import io
import subprocess
import sys
import tarfile
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
#: Issue 33's targets.
TARGETS = {"lines": 28_000, "modules_over_800": 4, "functions_over_80": 20, "private_imports": 0}
MODULE_LIMIT, FUNCTION_LIMIT = 800, 80
#: Modules whose private names are the package's shared helpers (tests/test_architecture.py, SHARED).
SHARED = {"designkit._validation", "designkit._schemas", "designkit._io", "designkit._resources",
          "designkit._workers", "designkit.cli._app", "designkit.cli._options"}


@dataclass
class Size:
    lines: int = 0
    modules: list = field(default_factory=list)      # (lines, module)
    functions: list = field(default_factory=list)    # (lines, module:qualname)
    private: list = field(default_factory=list)      # "importer: target._name"
    shared: list = field(default_factory=list)       # the same, from SHARED modules


def _module_name(rel: Path) -> str:
    parts = list(rel.with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _resolve(mod: str, is_pkg: bool, node: ast.ImportFrom) -> str:
    if not node.level:
        return node.module or ""
    base = mod.split(".") if is_pkg else mod.split(".")[:-1]
    base = base[: len(base) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def _functions(tree: ast.AST, mod: str, out: list) -> None:
    def visit(node, prefix):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                body = child.body
                if (body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant)
                        and isinstance(body[0].value.value, str)):
                    body = body[1:]  # the docstring
                n = child.end_lineno - body[0].lineno + 1 if body else 0
                name = f"{prefix}{child.name}"
                if n > FUNCTION_LIMIT:
                    out.append((n, f"{mod}:{name}"))
                visit(child, name + ".")
            elif isinstance(child, ast.ClassDef):
                visit(child, f"{prefix}{child.name}.")
            else:
                visit(child, prefix)
    visit(tree, "")


def measure(files: dict[str, str]) -> Size:
    """``files``: path relative to the repository (``designkit/...py``) -> source."""
    size = Size()
    modules = {_module_name(Path(p)): (p, src) for p, src in files.items()}
    for mod, (path, src) in sorted(modules.items()):
        n = src.count("\n") + (0 if src.endswith("\n") or not src else 1)
        size.lines += n
        if n > MODULE_LIMIT:
            size.modules.append((n, mod))
        tree = ast.parse(src)
        _functions(tree, mod, size.functions)
        is_pkg = path.endswith("__init__.py")
        aliases: dict[str, str] = {}  # local name -> designkit module
        seen = set()

        def count(target: str, name: str) -> None:
            if (target, name) in seen or target == mod:
                return
            seen.add((target, name))
            (size.shared if target in SHARED else size.private).append(f"{mod}: {target}.{name}")

        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                target = _resolve(mod, is_pkg, node)
                if not target.startswith("designkit"):
                    continue
                for a in node.names:
                    if f"{target}.{a.name}" in modules:  # a submodule imported by name
                        aliases[a.asname or a.name] = f"{target}.{a.name}"
                    elif a.name.startswith("_") and not a.name.startswith("__"):
                        count(target, a.name)
            elif isinstance(node, ast.Import):
                for a in node.names:
                    if a.name.startswith("designkit") and a.asname:
                        aliases[a.asname] = a.name
        for node in ast.walk(tree):
            if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id in aliases
                    and node.attr.startswith("_") and not node.attr.startswith("__")):
                count(aliases[node.value.id], node.attr)
    size.modules.sort(reverse=True)
    size.functions.sort(reverse=True)
    return size


def tree_files(root: Path) -> dict[str, str]:
    return {p.relative_to(root).as_posix(): p.read_text(encoding="utf-8")
            for p in sorted((root / "designkit").rglob("*.py")) if "__pycache__" not in p.parts}


def rev_files(rev: str) -> dict[str, str]:
    data = subprocess.run(["git", "-C", str(REPO), "archive", rev, "designkit"], capture_output=True, check=True).stdout
    out = {}
    with tarfile.open(fileobj=io.BytesIO(data)) as tar:
        for m in tar.getmembers():
            if m.isfile() and m.name.endswith(".py"):
                out[m.name] = tar.extractfile(m).read().decode("utf-8")
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rev", help="Also measure this commit (e.g. the baseline c8fe4cc), beside the tree.")
    ap.add_argument("--list", action="store_true", help="Name what each figure counts.")
    args = ap.parse_args(argv)
    runs = []
    if args.rev:
        runs.append((args.rev, measure(rev_files(args.rev))))
    runs.append(("this tree", measure(tree_files(REPO))))
    rows = [("core lines (designkit/, lab excluded)", "lines", lambda s: s.lines),
            (f"modules over {MODULE_LIMIT} lines", "modules_over_800", lambda s: len(s.modules)),
            (f"function bodies over {FUNCTION_LIMIT} lines", "functions_over_80", lambda s: len(s.functions)),
            ("private names imported across modules", "private_imports", lambda s: len(s.private)),
            ("  (from the shared helper modules, apart)", None, lambda s: len(s.shared))]
    head = f"{'figure':44s}" + "".join(f"{name:>14s}" for name, _ in runs) + f"{'target':>10s}{'met':>6s}"
    print(head)
    for label, key, get in rows:
        vals = [get(s) for _, s in runs]
        target = TARGETS.get(key)
        met = "" if target is None else ("yes" if vals[-1] <= target else "no")
        print(f"{label:44s}" + "".join(f"{v:>14,}" for v in vals)
              + (f"{'≤' + format(target, ','):>10s}{met:>6s}" if target is not None else ""))
    if args.list:
        name, s = runs[-1]
        print(f"\n{name}: modules over {MODULE_LIMIT} lines")
        print("\n".join(f"  {n:5d} {m}" for n, m in s.modules))
        print(f"{name}: function bodies over {FUNCTION_LIMIT} lines")
        print("\n".join(f"  {n:5d} {f}" for n, f in s.functions))
        print(f"{name}: private names imported across modules")
        print("\n".join(f"  {p}" for p in s.private))
    return 0


if __name__ == "__main__":
    sys.exit(main())
