"""The options several commands share, each added by one ``add_..._option(parser, ...)``.

Where commands give an option the same meaning, its type, range, default and help are
written here once; the parameters carry what differs between commands (what a seed
seeds, what a budget is spent on), so every ``--help`` reads as the command's own.  The
help of an option with a default ends ``(default: %(default)s)`` (see
``tests/cli/test_cli_help.py``).
"""

from ..vibroimpact.model.scenario import builtin_scenarios
from ..vibroimpact.verify.criteria import CRITERIA
from ._common import integer, interval_count, number

SCENARIO_HELP = (
    f"built-in scenario ({', '.join(builtin_scenarios())}) or a TOML file (default: paper)"
)
LAW_HELP = (
    "force law in z = zeta (penetration w1 - w2, m) and zd = dzeta (its rate while "
    "loading, m/s), e.g. '2.06e8*z + 1.28e7*zd' (default: the scenario's law); a law "
    "starting with '-' as --law=-1e8*z; or a named contact model, e.g. 'hunt-crossley: "
    "k=2e9, n=1.5, lambda=3e9', 'flores: k=2e9, n=1.5, e=0.6', 'kelvin-voigt: k=2e8, c=1e6'"
)
MEASURED_HELP = (
    "CSV with t [s], F [N] (w1, v1, w2, v2 recommended: exact onsets and the machine's state)"
)
SCHEDULER_HELP = (
    "run on Dask: 'local' starts a LocalCluster of single-threaded workers, "
    "tcp://host:port joins a running scheduler (its workers started with "
    "--nthreads 1); needs pip install 'vibroimpact-discovery[dask]'"
)
#: the largest ``--seed`` of the commands whose seed goes to numpy's generators
SEED_MAX = 2**32 - 1


# ------------------------------------------------------------------ inputs
def add_scenario_option(parser, *, repeat=False, help_suffix=""):
    """``--scenario``: a built-in name or a TOML file (default paper); with ``repeat``
    given once per ``--data`` (the list is read by :func:`._common.read_records`)."""
    if not repeat:
        return parser.add_argument("--scenario", default="paper", help=SCENARIO_HELP)
    return parser.add_argument(
        "--scenario",
        action="append",
        help=SCENARIO_HELP + "; repeat it, once per --data in the same order" + help_suffix,
    )


def add_law_option(parser):
    """``--law``: a law's text or a named contact model (default: the scenario's law)."""
    return parser.add_argument("--law", help=LAW_HELP)


def add_data_option(parser, help=MEASURED_HELP, *, repeat=False):
    """``--data`` (required): the record, or with ``repeat`` the records fitted jointly."""
    if repeat:
        return parser.add_argument("--data", required=True, action="append", help=help)
    return parser.add_argument("--data", required=True, help=help)


def add_time_offset_option(parser, *, needs=None, help_prefix=""):
    """``--time-offset``: the drive-clock time [s] of the record's ``t = 0`` (default 0)."""
    return parser.add_argument(
        "--time-offset",
        type=number(-1e7, 1e7, unit="s"),
        default=0.0,
        needs=needs,
        help=f"{help_prefix}drive-clock time [s] of the record's t = 0, when the record does "
        "not start at drive phase 0 (default: %(default)g)",
    )


# ------------------------------------------------------------------ the checks by simulation
def add_criterion_option(parser, what):
    """``--criterion``: one of the criteria I0..I5 (default I2); ``what`` it is used for."""
    return parser.add_argument(
        "--criterion",
        default="I2",
        choices=list(CRITERIA),
        help=f"{what} (default: %(default)s)",
    )


def add_n_boot_option(parser, *, of="the noise floor", help_prefix="", help_suffix="", needs=None):
    """``--n-boot``: bootstrap replicates of ``of`` (a noise floor; default 16)."""
    return parser.add_argument(
        "--n-boot",
        type=integer(1, 10_000),
        default=16,
        needs=needs,
        help=f"{help_prefix}bootstrap replicates of {of}{help_suffix} (default: %(default)s)",
    )


