"""The lab's commands, added to ``designkit``'s command line through the ``designkit.commands`` entry points.

Each module registers one command on the core's application (:data:`designkit.cli._app.app`) when it is
imported: :mod:`~designkit_lab.cli.bench` (``designkit bench``), :mod:`~designkit_lab.cli.reproduce`
(``designkit reproduce``) and :mod:`~designkit_lab.cli.emulate` (``designkit emulate``). pyproject.toml's
``[project.entry-points."designkit.commands"]`` names them, one entry point per command; the core's CLI
(:mod:`designkit.cli`) imports the one asked for, or all of them for ``designkit --help``, and knows nothing
else of the lab. Each keeps its module-level imports cheap and loads the lab's instruments when it runs.
"""

#: The help panel of the lab's reports (``designkit --help``).
REPORTS = "The paper and accuracy"

__all__ = ["REPORTS", "bench", "emulate", "reproduce"]
