"""``palpate`` console script: a static table of subcommands, each in its own module.

Exit codes (a stable interface): 0 success (every trial ended as planned), 1 a fault (a trial
faulted, hardware failed), 2 bad input (configuration, arguments, input files): see
:func:`report_failure` and ``docs/reliability.md``.

The table below names each subcommand's module and its one-line help, so ``palpate --help``
imports none of them (nor numpy, scipy, ...): a command's module is imported only when that
command runs or its own ``--help`` is asked. Results go to stdout; diagnostics (progress notes,
warnings, errors) go through :mod:`logging` to stderr, at the level ``-v`` / ``-q`` set.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import re
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from types import ModuleType
from typing import Any

from palpate.exitcodes import EXIT_BAD_INPUT, EXIT_FAULT, EXIT_OK

log = logging.getLogger("palpate")


@dataclass(frozen=True)
class Command:
    """A subcommand: its module (``register(parser)``, ``run(args) -> int``) and one-line help
    (the first line of the module's docstring; a test keeps them equal)."""

    module: str
    summary: str


COMMANDS: dict[str, Command] = {
    "sim": Command(
        "palpate.commands.sim",
        "Run a simulated campaign (the paper's robot or bench-top experiment): no hardware needed.",
    ),
    "study": Command(
        "palpate.commands.study",
        "Coverage study: N seeded repeats of a scene's campaign; error and interval coverage "
        "with bounds.",
    ),
    "map": Command(
        "palpate.commands.map",
        "Map a patch of a simulated sample probe by probe and find the stiff inclusion in it.",
    ),
    "bench": Command(
        "palpate.commands.bench",
        "Speed against error of the mechanics, the signal chain and the servo bus.",
    ),
    "replay": Command(
        "palpate.commands.replay",
        "Re-run the estimation on a recorded trial log and compare with what the trial reported.",
    ),
    "export": Command(
        "palpate.commands.export",
        "Convert trial logs to MCAP recordings that ROS 2 tools and Foxglove open.",
    ),
    "emulate": Command(
        "palpate.commands.emulate",
        "Start the Dynamixel bus and board emulators on pseudo-terminals and print their paths.",
    ),
    "calibrate": Command(
        "palpate.commands.calibrate",
        "Calibrate what the paper could not: k'_eps, and the tube's or stage's compliance.",
    ),
    "design": Command(
        "palpate.commands.design",
        "Design a sensor for a tissue modulus range, then try it on simulated phantoms across "
        "the range.",
    ),
    "trial": Command(
        "palpate.commands.trial",
        "Run scripted indentation trials on the real bench: ports, stored poses and protocol "
        "from a YAML.",
    ),
    "teleop": Command(
        "palpate.commands.teleop",
        "Jog roll, advance and tube from the keyboard; live pose, strains and flags; store poses.",
    ),
    "ros": Command(
        "palpate.commands.ros",
        "Serve the stack as a ROS 2 node: trials and surveys on request, their topics as they run.",
    ),
}


# -- help text -----------------------------------------------------------------------------------

_ROLE = re.compile(r":(?:mod|func|class|meth|attr|data|obj|exc):`(~?)([^`]+)`")
_LITERAL = re.compile(r"``([^`]+)``")
_STRONG = re.compile(r"\*\*([^*]+)\*\*")


def plain_text(doc: str) -> str:
    """A docstring without its reStructuredText markup, as ``--help`` shows it:
    ``:func:`~a.b``` -> ``b``, ``:mod:`a.b``` -> ``a.b``, double backquotes and ``**`` dropped."""

    def role(m: re.Match[str]) -> str:
        target = m.group(2)
        return target.rsplit(".", 1)[-1] if m.group(1) else target

    text = _ROLE.sub(role, doc)
    text = _LITERAL.sub(r"\1", text)
    return _STRONG.sub(r"\1", text).strip()


class HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """Descriptions keep their paragraphs; every option that takes a value shows its default
    (unless it has none or its help already says it)."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        default = action.default
        if (
            "%(default)" in text
            or default is None
            or default is False
            or default is argparse.SUPPRESS
            or action.nargs == 0  # a flag or a counter: its help says what it does
            or (not action.option_strings and action.nargs not in ("?", "*"))
        ):
            return text
        return f"{text} (default: %(default)s)"


class _VersionAction(argparse.Action):
    """``--version``: the installed distribution's version (read only when asked)."""

    def __init__(self, option_strings: Sequence[str], dest: str, **kwargs: Any) -> None:
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, **kwargs)

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: Any,
        option_string: str | None = None,
    ) -> None:
        from importlib.metadata import PackageNotFoundError, version

        try:
            text = version("palpate")
        except PackageNotFoundError:
            text = "unknown (not installed)"
        print(f"palpate {text}")
        parser.exit()


# -- the parser ----------------------------------------------------------------------------------


def _add_verbosity(parser: argparse.ArgumentParser, default: Any) -> None:
    """``-v``/``-q`` (repeatable); the subcommands accept them too (``default`` SUPPRESS there,
    so they do not reset what was given before the subcommand)."""
    parser.add_argument(
        "-v", "--verbose", action="count", default=default, help="more diagnostics on stderr"
    )
    parser.add_argument(
        "-q",
        "--quiet",
        action="count",
        default=default,
        help="fewer diagnostics on stderr (-q: warnings and errors, -qq: errors only)",
    )


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The ``palpate`` parser; only ``command``'s module is imported and its options added."""
    return _build(command)[0]


