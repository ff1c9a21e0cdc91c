"""``vidi``: a thin command line over the :mod:`discovery` API.

One module per command (``simulate``, ``fit``, ``verify``, ``steady``, ``landscape``,
``identify``), each with ``register(subparsers)`` and ``run(args)``.  Every command
writes ``summary.json`` (results, versions, settings) beside its other outputs;
outputs are staged and moved in only when the command succeeds.  Bad input gives one
line on stderr and exit code 2.
"""

import argparse
import sys

from ..errors import VidiError
from . import fit, identify, landscape, simulate, steady, verify

__all__ = ["main"]

_COMMANDS = (simulate, fit, verify, steady, landscape, identify)


def _parser():
    p = argparse.ArgumentParser(
        prog="vidi",
        description="Discover and verify contact-force laws F(zeta, dzeta) of vibro-impact "
                    "machines by simulation.")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for cmd in _COMMANDS:
        cmd.register(sub)
    return p


def main(argv=None):
    """Run ``vidi``; returns the exit code (0 ok, 2 bad input or failed numerics)."""
    args = _parser().parse_args(argv)
    try:
        return args.func(args)
    except VidiError as exc:
        print(f"vidi: error: {exc}", file=sys.stderr)
        return 2
    except ValueError as exc:  # certificate/validation errors from the packages
        print(f"vidi: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # output piped into e.g. `head`: stop quietly
        sys.stderr.close()
        return 0


if __name__ == "__main__":
    sys.exit(main())
