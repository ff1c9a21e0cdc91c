"""The one definition of each criterion (name, formula, meaning, unit) is what is computed.

Every printout and report reads the criteria registry; here each entry's stated formula is
computed independently, on a dense grid, for a small synthetic pair of impulses (a
triangle and a later, lower, longer one), and compared with what the registry computes.
"""

import numpy as np
import pytest

from discovery.vibroimpact.data.impulse import Impulse
from discovery.vibroimpact.verify.criteria import CRITERIA, Criterion, criteria_lines, definition

DURATION = 1.0


def _triangle(t0, t1, peak):
    mid = 0.5 * (t0 + t1)
    t = np.array([0.0, t0, mid, t1, DURATION])
    F = np.array([0.0, 0.0, peak, 0.0, 0.0])
    return Impulse(
        t=t, F=F, duration=DURATION, support=np.array([[t0, t1]]), n_periods=1, onset=0.0
    )


MEASURED = _triangle(0.10, 0.30, 1000.0)
SIMULATED = _triangle(0.15, 0.40, 800.0)

# what each registry formula says, computed by brute force on a fine grid
_T = np.linspace(0.0, DURATION, 400_001)
_FE = np.interp(_T, MEASURED.t, MEASURED.F)
_FN = np.interp(_T, SIMULATED.t, SIMULATED.F)
_DT = _T[1] - _T[0]


def _int(y):
    return float(np.sum(0.5 * (y[1:] + y[:-1])) * _DT)


_SE, _SN = _FE > 0, _FN > 0
BY_FORMULA = {
    "max |F_N - F_E| / max |F_E|": np.max(np.abs(_FN - _FE)) / np.max(np.abs(_FE)),
    "int |F_N - F_E| dt / int |F_E| dt": _int(np.abs(_FN - _FE)) / _int(np.abs(_FE)),
    "sqrt( int (F_N - F_E)^2 dt / int F_E^2 dt )": np.sqrt(_int((_FN - _FE) ** 2) / _int(_FE**2)),
    "|supp F_N (symmetric difference) supp F_E| / |supp F_E|": (np.sum(_SE ^ _SN) / np.sum(_SE)),
}
# the meaning names the formula's kind (a test that reads the prose for its key words)
MEANING_WORDS = {
    "I1": ("peak",),
    "I2": ("L1",),
    "I3": ("L2",),
    "I4": ("symmetric difference", "contact"),
    "I0": ("I1", "I4"),
}


def test_every_registry_entry_is_a_full_definition():
    for name, c in CRITERIA.items():
        assert isinstance(c, Criterion) and c.name == name
        assert c.formula and c.latex and c.meaning and c.unit == "1"
        assert definition(name) is c


@pytest.mark.parametrize("name", sorted(CRITERIA))
def test_the_stated_formula_is_what_is_computed(name):
    c = CRITERIA[name]
    from discovery.vibroimpact.verify.criteria import compare

    value = c(compare(MEASURED, SIMULATED))
    if c.formula == "(I1 + I4) / 2":
        i1 = BY_FORMULA[CRITERIA["I1"].formula]
        i4 = BY_FORMULA[CRITERIA["I4"].formula]
        expected = 0.5 * (i1 + i4)
    else:
        expected = BY_FORMULA[c.formula]
    assert value == pytest.approx(expected, rel=2e-4), (name, c.formula)
    for word in MEANING_WORDS[name]:
        assert word in c.meaning, (name, word, c.meaning)


def test_print_and_reports_read_the_registry():
    from reports.context import _criteria_table

    crit = {k: 0.1 for k in CRITERIA}
    lines = criteria_lines(crit, {k: 0.01 for k in CRITERIA}, {"I2": 0.025})
    for name, c in CRITERIA.items():
        row = next(ln for ln in lines if ln.split()[0] == name)
        assert row.endswith(c.meaning)
    assert "0.025" in next(ln for ln in lines if ln.split()[0] == "I2")
    rows = _criteria_table(crit, {}, {})
    for row, c in zip(rows, CRITERIA.values(), strict=True):
        assert c.latex in row[-1] and c.meaning in row[-1]


def test_a_plain_function_registered_still_prints():
    def m1(comparison):
        """Motion mismatch of the bodies."""
        return 0.0

    CRITERIA["M1"] = m1
    try:
        assert definition("M1").meaning == "Motion mismatch of the bodies."
        assert any("M1" in ln for ln in criteria_lines({"M1": 0.5}))
    finally:
        del CRITERIA["M1"]
