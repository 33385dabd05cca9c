"""The `cellmd` console script of the Python package: the same command line
as the executable built by `cargo install --path .` (`cellmd --help`)."""

import signal
import sys

from . import _native


def main() -> None:
    """Runs the command line with `sys.argv` and exits with its status."""
    # Ctrl-C stops the program as it stops the native executable (Python's
    # own handler would only set a flag that the engine never reads).
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    sys.stdout.flush()
    sys.exit(_native.cli_main(["cellmd", *sys.argv[1:]]))


if __name__ == "__main__":
    main()
