"""Every numeric option of every command refuses a bad value with exit 2 and a line naming the
option, never an internal error: a table of each option's accepted values among a negative
number, zero, NaN, infinity, an overflowing number and text, tried through ``palpate.cli.main``.

A new numeric option must be given an ``argtypes`` type (a bare ``int`` or ``float`` lets NaN,
inf or a negative count through to a traceback) and a row here."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

from palpate.cli import COMMANDS, command_parser, main

BAD = ("-10", "0", "nan", "inf", "1e400", "text")

# The values of BAD each numeric option accepts (a seed of 0, a half-space's thickness of inf).
ACCEPTS: dict[tuple[str, str], frozenset[str]] = {
    ("sim", "--seed"): frozenset({"0"}),
    ("sim", "--workers"): frozenset(),
    ("sim", "--limit"): frozenset(),
    ("sim", "--live"): frozenset({"0"}),
    ("study", "--repeats"): frozenset(),
    ("study", "--seed"): frozenset({"0"}),
    ("study", "--workers"): frozenset(),
    ("map", "--max-probes"): frozenset(),
    ("map", "--seed"): frozenset({"0"}),
    ("map", "--live"): frozenset({"0"}),
    ("map", "--worlds"): frozenset(),
    ("map", "--plans"): frozenset(),
    ("map", "--workers"): frozenset(),
    ("map", "--tilt-deg"): frozenset({"0"}),
    ("map", "--through"): frozenset(),
    ("bench", "--seed"): frozenset({"0"}),
    ("emulate", "--seed"): frozenset({"0"}),
    ("emulate", "--seconds"): frozenset(),
    ("calibrate", "--confidence"): frozenset(),
    ("calibrate", "--exposed-length-mm"): frozenset(),
    ("calibrate", "--rest-frames"): frozenset(),
    ("design", "--modulus-range"): frozenset(),
    ("design", "--poisson"): frozenset({"0"}),
    ("design", "--thickness-mm"): frozenset({"inf", "1e400"}),
    ("design", "--imperfection"): frozenset({"0"}),
    ("design", "--max-depth-ratio"): frozenset(),
    ("design", "--resolution-multiple"): frozenset(),
    ("design", "--fiber-radii-um"): frozenset(),
    ("design", "--wire-diameters-um"): frozenset(),
    ("design", "--wire-counts"): frozenset({"0"}),
    ("design", "--tip-radii-mm"): frozenset(),
    ("design", "--lumen-mm"): frozenset(),
    ("design", "--clearance-mm"): frozenset({"0"}),
    ("design", "--tip-resolution-mn"): frozenset(),
    ("design", "--length-range-mm"): frozenset(),
    ("design", "--moduli"): frozenset(),
    ("design", "--lengths"): frozenset(),
    ("design", "--contact-uncertainty-mm"): frozenset({"0"}),
    ("design", "--seed"): frozenset({"0"}),
    ("design", "--workers"): frozenset(),
    ("design", "--tolerance-pct"): frozenset(),
    ("design", "--tip-mass-g"): frozenset({"0"}),
    ("trial", "--live"): frozenset({"0"}),
    ("teleop", "--rate"): frozenset(),
    ("teleop", "--live"): frozenset({"0"}),
    ("ros", "--seed"): frozenset({"0"}),
    ("ros", "--rate"): frozenset(),
    ("ros", "--pace"): frozenset(),
}

# What each command needs besides the option under test, so only that option can be wrong.
REQUIRED: dict[str, list[str]] = {
    "replay": ["log.jsonl"],
    "export": ["log.jsonl"],
    "calibrate": ["frames.jsonl"],
    "design": ["--modulus-range", "1:20"],
}

NOT_NUMERIC = (None, Path, str)
LOOKS_NUMERIC = re.compile(r"[-+0-9.eE,:\s]+")


def _options(command: str) -> list[argparse.Action]:
    parser = command_parser(command)
    return [a for a in parser._actions if a.option_strings and a.nargs != 0]


def _numeric(action: argparse.Action) -> bool:
    return action.type not in NOT_NUMERIC and action.choices is None


def test_every_numeric_option_of_every_command_is_in_the_table() -> None:
    found = {(c, a.option_strings[-1]) for c in COMMANDS for a in _options(c) if _numeric(a)}
    assert found == set(ACCEPTS)


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_no_option_takes_a_bare_number_or_numbers_as_text(command: str) -> None:
    for action in _options(command):
        flag = action.option_strings[-1]
        assert action.type not in (int, float), f"{command} {flag}: use an argtypes type"
        if action.type is None and isinstance(action.default, str):
            assert not LOOKS_NUMERIC.fullmatch(action.default), f"{command} {flag}: untyped"


@pytest.mark.parametrize(("command", "flag"), sorted(ACCEPTS))
def test_a_bad_value_is_exit_2_naming_the_option(
    command: str, flag: str, capsys: pytest.CaptureFixture[str]
) -> None:
    for value in BAD:
        argv = [command, *REQUIRED.get(command, []), flag, value]
        if value in ACCEPTS[command, flag]:
            command_parser(command).parse_args(argv[1:])  # accepted: parses
            continue
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert f"argument {flag}" in err, (argv, err)
        assert "internal error" not in err


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_a_help_text_states_each_default_once(command: str) -> None:
    text = " ".join(command_parser(command).format_help().split())
    assert not re.search(r"\(default\b[^()]*\) \(default", text), text
