"""Subcommands of ``palpate``; each module has ``register(parser)`` and ``run(args) -> int``."""
