"""What a user without designkit reads first: the generated header's and module's opening examples run as printed,
every lookup header compiles strictly in a program that calls none of its functions, and every export records its
estimator and version (issue 38).

Each test exports a shipped table once (no table is built).
"""

from __future__ import annotations

import doctest
import re
import shutil
import subprocess
import sys

import pytest

from designkit.export import export_bytes
from designkit.export.estimator import ESTIMATOR, ESTIMATOR_VERSION

CC = shutil.which("cc") or shutil.which("gcc")
STRICT = ("-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic")
needs_cc = pytest.mark.skipif(CC is None, reason="no C compiler")
#: The README's main job, as the examples ask it.
SCENE = dict(noise_c=0.05, delta_t_c=10.0)


def _c_example(header: str) -> tuple[str, str, list[str]]:
    """The opening comment's example: (program text, what it says it prints, its compile command's flags)."""
    comment = header.split("*/", 1)[0]
    block = comment.split(" * Example (", 1)[1].split("\n", 1)[1]
    lines = []
    for line in block.splitlines():
        if not line.startswith(" *     "):
            break
        lines.append(line[len(" *     "):])
    m = re.fullmatch(r"prints (.*) \.\.\.  \((cc .*)\)", lines[-1])
    assert m, lines[-1]
    return "\n".join(lines[:-1]) + "\n", m.group(1), m.group(2).split()[1:]


@needs_cc
def test_the_c_header_s_opening_example_runs_as_printed(tmp_path):
    res = export_bytes("svm-fine", "c", **SCENE)
    program, prints, command = _c_example(res.data.decode())
    include = re.search(r'#include "(.+)"', program).group(1)
    (tmp_path / include).write_bytes(res.data)
    (tmp_path / "main.c").write_text(program)
    assert command == ["-std=c99", "main.c", "-lm"]
    proc = subprocess.run([CC, *command, "-o", "main"], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    out = subprocess.run(["./main"], cwd=tmp_path, capture_output=True, text=True, timeout=60).stdout
    assert out.startswith(prints + " (") and prints == "1.225 s", (out, prints)


def test_the_python_module_s_opening_example_runs_as_printed(tmp_path):
    res = export_bytes("svm-fine", "python", **SCENE)
    text = res.data.decode()
    doc = text.split('"""', 2)[1]
    example = doc.split("Example (save this file as ", 1)[1]
    name = example.split(" ", 1)[0]
    block = example.split("\n\n", 2)[1]  # the indented >>> lines and their answer
    assert ">>> import designkit_table as t" in block and "1.225" in block
    (tmp_path / name).write_bytes(res.data)
    # a fresh interpreter that sees only the saved module (no designkit), as the example says
    code = ("import doctest, sys; sys.path.insert(0, '.'); t = doctest.DocTestParser().get_doctest("
            f"{block!r}, {{}}, 'example', None, 0); r = doctest.DocTestRunner(); r.run(t); "
            "sys.exit(1 if r.failures or not r.tries else 0)")
    proc = subprocess.run([sys.executable, "-I", "-c", code], cwd=tmp_path, capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    assert doctest.DocTestParser().get_examples(block)[-1].want.strip() == "1.225"


@needs_cc
@pytest.mark.parametrize("table, kwargs", [("svm-fine", SCENE), ("ideal-paper", dict(SCENE, contact="1:2")),
                                           ("svm-paper-varied", {})])
def test_a_lookup_header_compiles_strictly_in_a_program_that_calls_nothing(tmp_path, table, kwargs):
    """With the estimator, an ideal table (the grid rule) and a table the estimator cannot answer: every function
    is ``static inline``, so including the header alone, or with other headers, warns about nothing."""
    (tmp_path / "t.h").write_bytes(export_bytes(table, "c", **kwargs).data)
    (tmp_path / "none.c").write_text('#include <stdio.h>\n#include <math.h>\n#include "t.h"\n'
                                     "int main(void) { return 0; }\n")
    for opt in ("-O0", "-O2"):
        proc = subprocess.run([CC, *STRICT, opt, "-c", "none.c"], cwd=tmp_path, capture_output=True, text=True,
                              timeout=300)
        assert proc.returncode == 0, (opt, proc.stderr[-2000:])


@pytest.mark.parametrize("fmt", ["c", "python", "json", "csv", "npz"])
def test_every_export_records_its_estimator_and_version(fmt):
    for table, kwargs in (("svm-fine", SCENE), ("svm-paper-varied", {})):
        res = export_bytes(table, fmt, **kwargs)
        est = res.provenance["estimator"]
        assert est["name"] == ESTIMATOR and est["version"] == ESTIMATOR_VERSION
        if fmt == "c":
            text = res.data.decode()
            assert f'#define DESIGNKIT_ESTIMATOR "{ESTIMATOR}"' in text
            assert f"#define DESIGNKIT_ESTIMATOR_VERSION {ESTIMATOR_VERSION}" in text
        elif fmt in ("python", "json"):
            assert ESTIMATOR in res.data.decode()
