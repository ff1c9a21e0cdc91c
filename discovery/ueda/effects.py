"""The catalogue of named physical effects of Ueda's forced oscillators: each a candidate
"omitted variable" of the equation ``x'' = sum_j c_j x^i x'^j + B cos(nu t)``.

The same mechanism as the vibro-impact catalogue (:mod:`discovery.vibroimpact.explain.effects`,
whose
:class:`~discovery.vibroimpact.explain.effects.Effect` and
:class:`~discovery.vibroimpact.explain.effects.Parameter`
are reused): an effect adds terms of the polynomial library (:data:`TERMS` of
:mod:`discovery.ueda.polynomial`) to a :class:`ForcedPolynomial`; its parameter is the
coefficient in the ``x'' = ...`` form, with physical bounds (a sign).  Nothing
effect-specific enters the integrator.

``phases`` (impact phases in the vibro-impact catalogue) are empty here: this system has no
impacts, and where an effect acts in the ``(x, x')`` plane is said in ``signature``.
"""

import numpy as np

from ..catalogue import Effect, Parameter, lookup
from .polynomial import TERMS

__all__ = ["EFFECTS", "effect", "effect_dict", "in_bounds"]

_INF = np.inf

EFFECTS = (
    Effect(
        id="van_der_pol_damping",
        title="Amplitude-dependent (van der Pol) damping",
        explanation="The resistance depends on the amplitude: negative (energy fed in) at "
        "small |x|, positive (energy taken out) at large |x|, as in a vacuum-tube "
        "or tunnel-diode oscillator, mu (1 - gamma x^2) x'. The x^2 x' part is what "
        "limits the self-excited growth: without it a negative linear resistance "
        "makes the oscillation grow without bound.",
        enters="a term c x^2 x' in x'' = ..., c = -mu gamma <= 0",
        signature="damping that grows with the displacement: energy removed at the large-|x| "
        "ends of each swing, fed in near x = 0; without it, a negative linear "
        "damping lets the model's amplitude run away",
        parameters=(Parameter("c_x2_v", "1 (dimensionless)", (-_INF, 0.0)),),
        phases=(),
        terms=("x^2 x'",),
    ),
    Effect(
        id="linear_damping",
        title="Linear (viscous) damping or negative resistance",
        explanation="A force proportional to the velocity: viscous damping (c < 0 in "
        "x'' = ...) or, fed by an active element, a negative resistance (c > 0) "
        "that makes the rest state unstable and the oscillation self-excited.",
        enters="a term c x' in x'' = ..., c of either sign (c = mu - k)",
        signature="energy taken out (or fed in) in proportion to the speed, most near x = 0 "
        "where |x'| is largest; an amplitude drift between forcing periods",
        parameters=(Parameter("c_v", "1 (dimensionless)", (-_INF, _INF)),),
        phases=(),
        terms=("x'",),
    ),
    Effect(
        id="cubic_stiffness",
        title="Cubic (Duffing) stiffness",
        explanation="A restoring force growing with the cube of the displacement (a hardening "
        "spring, c < 0 in x'' = ...; softening when c > 0): the natural frequency "
        "rises with the amplitude and the resonance curve bends.",
        enters="a term c x^3 in x'' = ..., c of either sign (-1 for Ueda's oscillators)",
        signature="a restoring force that stiffens at large |x|: swings of large amplitude "
        "are faster than small ones",
        parameters=(Parameter("c_x3", "1 (dimensionless)", (-_INF, _INF)),),
        phases=(),
        terms=("x^3",),
    ),
    Effect(
        id="quadratic_stiffness",
        title="Quadratic stiffness (asymmetric restoring force)",
        explanation="A restoring force that differs for x > 0 and x < 0 (an asymmetric "
        "spring, a static preload or a gravity offset of a nonlinear spring): "
        "the term c x^2 breaks the symmetry x -> -x of the equation.",
        enters="a term c x^2 in x'' = ..., c of either sign",
        signature="the swings to one side stiffer than to the other: the attractor's strobe "
        "points and the record's mean shifted to one side",
        parameters=(Parameter("c_x2", "1 (dimensionless)", (-_INF, _INF)),),
        phases=(),
        terms=("x^2",),
    ),
    Effect(
        id="velocity_cubic_damping",
        title="Cubic velocity (Rayleigh) damping",
        explanation="Damping that grows with the cube of the velocity (Rayleigh's oscillator, "
        "x' - x'^3 / 3: aerodynamic or friction-like losses at high speed), "
        "c x'^3 with c <= 0.",
        enters="a term c x'^3 in x'' = ..., c <= 0",
        signature="energy removed where the motion is fastest (near x = 0), little at the "
        "turning points; unlike van der Pol damping, it depends on the speed, not "
        "the displacement",
        parameters=(Parameter("c_v3", "1 (dimensionless)", (-_INF, 0.0)),),
        phases=(),
        terms=("x'^3",),
    ),
)

for _e in EFFECTS:
    if not set(_e.terms) <= set(TERMS):  # a catalogue error, caught on import
        raise AssertionError(
            f"catalogue: effect {_e.id}: terms {_e.terms} not in the library {TERMS}"
        )


def effect(effect_id):
    """The catalogue entry ``effect_id`` (:func:`discovery.catalogue.lookup`)."""
    return lookup(EFFECTS, effect_id)


def in_bounds(eff, values):
    """Whether ``values`` (the coefficients of the effect's terms, in order; a number for
    one term) are within the physical bounds of its parameters."""
    values = np.atleast_1d(np.asarray(values, float))
    return bool(
        all(p.bounds[0] <= v <= p.bounds[1] for p, v in zip(eff.parameters, values, strict=True))
    )


def effect_dict(eff):
    """:meth:`Effect.as_dict` with the terms it adds (JSON-ready: infinite bounds as
    None)."""
    d = eff.as_dict()
    for p in d["parameters"]:
        p["bounds"] = [None if not np.isfinite(b) else float(b) for b in p["bounds"]]
    d["terms"] = list(eff.terms)
    return d
