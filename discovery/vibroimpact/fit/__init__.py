"""Fitting force laws: the certified sparse regressor (``regression``),
discovery with full-simulation ranking (``discover``), output-error identification
(``identify``) and coefficient intervals (``intervals``).
"""
