"""What keeps a start short, private to the package: names imported on first use
(``_lazy``, so that ``import discovery`` and ``vidi --help`` load no numba, cvxpy, sympy or
matplotlib) and the compiled kernels kept in numba's cache (``_compile``).

Imports nothing itself: each module is imported by its path."""
