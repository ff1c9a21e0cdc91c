"""Packages whose names are imported on first use (PEP 562), one mechanism for all.

``import discovery`` (and ``vidi --help``) must not load numba, cvxpy, scipy.stats, sympy and
matplotlib. A package lists its public names with the submodule that defines each; a name
is imported when it is first read, and then kept in the package's namespace.

Rule: no public name is also the name of a module. Importing ``pkg.sub`` binds ``sub`` in
``pkg``, so an exported function ``sub`` would be replaced by its module (and
``import pkg.sub as m`` would give the function). A module is named for what it holds
(``regime_chart`` defines ``chart``), and :func:`lazy_package` refuses, at import, an
export named like the module that defines it or like a submodule of the package.
"""

from __future__ import annotations

import importlib
import os
import sys

__all__ = ["lazy_package"]


def _submodules(module):
    """Names of the modules and subpackages in package ``module``'s directories."""
    names = set()
    for path in getattr(module, "__path__", ()):
        for entry in os.listdir(path):
            stem, ext = os.path.splitext(entry)
            if ext == ".py" or (not ext and os.path.isdir(os.path.join(path, entry))):
                names.add(stem)
    return names - {"__init__", "__pycache__"}


def _refuse_shadowing(name, exports, submodules):
    """Raise ``ImportError`` naming every export that shares its name with a module."""
    clashes = [
        f"{attr!r} (from .{sub})"
        for attr, sub in exports.items()
        if attr == sub.rsplit(".", 1)[-1] or attr in submodules
    ]
    if clashes:
        raise ImportError(
            f"package {name!r} exports {', '.join(clashes)} under the name of a module: "
            "importing that module would replace the name; rename the module for what it "
            "holds (e.g. regime_chart.py for chart)"
        )


def lazy_package(name, exports):
    """Make package ``name`` import ``exports`` (``{public name: submodule}``) on first use.

    Call it at the end of the package's ``__init__``; returns nothing.  Raises
    ``ImportError`` when a public name is also the name of a module (see the module
    docstring).
    """
    module = sys.modules[name]
    _refuse_shadowing(name, exports, _submodules(module))

    def __getattr__(attr):
        if attr not in exports:
            raise AttributeError(f"module {name!r} has no attribute {attr!r}")
        value = getattr(importlib.import_module(f".{exports[attr]}", name), attr)
        module.__dict__[attr] = value
        return value

    def __dir__():
        return sorted(set(module.__dict__) | set(exports))

    module.__getattr__, module.__dir__ = __getattr__, __dir__
