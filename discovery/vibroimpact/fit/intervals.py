"""Coefficient intervals by a parametric bootstrap through the full processing.

The bootstrap refits the model for every replicate, so it lives with the fit it repeats:
:func:`discovery.vibroimpact.fit.identify.bootstrap_intervals` and
:class:`discovery.vibroimpact.fit.identify.Intervals`,
re-exported here (the path the documentation has always given).
"""

from .identify import Intervals, bootstrap_intervals

__all__ = ["Intervals", "bootstrap_intervals"]
