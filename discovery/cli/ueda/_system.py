"""Options and objects the ``vidi ueda`` subcommands share: the model and its
parameters, the forcing, the initial state, the tolerances."""

from ...errors import InputError
from .._common import number

_PARAMS = ("mu", "gamma", "k", "B", "nu")


def _system(args, **fixed):
    from ...ueda import UedaSystem

    over = {p: getattr(args, p, None) for p in _PARAMS}
    over.update(fixed)
    return UedaSystem.from_model(args.model, **over)


def _tolerances(args):
    from ...numerics.tolerances import Tolerances

    return Tolerances(rtol=args.rtol)


def _models_default(param):
    """`` (default: the --model's: negres 8, duffing 0)``: a parameter's value in each
    built-in model, for an option whose default is the model's."""
    from ...ueda.system import MODELS

    values = ", ".join(f"{m} {v[param]:g}" for m, v in MODELS.items())
    return f" (default: the --model's: {values})"


def _add_system_options(s, chart=False):
    s.add_argument(
        "--model",
        choices=("negres", "duffing"),
        default="negres",
        help="negres: x'' - mu (1 - gamma x^2) x' + x^3 = B cos(nu t) (mu 0.2, "
        "gamma 8, B 0.35, nu 1.02: the broken egg); duffing: x'' + k x' + x^3 = "
        "B cos(nu t) (k 0.05, B 7.5, nu 1) (default: %(default)s)",
    )
    s.add_argument("--mu", type=number(-10, 10), help="negative resistance" + _models_default("mu"))
    s.add_argument(
        "--gamma",
        type=number(0, 1e3),
        help="amplitude dependence of the resistance, >= 0" + _models_default("gamma"),
    )
    s.add_argument("--k", type=number(-10, 10), help="linear damping" + _models_default("k"))
    if not chart:
        _add_forcing_values(s)
    s.add_argument(
        "--rtol",
        type=number(1e-13, 1e-3),
        default=1e-9 if not chart else 1e-6,
        help="integrator tolerance (default: %(default)g)",
    )


def _add_forcing_values(s):
    """``--B`` and ``--nu``: the forcing B cos(nu t) (default: the model's)."""
    s.add_argument("--B", type=number(-1e3, 1e3), help="forcing amplitude" + _models_default("B"))
    s.add_argument(
        "--nu",
        type=number(0.01, 100),
        help="forcing angular frequency, 0.01-100 (a period of 2 pi / nu time units)"
        + _models_default("nu"),
    )


def _add_forcing_options(s):
    """``--model`` (no default) for its forcing, ``--B`` and ``--nu`` (see :func:`_forcing`)."""
    s.add_argument(
        "--model",
        choices=("negres", "duffing"),
        help="take the forcing B, nu from this model (override with --B, --nu; no "
        "default: give --model, or --B and --nu)",
    )
    _add_forcing_values(s)


def _add_start_options(s):
    """``--x0`` and ``--v0``: the initial state."""
    s.add_argument(
        "--x0", type=number(-1e3, 1e3), default=0.1, help="initial x (default: %(default)g)"
    )
    s.add_argument(
        "--v0", type=number(-1e3, 1e3), default=0.0, help="initial x' (default: %(default)g)"
    )


def _forcing(args):
    from ...ueda import MODELS

    if args.model is None and (args.B is None or args.nu is None):
        raise InputError(
            "give the forcing: --B and --nu (e.g. --B 0.35 --nu 1.02), or --model "
            "negres|duffing for its forcing"
        )
    base = MODELS[args.model] if args.model else {}
    B = args.B if args.B is not None else base["B"]
    nu = args.nu if args.nu is not None else base["nu"]
    return B, nu
