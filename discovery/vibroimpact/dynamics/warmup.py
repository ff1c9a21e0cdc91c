"""The vibro-impact system's warm-up: compile its kernels (or load them from numba's cache)
by running each once on the paper's scenario.

A parallel sweep's workers run it before their first job
(:func:`discovery.numerics.executor.make_executor`'s ``warm``), so that numba's cache is
built once; :func:`discovery.warm.warm` runs it with Ueda's.
"""

__all__ = ["compile_kernels"]


def compile_kernels():
    """Run the integrator with its event location, the criteria's compiled interpolation and
    a sensor's lag once each; returns nothing."""
    from ...numerics.lag import lag_at, lag_at_knots
    from ..model.scenario import load_scenario
    from .law_response import impulse_from_steady_state
    from .steady_states import steady_state

    sc = load_scenario("paper")
    imp = impulse_from_steady_state(sc, sc.law, steady_state(sc, sc.law))
    imp.evaluate(imp.t)  # the criteria's compiled interpolation
    lag_at(imp.t, imp.F, lag_at_knots(imp.t, imp.F, 1e-4), 1e-4, imp.t)  # a sensor's lag
