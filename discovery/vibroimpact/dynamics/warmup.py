"""The vibro-impact system's warm-up: compile its kernels (or load them from numba's cache)
by running each once on the paper's scenario.

A parallel sweep's workers run it before their first job
(:func:`discovery.numerics.executor.make_executor`'s ``warm``), so that numba's cache is
built once; :func:`discovery.warm.warm` runs it with Ueda's.
"""

import numpy as np

__all__ = ["compile_kernels"]


def compile_kernels():
    """Run the integrator with its event location, the criteria's compiled interpolation, a
    sensor's lag and the compiled loops over sampled signals (contact edges, the criteria's
    areas and contact windows) once each; returns nothing."""
    from ...numerics.intervals import in_widened_intervals
    from ...numerics.lag import lag_at, lag_at_knots
    from ...numerics.sampled import bin_means
    from ..data.contact_edges import _edges, moving_mean
    from ..model.scenario import load_scenario
    from ..verify.criteria import evaluate_criteria
    from .law_response import impulse_from_steady_state
    from .steady_states import steady_state

    sc = load_scenario("paper")
    imp = impulse_from_steady_state(sc, sc.law, steady_state(sc, sc.law))
    imp.evaluate(imp.t)  # the criteria's compiled interpolation
    lag_at(imp.t, imp.F, lag_at_knots(imp.t, imp.F, 1e-4), 1e-4, imp.t)  # a sensor's lag
    evaluate_criteria(imp, imp)  # the areas of the difference
    moving_mean(imp.F, 3)
    _edges(imp.t, imp.F, imp.threshold, 3, max_extrap=4.0, noise=0.0)
    in_widened_intervals(imp.t, imp.support, 0.0, imp.duration)
    bin_means(np.zeros(imp.t.size, dtype=np.int64), imp.F, np.array([imp.t.size]))  # a fold's
