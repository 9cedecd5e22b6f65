"""The command line's exit codes (docs/reliability.md): 0 done, 1 a trial or check did not end
as planned (or an internal error), 2 bad input (the file and key named)."""

EXIT_OK = 0
EXIT_FAULT = 1
EXIT_BAD_INPUT = 2