def command_parser(name: str) -> argparse.ArgumentParser:
    """The parser of one subcommand, with its options (for tests and documentation)."""
    return _build(name)[1][name]


def _build(
    command: str | None,
) -> tuple[argparse.ArgumentParser, dict[str, argparse.ArgumentParser]]:
    parser = argparse.ArgumentParser(
        prog="palpate",
        description="Tissue palpation with a buckling FBG-sensorized beam: "
        "simulator and control stack.",
        formatter_class=HelpFormatter,
    )
    parser.add_argument(
        "--version", action=_VersionAction, help="print the installed version and exit"
    )
    _add_verbosity(parser, 0)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    commands = {}
    for name, spec in COMMANDS.items():
        cmd = sub.add_parser(
            name, help=spec.summary, description=spec.summary, formatter_class=HelpFormatter
        )
        if name == command:
            _register(cmd, importlib.import_module(spec.module))
        commands[name] = cmd
    return parser, commands


def _register(cmd: argparse.ArgumentParser, module: ModuleType) -> None:
    cmd.description = plain_text(module.__doc__ or "")
    cmd.add_argument("--json", action="store_true", help="print machine-readable results on stdout")
    _add_verbosity(cmd, argparse.SUPPRESS)
    module.register(cmd)
    cmd.set_defaults(_module=module)


def command_in(argv: Sequence[str]) -> str | None:
    """The subcommand ``argv`` names: its first word that is not an option (the global options
    take no value), if it is a known command."""
    for arg in argv:
        if arg == "--":
            return None
        if not arg.startswith("-"):
            return arg if arg in COMMANDS else None
    return None


# -- diagnostics ---------------------------------------------------------------------------------


class _StderrHandler(logging.Handler):
    """Writes each record to whatever ``sys.stderr`` is when it is emitted (a redirect, pytest)."""

    def emit(self, record: logging.LogRecord) -> None:
        try:
            sys.stderr.write(self.format(record) + "\n")
            sys.stderr.flush()
        except Exception:  # logging's own contract: report, never raise
            self.handleError(record)


def configure_logging(verbose: int = 0, quiet: int = 0) -> None:
    """INFO by default (progress notes), DEBUG with ``-v``, WARNING with ``-q``, ERROR with
    ``-qq``; records print as their bare message on stderr."""
    level = min(max(logging.INFO + 10 * (quiet - verbose), logging.DEBUG), logging.CRITICAL)
    for handler in [h for h in log.handlers if isinstance(h, _StderrHandler)]:
        log.removeHandler(handler)
    handler = _StderrHandler()
    handler.setFormatter(logging.Formatter("%(message)s"))
    log.addHandler(handler)
    log.setLevel(level)


def main(argv: Sequence[str] | None = None) -> int:
    words = list(sys.argv[1:] if argv is None else argv)
    try:
        args = build_parser(command_in(words)).parse_args(words)
        if not hasattr(args, "_module"):  # the command was not where command_in looked
            args = build_parser(args.command).parse_args(words)
    except SystemExit as exc:  # argparse exits 2 on bad arguments, 0 on --help
        return int(exc.code or 0)
    configure_logging(args.verbose, args.quiet)
    try:
        return int(args._module.run(args) or EXIT_OK)
    except KeyboardInterrupt:
        log.error("palpate: interrupted")
        return EXIT_FAULT
    except Exception as exc:  # the one mapping of errors to messages and exit codes
        return report_failure(exc)


def report_failure(exc: Exception) -> int:
    """One line on stderr and the exit code for an error that ended a command:

    - bad input, exit 2: a configuration error (file and key), an
      :class:`~config.loader.InputError` (the commands raise it at their boundary naming the
      file and key or line, or the option; a trial log that fails its schema), and a file that
      cannot be read or written (an ``OSError`` that names a file: missing, a directory, no
      permission);
    - anything else is a fault, exit 1: a hardware error the command did not handle, or a bug
      (``internal error``; ``-v`` shows the traceback), a ``ValueError`` from inside the code
      among them. No input a user can give should get here: the fuzz targets (``palpate bench
      --only fuzz``) check that."""
    from palpate.config.loader import ConfigError, InputError

    if isinstance(exc, ConfigError):
        log.error("palpate: bad configuration: %s", exc)
        return EXIT_BAD_INPUT
    if isinstance(exc, InputError):
        log.error("palpate: bad input: %s", exc)
        return EXIT_BAD_INPUT
    if isinstance(exc, OSError) and exc.filename is not None:
        log.error("palpate: bad input: %s: %s", exc.filename, exc.strerror or exc)
        return EXIT_BAD_INPUT
    if isinstance(exc, OSError):
        log.error("palpate: fault: %s", exc)
        return EXIT_FAULT
    log.error("palpate: internal error (a bug; -v shows where): %s: %s", type(exc).__name__, exc)
    log.debug("traceback of the internal error", exc_info=exc)
    return EXIT_FAULT


if __name__ == "__main__":
    sys.exit(main())
