"""The second system: Ueda's periodically forced oscillators.

``x'' - (mu (1 - gamma x^2) - k) x' + x^3 = B cos(nu t)`` - the negative-resistance
oscillator of the "broken egg" (``negres``) and Ueda's classical Duffing-type oscillator
(``duffing``).  Integrated by the Dormand-Prince machinery shared with the vibro-impact
system (:mod:`discovery.dynamics._dopri`).

* :class:`UedaSystem` - the system description (parameters, rhs, Jacobian, period);
* :func:`attractor`, :func:`lyapunov`, :func:`lyapunov_two_trajectory`,
  :func:`classify`, :func:`basins`, :func:`strobe_points`, :func:`trajectory`;
* :class:`UedaMap`, :func:`periodic_orbit`, :class:`PeriodicOrbit` - the period map,
  shooting and Floquet multipliers (:mod:`discovery.dynamics.shooting`, shared with the
  vibro-impact system) - :mod:`.periodic`;
* :func:`chart` - the regime chart over ``(nu, B)`` in parallel processes;
* :func:`discover` (equation discovery from a record ``t, x`` with known forcing) and
  :func:`verify` (the discovered equation's attractor against the record's),
  :class:`ForcedPolynomial`, :func:`simulate_record` - :mod:`.discover`;
* :func:`explain` (the missing-effect workflow) -> :class:`Explanation`, over this
  system's catalogue :data:`EFFECTS` - :mod:`.explain`, :mod:`.effects`.
"""

from .attractor import (
    Attractor,
    Basins,
    Lyapunov,
    Regime,
    attractor,
    basins,
    classify,
    classify_points,
    lyapunov,
    lyapunov_two_trajectory,
    rotation_number,
    strobe_points,
    trajectory,
)
from .discover import Discovery, ForcedPolynomial, Verification, discover, simulate_record, verify
from .effects import EFFECTS
from .explain import Explanation, explain
from .periodic import PeriodicOrbit, UedaMap, periodic_orbit
from .system import MODELS, UedaSystem

__all__ = [
    "UedaSystem",
    "MODELS",
    "Attractor",
    "Basins",
    "Lyapunov",
    "Regime",
    "attractor",
    "basins",
    "classify",
    "classify_points",
    "lyapunov",
    "lyapunov_two_trajectory",
    "rotation_number",
    "strobe_points",
    "trajectory",
    "Discovery",
    "ForcedPolynomial",
    "Verification",
    "discover",
    "simulate_record",
    "verify",
    "UedaMap",
    "PeriodicOrbit",
    "periodic_orbit",
    "EFFECTS",
    "Explanation",
    "explain",
]