def add_max_simulations_option(parser, *, least, most, default, of="", default_help=None, **kw):
    """``--max-simulations``: the simulation budget (of ``of``), an integer in
    ``[least, most]``; ``default_help`` replaces ``default: %(default)s`` in the help
    where the default depends on other options (``kw``: e.g. ``excludes``)."""
    return parser.add_argument(
        "--max-simulations",
        type=integer(least, most),
        default=default,
        help=f"simulation budget{of} ({default_help or 'default: %(default)s'})",
        **kw,
    )


def add_seed_option(parser, what, *, most=SEED_MAX, needs=None):
    """``--seed``: an integer >= 0 (at most ``most``; None: no bound), default 0; ``what``
    is its help before the default."""
    return parser.add_argument(
        "--seed",
        type=integer(0, most),
        default=0,
        needs=needs,
        help=f"{what} (default: %(default)s)",
    )


# ------------------------------------------------------------------ coefficient intervals
def add_intervals_option(parser, of, note="0 = none"):
    """``--intervals``: bootstrap replicates of ``of`` (intervals, e.g. "the 95 %
    coefficient intervals") through the full processing; 0 or at least 5, default 30."""
    return parser.add_argument(
        "--intervals",
        type=interval_count,
        default=30,
        help=f"bootstrap replicates of {of.replace('%', '%%')} through the full processing "
        f"({note}) (default: %(default)s)",
    )


def add_interval_refit_option(parser):
    """``--interval-refit``: how each bootstrap replicate of the intervals is refitted."""
    return parser.add_argument(
        "--interval-refit",
        choices=("two-step", "full"),  # identify.INTERVAL_REFITS (not imported: --help stays fast)
        default="two-step",
        help="how each bootstrap replicate is refitted: two Gauss-Newton steps from the fit "
        "with exact Jacobians, or a full least-squares refit (about 3x the time) "
        "(default: %(default)s)",
    )


# ------------------------------------------------------------------ the missing-effect loop
def add_effect_search_options(parser, *, alpha_most, alpha_help, max_iterations):
    """``--alpha`` (the score tests' family-wise level in ``(0, alpha_most]``, default
    0.01, ``alpha_help`` before the default) and ``--max-iterations`` (effects added at
    most, ``[0, max_iterations]``, default 3) of an explain command."""
    parser.add_argument(
        "--alpha",
        type=number(0.0, alpha_most, lo_open=True),
        default=0.01,
        help=f"{alpha_help} (default: %(default)g)",
    )
    parser.add_argument(
        "--max-iterations",
        type=integer(0, max_iterations),
        default=3,
        help="effects added at most (default: %(default)s)",
    )


def add_sensor_lag_option(parser):
    """``--sensor-lag SECONDS``: the force sensor's time constant (read with
    :func:`._common.sensor_lag_of`)."""
    return parser.add_argument(
        "--sensor-lag",
        type=number(0.0, 5e-3, unit="s"),
        default=None,
        metavar="SECONDS",
        help="the force sensor's time constant: the simulated force is compared as the "
        "sensor sees it (default: the calibration's, when it finds one; 0: none)",
    )


# ------------------------------------------------------------------ processes and outputs
def add_workers_option(parser, what=None):
    """``--workers N``: processes (for ``what``; default: every core)."""
    if what is None:
        return parser.add_argument(
            "--workers", type=integer(1, 1024), help="processes (default: all cores)"
        )
    return parser.add_argument(
        "--workers",
        type=integer(1, 1024),
        help=f"processes for {what} (default: all cores; the result does not depend on it)",
    )


def add_scheduler_option(parser):
    """``--scheduler ADDR``: run on Dask (:func:`._common.executor_of`)."""
    return parser.add_argument("--scheduler", metavar="ADDR", help=SCHEDULER_HELP)


def add_parallel_options(parser, what=None):
    """``--workers`` (see :func:`add_workers_option`) and ``--scheduler``."""
    add_workers_option(parser, what)
    add_scheduler_option(parser)


def add_out_option(parser, help="output directory"):
    """``--out`` (required): where the results go (``help``: a directory by default)."""
    return parser.add_argument("--out", required=True, help=help)
