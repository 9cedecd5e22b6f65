"""The conventions of the ``palpate`` command line: ``python -m palpate``, ``--version``, help on
every option with its default and without docstring markup, a static command table whose
``--help`` imports no command module, diagnostics on stderr at the level ``-v``/``-q`` set."""

from __future__ import annotations

import ast
import importlib
import json
import subprocess
import sys
from importlib.metadata import version
from pathlib import Path

import pytest

from palpate.cli import COMMANDS, command_in, command_parser, main, plain_text

MARKUP = ("``", ":mod:", ":func:", ":class:", ":meth:", ":attr:", "**")


def _run(*argv: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, *argv], capture_output=True, text=True, timeout=120, check=False
    )


def test_python_dash_m_palpate_runs_the_console_script() -> None:
    done = _run("-m", "palpate", "--help")
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("usage: palpate ")
    for name in COMMANDS:
        assert name in done.stdout


def test_version_is_the_installed_one(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--version"]) == 0
    assert capsys.readouterr().out == f"palpate {version('palpate')}\n"


def _imported_by(argv: list[str], prefixes: tuple[str, ...]) -> list[str]:
    """The modules starting with one of ``prefixes`` that ``main(argv)`` leaves imported."""
    code = (
        "import sys\n"
        "from palpate.cli import main\n"
        f"assert main({argv!r}) == 0\n"
        f"print(sorted(m for m in sys.modules if m.startswith({prefixes!r})))\n"
    )
    done = _run("-c", code)
    assert done.returncode == 0, done.stderr
    modules: list[str] = ast.literal_eval(done.stdout.strip().splitlines()[-1])
    return modules


def test_top_level_help_imports_no_command_module() -> None:
    """The subcommand list comes from the static table: numpy, scipy, the configuration and
    every command's module stay unimported (``python -X importtime`` shows the cost)."""
    heavy = ("numpy", "scipy", "yaml", "matplotlib", "tqdm", "palpate.config")
    heavy += ("palpate.estimation", "palpate.robot", "palpate.sensor", "palpate.sim")
    heavy += ("palpate.wire", "palpate.commands", "config", "estimation", "robot", "sim")
    assert _imported_by(["--help"], heavy) == []


def test_a_subcommand_imports_only_its_own_module() -> None:
    commands = _imported_by(["calibrate", "--help"], ("palpate.commands.",))
    assert commands == ["palpate.commands.calibrate"]


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_the_static_summary_is_the_modules_first_line(name: str) -> None:
    module = importlib.import_module(COMMANDS[name].module)
    assert module.__doc__ is not None
    assert COMMANDS[name].summary == plain_text(module.__doc__).splitlines()[0]


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_every_option_has_help_and_shows_its_default(name: str) -> None:
    parser = command_parser(name)
    text = parser.format_help()
    for action in parser._actions:
        assert action.help, f"palpate {name} {action.option_strings or action.dest}: no help"
        takes_value = action.option_strings and action.nargs != 0
        if takes_value and action.default is not None:
            assert f"(default: {action.default})" in " ".join(text.split()), action.dest
    for mark in MARKUP:
        assert mark not in text, f"palpate {name} --help shows {mark!r}"


def test_plain_text_drops_the_markup() -> None:
    doc = "See :func:`~robot.teleop.render`, :mod:`robot.teleop` and ``x = 1``; **Safe stop**."
    assert plain_text(doc) == "See render, robot.teleop and x = 1; Safe stop."


def test_the_command_is_the_first_word_that_is_not_an_option() -> None:
    assert command_in(["-v", "sim", "--scene", "x"]) == "sim"
    assert command_in(["--version"]) is None
    assert command_in(["nosuch", "sim"]) is None


@pytest.mark.slow
def test_diagnostics_go_to_stderr_and_quiet_hides_them(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.setenv("PALPATE_FUZZ_SECONDS", "0.01")
    monkeypatch.setenv("PALPATE_FUZZ_INPUTS", "50")
    argv = ["bench", "--only", "fuzz", "--quick", "--json", "--out", str(tmp_path)]
    assert main(argv) == 0
    out, err = capsys.readouterr()
    assert err == "[bench] fuzz ...\n"  # the progress note; no progress bar off a terminal
    assert json.loads(out)["fuzz"]["summary"]["frame parser"]["failures"] == 0
    assert main(["-q", *argv]) == 0
    assert capsys.readouterr().err == ""
    assert main([*argv, "-q"]) == 0  # after the subcommand too
    assert capsys.readouterr().err == ""


def test_a_bad_input_is_one_line_on_stderr_and_exit_2(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["-q", "replay", "/nonexistent/trial.jsonl"]) == 2  # -q keeps errors
    out, err = capsys.readouterr()
    assert out == ""
    assert err.startswith("palpate: bad input: ")
    assert err.count("\n") == 1


def test_a_value_error_from_inside_the_code_is_an_internal_error_exit_1(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Only what the user gave is bad input: a ValueError raised inside the code is a bug, exit
    1 with ``internal error``, its traceback under -v (it was 'bad input', exit 2)."""
    import palpate.commands.replay as replay_command

    def broken(args: object) -> int:
        raise ValueError("lengths must be > 0 m")  # what the beam model raised inside export

    monkeypatch.setattr(replay_command, "run", broken)
    assert main(["replay", "any.jsonl"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("palpate: internal error (a bug; -v shows where): ValueError: lengths")
    assert "Traceback" not in err
    assert main(["-v", "replay", "any.jsonl"]) == 1
    err = capsys.readouterr().err
    assert "Traceback (most recent call last)" in err
    assert 'raise ValueError("lengths must be > 0 m")' in err
