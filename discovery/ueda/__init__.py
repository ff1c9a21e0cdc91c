"""The second system: Ueda's periodically forced oscillators.

``x'' - (mu (1 - gamma x^2) - k) x' + x^3 = B cos(nu t)`` - the negative-resistance
oscillator of the "broken egg" (``negres``) and Ueda's classical Duffing-type oscillator
(``duffing``).  Integrated by the Dormand-Prince machinery shared with the vibro-impact
system (:mod:`discovery.numerics._dopri`).

* :class:`UedaSystem` - the system description (parameters, rhs, Jacobian, period);
* :func:`strobe_points`, :func:`trajectory` - the stroboscopic map - :mod:`.strobe`;
  :func:`lyapunov`, :func:`lyapunov_two_trajectory` -> :class:`Lyapunov` -
  :mod:`.exponents`; :func:`classify`, :func:`classify_points` (thresholds
  :class:`RegimeRules`) -> :class:`Regime` - :mod:`.regimes`; :func:`attractor` ->
  :class:`Attractor` - :mod:`.attractor_analysis`; :func:`basins` -> :class:`Basins` (coexisting
  attractors) - :mod:`.coexisting`;
* :class:`UedaMap`, :func:`periodic_orbit`, :class:`PeriodicOrbit` - the period map,
  shooting and Floquet multipliers (:mod:`discovery.numerics.shooting`, shared with the
  vibro-impact system) - :mod:`.periodic`;
* :func:`chart` -> :class:`Chart` - the regime chart over ``(nu, B)`` in parallel processes;
* :class:`ForcedPolynomial` (an equation, simulable) - :mod:`.polynomial`; a record:
  :func:`simulate_record`, reading, checking and smoothing it - :mod:`.record`;
* :func:`discover` (equation discovery from a record ``t, x`` with known forcing,
  :mod:`.equation_discovery` on the weak form of :mod:`.weak_form`) and :func:`verify` (the
  discovered equation's attractor against the record's, :mod:`.verification` with the
  energy-distance test of :mod:`.strobe_resampling`);
* :func:`explain` (the missing-effect workflow) -> :class:`Explanation`, over this
  system's catalogue :data:`EFFECTS` - :mod:`.explain_loop` (the loop), :mod:`.weak_fits` (fits
  and score tests), :mod:`.explanation` (its outcome), :mod:`.effects`.
"""

from .._startup._lazy import lazy_package

# names are imported on first use (:mod:`discovery._startup._lazy`)
_EXPORTS = {
    "Attractor": "attractor_analysis",
    "attractor": "attractor_analysis",
    "Basins": "coexisting",
    "basins": "coexisting",
    "Lyapunov": "exponents",
    "lyapunov": "exponents",
    "lyapunov_two_trajectory": "exponents",
    "Regime": "regimes",
    "RegimeRules": "regimes",
    "classify": "regimes",
    "classify_points": "regimes",
    "rotation_number": "regimes",
    "strobe_points": "strobe",
    "trajectory": "strobe",
    "Chart": "regime_chart",
    "chart": "regime_chart",
    "KINDS": "sweep",
    "Discovery": "equation_discovery",
    "ForcedPolynomial": "polynomial",
    "Verification": "verification",
    "discover": "equation_discovery",
    "simulate_record": "record",
    "verify": "verification",
    "EFFECTS": "effects",
    "Explanation": "explanation",
    "explain": "explain_loop",
    "PeriodicOrbit": "periodic",
    "UedaMap": "periodic",
    "periodic_orbit": "periodic",
    "MODELS": "system",
    "UedaSystem": "system",
    "UedaRecordSettings": "record",
    "UedaVerifySettings": "verification",
    "UedaChartSettings": "regime_chart",
    "UedaDiscoverSettings": "equation_discovery",
    "UedaExplainSettings": "explain_loop",
}

__all__ = list(_EXPORTS)

lazy_package(__name__, _EXPORTS)
