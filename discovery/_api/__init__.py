"""The public API's machinery, private to the package: results as data (``_result``),
settings objects (``_settings``), argument checks at the boundary (``_validate``), printed
results (``_printing``) and the progress of long runs (``_progress``).

Imports nothing itself: each module is imported by its path."""
