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
            if path and cmd.invoke_without_command:   # a group that runs on its own (the guided calibrate)
                out.append(path)
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


def test_the_console_script_knows_which_module_registers_each_command():
    """``designkit NAME`` imports only NAME's module: the map (and, for a command another package adds, its
    entry point) must name every top-level command, and right."""
    from importlib.metadata import entry_points

    import designkit.cli as cli_pkg

    app = cli_pkg.app
    registered = {}
    for c in app.registered_commands:
        registered[c.name or c.callback.__name__.replace("_", "-")] = c.callback.__module__
    for g in app.registered_groups:
        registered[g.name] = g.typer_instance.registered_commands[0].callback.__module__
    added = {ep.name: ep.value for ep in entry_points(group=cli_pkg.ENTRY_POINT_GROUP)}
    assert not set(added) & set(cli_pkg.COMMAND_MODULE)
    assert set(cli_pkg.COMMAND_MODULE) | set(added) == set(registered)
    for name, module in registered.items():
        assert module == added.get(name, f"designkit.cli.{cli_pkg.COMMAND_MODULE.get(name)}"), name
    assert set(cli_pkg.COMMAND_MODULE.values()) == set(cli_pkg.COMMAND_MODULES)


def test_a_command_runs_with_only_its_own_module_imported():
    import subprocess
    import sys

    code = ("import sys; sys.argv = ['designkit', 'materials', 'list', '--format', 'csv']\n"
            "from designkit.cli import main\n"
            "try:\n    main()\nexcept SystemExit as e:\n    assert e.code in (0, None), e.code\n"
            "print('LOADED', sorted(m.rsplit('.', 1)[1] for m in sys.modules if m.startswith('designkit.cli.')"
            " and not m.split('.')[-1].startswith('_')), file=sys.stderr)\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith("name,family")
    assert "LOADED ['materials']" in r.stderr


def test_the_table_options_name_the_query_layers_default_table():
    """The CLI's --table help spells the default out (it must not import the query layer to say it)."""
    import typer.main

    from designkit.cli import app
    from designkit.query.table import DEFAULT_TABLE

    group = typer.main.get_command(app)
    for name in ("min-contact", "max-noise", "min-delta-t", "delta-e", "distinguishable", "matrix"):
        opt = [p for p in group.commands[name].params if "--table" in getattr(p, "opts", ())]
        assert opt and f"(default: {DEFAULT_TABLE})" in opt[0].help, name
