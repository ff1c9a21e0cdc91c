"""A bounded cache of simulations, keyed by the values they depend on.

The fitting loops evaluate one model several times in a row: an optimiser's last point is
evaluated again for its verdict (with the noise floor), an iteration of ``explain`` starts
by verifying the model the previous one named, and the residual of a model is taken right
after its verification.  Each of those simulates the same law from the same states; a
:class:`Memo` keeps the last results so the second asks cost nothing.

Only pure computations go in: a result is a function of its key (frozen scenarios and
laws compare by value, arrays by their bytes), so a hit returns what the computation would
have returned, bit for bit.  Results are shared, so callers copy an array before changing
it.  The cache is per process (forked workers start with the parent's entries) and holds
at most ``size`` results, least recently used first out.
"""

from collections import OrderedDict

import numpy as np

__all__ = ["Memo", "value_key"]


def value_key(*parts):
    """A hashable key of ``parts``: arrays by dtype, shape and bytes, dicts by their sorted
    items, sequences element by element; anything else as itself (it must be hashable)."""
    return tuple(_freeze(p) for p in parts)


def _freeze(v):
    if isinstance(v, np.ndarray):
        return ("array", v.dtype.str, v.shape, v.tobytes())
    if isinstance(v, dict):
        return ("dict", tuple(sorted((k, _freeze(x)) for k, x in v.items())))
    if isinstance(v, list | tuple):
        return ("seq", tuple(_freeze(x) for x in v))
    return v


class Memo:
    """A least-recently-used cache of at most ``size`` results.

    Attributes
    ----------
    hits, misses : int
        How many asks were answered from the cache and how many were computed.
    """

    def __init__(self, size):
        self.size = int(size)
        self._d = OrderedDict()
        self.hits = self.misses = 0

    def get(self, key, compute):
        """The result stored under ``key``, else ``compute()`` stored and returned (an
        exception from ``compute`` is raised and nothing is stored)."""
        try:
            value = self._d[key]
        except KeyError:
            self.misses += 1
            value = compute()
            self._d[key] = value
            if len(self._d) > self.size:
                self._d.popitem(last=False)
            return value
        except TypeError:  # an unhashable part: not cached
            self.misses += 1
            return compute()
        self.hits += 1
        self._d.move_to_end(key)
        return value

    def of(self, obj, compute):
        """``compute()`` for the object ``obj`` itself, kept under its identity (a measured
        block's arrays, asked for by every evaluation): the entry holds ``obj``, so its id is
        not reused while kept; an object that took the id of one no longer kept is computed
        afresh."""
        kept, value = self.get(id(obj), lambda: (obj, compute()))
        return value if kept is obj else compute()

    def __contains__(self, key):
        """Whether ``key`` is stored (not counted as a hit or a miss)."""
        try:
            return key in self._d
        except TypeError:
            return False

    def clear(self):
        self._d.clear()
        self.hits = self.misses = 0

    def __len__(self):
        return len(self._d)
