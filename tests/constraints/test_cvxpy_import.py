"""cvxpy imported without ``scipy.stats`` (constraints/_cvxpy.py): the same cvxpy, its one
use of ``scipy.stats`` still right, and ``scipy.stats`` itself unchanged afterwards."""

import subprocess
import sys
import textwrap

import pytest


def _run(code):
    """``code`` in a fresh interpreter (imports are process-wide); its stdout's last line."""
    out = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        capture_output=True,
        text=True,
        check=True,
    )
    return out.stdout.strip().splitlines()[-1]


def test_cvxpy_is_imported_without_scipy_stats_and_solves():
    got = _run(
        """
        import sys
        from constraints import cvxpy as cp
        loaded = "scipy.stats" in sys.modules
        x = cp.Variable(2)
        p = cp.Problem(cp.Minimize(cp.sum_squares(x - [1.0, -1.0])), [x >= 0])
        p.solve(solver="CLARABEL")
        print(loaded, sys.modules["cvxpy"] is cp, [round(float(v), 6) + 0.0 for v in x.value])
        """
    )
    assert got == "False True [1.0, 0.0]"


def test_the_one_name_cvxpy_reads_loads_the_real_module_when_called():
    """The quantum relative entropy atom's ``entropy`` is scipy's (called: the real module
    is loaded then); ``import scipy.stats`` afterwards is the real module, whole."""
    got = _run(
        """
        import importlib, sys
        from constraints import cvxpy
        q = importlib.import_module("cvxpy.atoms.quantum_rel_entr")
        v = q.entropy([0.2, 0.8], [0.5, 0.5])
        import scipy, scipy.stats
        real = type(sys.modules["scipy.stats"]).__name__ == "module"
        print(real, scipy.stats is sys.modules["scipy.stats"], hasattr(scipy.stats, "norm"),
              v == scipy.stats.entropy([0.2, 0.8], [0.5, 0.5]))
        """
    )
    assert got == "True True True True"


def test_any_other_name_or_submodule_of_the_stand_in_is_the_real_one():
    """A later cvxpy that reads more of ``scipy.stats`` while it is imported gets the real
    module: any other name, and any submodule."""
    got = _run(
        """
        import sys
        from constraints import _cvxpy
        stand_in = _cvxpy._stand_in()
        sys.modules["scipy.stats"] = stand_in
        norm = stand_in.norm
        real = sys.modules["scipy.stats"]
        sys.modules["scipy.stats"] = _cvxpy._stand_in()
        from scipy.stats import distributions
        print(real is not stand_in, norm is real.norm, hasattr(distributions, "norm"))
        """
    )
    assert got == "True True True"


def test_with_scipy_stats_already_loaded_cvxpy_is_imported_as_ever():
    got = _run(
        """
        import sys
        import scipy.stats
        real = sys.modules["scipy.stats"]
        from constraints import cvxpy
        print(sys.modules["scipy.stats"] is real)
        """
    )
    assert got == "True"


@pytest.mark.parametrize("module", ["constraints.builders", "constraints.solver"])
def test_the_package_reads_cvxpy_through_the_loader(module):
    import importlib

    from constraints import cvxpy

    assert importlib.import_module(module).cp is cvxpy
