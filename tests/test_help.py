"""Every command is documented: ``--help`` works and shows at least one example invocation."""

from __future__ import annotations

import pytest


def _commands():
    import typer.main

    from designkit.cli import app

    group = typer.main.get_command(app)
    out = []

    def walk(cmd, path):
        subs = getattr(cmd, "commands", None)
        if subs:
            for name, sub in subs.items():
                walk(sub, path + [name])
        else:
            out.append(path)
    walk(group, [])
    return out


COMMANDS = _commands()


def test_there_are_commands():
    assert len(COMMANDS) >= 17


@pytest.mark.parametrize("path", COMMANDS, ids=lambda p: " ".join(p))
def test_every_command_has_help_with_an_example(cli, path):
    r = cli(*path, "--help")
    assert r.exit_code == 0, r.output
    assert "Example" in r.output and "designkit " + path[0] in r.output.split("Example", 1)[1], \
        f"'designkit {' '.join(path)} --help' shows no example invocation"
