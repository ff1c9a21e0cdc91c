"""Fitting force laws: the certified sparse regressor (``regression``, over
``constrained_lsq`` and ``proposals``), discovery with full-simulation ranking
(``discovery``, over ``evidence``, the ``shortlist`` checker, the ``stepwise`` search,
``ranking``, ``equivalence``, ``discovery_warnings`` and ``discovery_result``),
output-error identification (``identification``, over ``records``, the residual ``problem`` and
the optimisers of ``optimise``) and coefficient intervals by a bootstrap (``intervals``).
"""
