"""Packages whose names are imported on first use (PEP 562), one mechanism for all.

``import discovery`` (and ``vidi --help``) must not load numba, cvxpy, scipy.stats, sympy and
matplotlib. A package lists its public names with the submodule that defines each; a name
is imported when it is first read. A function that shares its name with the submodule
defining it (``discovery.ueda.chart``, ``discovery.vibroimpact.explain.explain``) would be
replaced by the submodule as soon as that is imported, so such names are properties of the
package's module class and always give the function, as the eager ``from .x import x`` did.
"""

from __future__ import annotations

import importlib
import sys
import types

__all__ = ["lazy_package"]


def lazy_package(name, exports):
    """Make package ``name`` import ``exports`` (``{public name: submodule}``) on first use.

    Call it at the end of the package's ``__init__``; returns nothing.
    """
    module = sys.modules[name]

    def load(attr):
        return getattr(importlib.import_module(f".{exports[attr]}", name), attr)

    def __getattr__(attr):
        if attr not in exports:
            raise AttributeError(f"module {name!r} has no attribute {attr!r}")
        value = load(attr)
        module.__dict__[attr] = value
        return value

    def __dir__():
        return sorted(set(module.__dict__) | set(exports))

    module.__getattr__, module.__dir__ = __getattr__, __dir__
    shadowed = [a for a, sub in exports.items() if sub.split(".")[-1] == a]
    if shadowed:

        def prop(attr):
            def get(_):
                return load(attr)

            def set_(_, value):  # the import system binds the submodule here
                pass

            return property(get, set_)

        cls = type(
            f"_{name.replace('.', '_')}_package",
            (types.ModuleType,),
            {a: prop(a) for a in shadowed},
        )
        module.__class__ = cls
