"""Sphinx configuration of designkit's documentation site (``sphinx-build -W docs docs/_build``).

The pages are the Markdown files of this folder (MyST); the API reference is generated from the
numpydoc docstrings of the public modules (``api.md``). tests/test_docs_site.py builds it with
warnings as errors.
The examples gallery (``gallery/``, generated) is made by sphinx-gallery from ``examples/gallery/plot_*.py``:
every build runs every script and shows its output and figure.
"""

import designkit

project = "designkit"
author = "designkit developers"
release = version = designkit.__version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "numpydoc",
    "sphinx.ext.mathjax",
    "sphinx_gallery.gen_gallery",
]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "README.md"]

sphinx_gallery_conf = {
    "examples_dirs": "../examples/gallery",
    "gallery_dirs": "gallery",          # generated (git-ignored)
    "filename_pattern": r"/plot_",      # run every script
    "run_stale_examples": True,         # and run it on every build, changed or not: the docs build is its test
    "within_subsection_order": "FileNameSortKey",
    "write_computation_times": False,
    "download_all_examples": False,
    "show_signature": False,
    "remove_config_comments": True,
}
myst_heading_anchors = 3
myst_enable_extensions = ["dollarmath"]
# Links into the repository (`../designkit/...`, `../tables/...`) are for readers of the files on GitHub.
suppress_warnings = ["myst.xref_missing", "myst.header", "misc.highlighting_failure"]

autosummary_generate = False
autodoc_member_order = "bysource"
autodoc_typehints = "none"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_validation_checks = set()
numpydoc_xref_param_type = False

html_theme = "furo"
html_title = f"designkit {release}"

import re  # noqa: E402

#: ``|dT|`` and ``|Ts0 - Ta|`` in docstrings are absolute values, not reStructuredText substitutions.
_ABS = re.compile(r"(?<![\\`|])\|([^|`\n]{1,20})\|(?![_|])")


def _absolute_values(app, what, name, obj, options, lines):
    for i, line in enumerate(lines):
        # a module docstring's "Examples" heading is a rubric: one page may hold several modules' examples
        if i + 1 < len(lines) and line.strip() in ("Examples", "Example") and set(lines[i + 1].strip()) == {"-"}:
            lines[i], lines[i + 1] = f".. rubric:: {line.strip()}", ""
            continue
        if not line.lstrip().startswith((">>>", "...", "|", "+", "=")):
            lines[i] = _ABS.sub(r"\\|\1\\|", line)


def setup(app):
    app.connect("autodoc-process-docstring", _absolute_values)
