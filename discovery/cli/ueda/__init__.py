"""``vidi ueda``: Ueda's forced oscillators (the second system).

``vidi ueda attractor`` - one attractor: strobe points, the two Lyapunov exponents with
standard errors, the regime with its evidence, figures (optionally the coexisting
attractors from a grid of initial states).  ``vidi ueda chart`` - the regime chart over
``(nu, B)`` in parallel processes.  ``vidi ueda simulate`` - a noisy record ``t, x`` (CSV)
of a model.  ``vidi ueda discover`` - the equation recovered from a record with known
forcing (weak-form sparse regression, bootstrap standard errors), verified by simulation
against the record's attractor (energy distance of strobe points against a noise floor,
Lyapunov exponent, regime).  ``vidi ueda explain`` - the missing-effect workflow: from a
start model (default negres without its van der Pol damping), name the missing effect of
this system's catalogue by score tests, add it, refit, and show the gap shrink.
"""

from . import attractor, chart, discover, explain, simulate


def register(sub):
    """Add ``vidi ueda`` and its subcommands to the command subparsers ``sub``."""
    u = sub.add_parser(
        "ueda",
        help="Ueda's forced oscillators: attractors, Lyapunov exponents, regime charts, "
        "synthetic records, equation discovery, missing effects",
    )
    usub = u.add_subparsers(
        dest="ueda_command", required=True, metavar="SUBCOMMAND", parser_class=type(u)
    )
    for module in (attractor, chart, simulate, discover, explain):
        module.register(usub)
