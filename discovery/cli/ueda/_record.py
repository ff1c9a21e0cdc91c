"""Options and outputs of the ``vidi ueda`` subcommands that read a record ``t, x``
(discover, explain): the weak-form fit, the verification by simulation, the strobe
points written as CSV, the coefficients printed."""

import numpy as np

from .. import _options
from .._common import integer, number

RECORD_HELP = "CSV with columns t (uniform) and x"


def add_noise_option(s):
    """``--noise``: the record's known noise (default: estimated)."""
    s.add_argument(
        "--noise",
        type=number(0, 1),
        help="known noise sd as a fraction of x's "
        "range (default: estimated from the smoothing residual)",
    )


def add_weak_form_options(s):
    """``--half-width`` of the test windows and ``--fix-forcing``."""
    s.add_argument(
        "--half-width",
        type=integer(2, 10**4),
        help="test-window half width in samples (default: a quarter period, at least 7)",
    )
    s.add_argument(
        "--fix-forcing",
        action="store_true",
        help="fix the forcing's coefficient at 1 instead of fitting it",
    )


def add_verification_options(s, models):
    """The simulation of ``models`` ("the discovered model", "each model") against the
    record: ``--model-periods``, ``--transient``, ``--resamples``, ``--seed``."""
    s.add_argument(
        "--model-periods",
        type=integer(50, 10**6),
        default=2000,
        help=f"periods of {models} simulated (default: %(default)s)",
    )
    s.add_argument(
        "--transient",
        type=integer(0, 10**6),
        default=200,
        help=f"periods of {models} discarded first (default: %(default)s)",
    )
    s.add_argument(
        "--resamples",
        type=integer(10, 10**5),
        default=200,
        help="random halves for the energy-distance noise floor (default: %(default)s)",
    )
    _options.add_seed_option(s, "seed of the resampling", most=None)


def write_strobe(path, points):
    """Strobe points, ndarray of shape (n, 2), as a CSV with the header ``x,v``."""
    np.savetxt(path, points, delimiter=",", header="x,v", comments="")


def print_coefficients(res):
    """One line per coefficient of ``res`` with its standard error."""
    for k, c in res.coefficients.items():
        print(f"  {k:>12}: {c: .5f} +- {res.standard_errors[k]:.5f}")
