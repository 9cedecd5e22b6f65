"""``palpate`` console script: a registry of subcommands, each in its own module.

Exit codes (a stable interface): 0 success, 2 bad input (configuration, arguments), 1 a fault.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from config.loader import ConfigError

# Subcommand name -> module in palpate.commands exposing ``register(parser)`` and ``run(args)``.
COMMANDS: dict[str, str] = {
    "sim": "palpate.commands.sim",
    "bench": "palpate.commands.bench",
    "replay": "palpate.commands.replay",
    "emulate": "palpate.commands.emulate",
    "calibrate": "palpate.commands.calibrate",
    "design": "palpate.commands.design",
    "trial": "palpate.commands.trial",
    "teleop": "palpate.commands.teleop",
}

EXIT_OK = 0
EXIT_FAULT = 1
EXIT_BAD_INPUT = 2


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="palpate",
        description="Tissue palpation with a buckling FBG-sensorized beam: "
        "simulator and control stack.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name, module_name in COMMANDS.items():
        module = importlib.import_module(module_name)
        doc = (module.__doc__ or "").strip().splitlines()[0] if module.__doc__ else ""
        cmd = sub.add_parser(name, help=doc, description=module.__doc__)
        cmd.add_argument(
            "--json", action="store_true", help="print machine-readable results on stdout"
        )
        module.register(cmd)
        cmd.set_defaults(_module=module)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse exits 2 on bad arguments, 0 on --help
        return int(exc.code or 0)
    try:
        return int(args._module.run(args) or EXIT_OK)
    except ConfigError as exc:
        print(f"palpate: bad configuration: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except (ValueError, FileNotFoundError) as exc:
        print(f"palpate: bad input: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print("palpate: interrupted", file=sys.stderr)
        return EXIT_FAULT


if __name__ == "__main__":
    sys.exit(main())
