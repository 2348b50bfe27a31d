"""The parser of one command line: only the invoked command's module is imported, and its
options are those of the parser of every command (``tmfem --help``, the CLI reference)."""
import subprocess
import sys

import pytest

from tmfem.cli import build_parser, subcommands

COMMANDS = sorted(subcommands())


def _options(parser, command):
    """{option strings: (dest, default)} of ``command``'s subparser in ``parser``."""
    sub = next(a for a in parser._actions if a.dest == "command").choices[command]
    return {tuple(a.option_strings): (a.dest, repr(a.default)) for a in sub._actions}


@pytest.mark.parametrize("command", COMMANDS)
def test_one_commands_parser_has_the_options_of_the_full_parser(command):
    one = build_parser(subcommands()[command])
    assert _options(one, command) == _options(build_parser(), command)


def test_a_run_imports_only_its_own_command():
    """``tmfem presets`` in a fresh interpreter: no other command's module is imported."""
    code = ("import sys; from tmfem.cli import main; main(['presets', '--quiet']); "
            "print(sorted(m for m in sys.modules if m.startswith('tmfem.cli.')), file=sys.stderr)")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    loaded = eval(p.stderr.strip().splitlines()[-1])
    assert [m for m in loaded if m.split(".")[-1] in COMMANDS] == ["tmfem.cli.presets"]


def test_an_unknown_command_lists_every_command(capsys):
    from tmfem.cli import main
    with pytest.raises(SystemExit) as e:
        main(["stati"])
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert "invalid choice: 'stati'" in err and all(f"'{c}'" in err for c in COMMANDS)
