"""cvxpy, imported without loading ``scipy.stats``.

cvxpy's import loads ``scipy.stats`` for one name: ``entropy``, which its quantum relative
entropy atom evaluates numerically (``cvxpy/atoms/quantum_rel_entr.py``).  No problem here
uses that atom, and ``scipy.stats`` is a third of a second (more on a loaded machine) of
the half second cvxpy takes to import, in every ``vidi fit`` and ``vidi explain``.  So while
cvxpy is imported, ``scipy.stats`` stands as :class:`_Deferred`: a module whose ``entropy``
loads the real one when called, and whose any other name, or submodule, loads the real
one at once (a later cvxpy that reads more of ``scipy.stats`` at import gets the real
thing).  After cvxpy's import the stand-in is gone: ``import scipy.stats`` then loads the
real module as ever.  Nothing else changes: the solvers and every problem are cvxpy's.
"""

import importlib
import importlib.util
import sys
import types

_STATS = "scipy.stats"


def _real_stats():
    """The real ``scipy.stats`` (the stand-in removed first)."""
    if isinstance(sys.modules.get(_STATS), _Deferred):
        del sys.modules[_STATS]
    return importlib.import_module(_STATS)


def _entropy(*args, **kwargs):
    """``scipy.stats.entropy``, its module loaded on the first call."""
    return _real_stats().entropy(*args, **kwargs)


class _Deferred(types.ModuleType):
    """``scipy.stats`` while cvxpy is imported (see the module's docstring)."""

    def __getattr__(self, name):
        if name.startswith("__"):
            raise AttributeError(name)
        return getattr(_real_stats(), name)


def _stand_in():
    """The stand-in module (a package: its submodules are the real ones)."""
    spec = importlib.util.find_spec(_STATS)
    mod = _Deferred(_STATS)
    mod.__path__ = list(spec.submodule_search_locations or [])
    mod.entropy = _entropy
    return mod


def _load():
    """cvxpy, imported with ``scipy.stats`` deferred (see the module's docstring)."""
    if "cvxpy" in sys.modules or _STATS in sys.modules:
        return importlib.import_module("cvxpy")
    stand_in = _stand_in()
    sys.modules[_STATS] = stand_in
    try:
        return importlib.import_module("cvxpy")
    finally:
        if sys.modules.get(_STATS) is stand_in:
            del sys.modules[_STATS]


cvxpy = _load()
