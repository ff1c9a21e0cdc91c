"""The paper's verification criteria I0..I4 (its equation (8)), in a registry.

With ``F_E`` the measured and ``F_N`` the simulated impulse on a common time axis
(both onsets at ``t* = 0``) over a whole number of cycles::

    I1 = max |F_N - F_E| / max |F_E|
    I2 = int |F_N - F_E| dt / int |F_E| dt
    I3 = sqrt( int (F_N - F_E)^2 dt / int F_E^2 dt )
    I4 = int |sign F_N - sign F_E| dt / int sign F_E dt
       = |supp F_N  symmetric-difference  supp F_E| / |supp F_E|
    I0 = (I1 + I4) / 2

I4 is the measure of the symmetric difference of the contact supports, which
equals the paper's ``|tau_N - tau_E| / tau_E`` when one contact contains the
other; with ``|.|`` it is >= 0.  Both signals are piecewise linear with one-sided
limits at jumps, and the integrals are exact for that representation, so the
force jump at onset adds no interpolation artefact.  For a measured (noisy) ``F_E``
both forces are compared inside the contact windows only (the union of both
supports, widened by 1 % of a period): outside them the simulated force is zero and
the measured one is sensor noise.  When the two cycles differ
(e.g. P1 against P2) both are extended periodically to a common length.
"""

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from ..._api._printing import fmt
from ..._api._validate import Instance, params
from ...errors import InputError, NoContactError
from ...numerics import counts
from ...numerics.intervals import in_widened_intervals
from ...numerics.memo import Memo

_IMPULSE = Instance("discovery.vibroimpact.data.impulse", "Impulse")

__all__ = [
    "CRITERIA",
    "Criterion",
    "Comparison",
    "compare",
    "evaluate_criteria",
    "criterion",
    "definition",
    "MOTION_DEFINITIONS",
    "criteria_lines",
]


@dataclass(frozen=True)
class Comparison:
    """Both impulses on a common grid (with duplicated times at jumps).

    Attributes
    ----------
    t : ndarray of shape (n,)
        Common times [s].
    fe, fn : ndarray of shape (n,)
        Measured and simulated force [N] at ``t`` (one-sided at jumps).
    support_e, support_n : ndarray of shape (k, 2)
        Contact intervals over the common length.
    length : float
        Common length [s] (a whole number of both cycles).
    """

    t: np.ndarray
    fe: np.ndarray
    fn: np.ndarray
    support_e: np.ndarray
    support_n: np.ndarray
    length: float
    _values: dict = field(default_factory=dict, repr=False, compare=False)


def _grid_points(imp, length):
    """(times, is_right_limit) of one impulse's nodes repeated over ``length``."""
    reps = int(round(length / imp.duration))
    # a force jump at the onset (F(0-) != F(0+)) recurs at every cycle boundary k*duration
    jump = imp.F[-1] != imp.F[0]
    parts = []
    for k in range(reps):
        if k and jump:
            parts.append([k * imp.duration])
        parts.append(imp.t[:-1] + k * imp.duration)
    ts = np.concatenate(parts + [[length]])
    dup = np.zeros(ts.size, dtype=bool)
    dup[1:] = ts[1:] == ts[:-1]
    return ts, dup


def compare(measured, simulated):
    """Put two :class:`~discovery.vibroimpact.data.impulse.Impulse` on a common grid."""
    if measured is None or simulated is None:
        raise InputError("both impulses are needed (a simulation without contact has none)")
    ratio = simulated.duration / measured.duration
    p, q = measured.n_periods, simulated.n_periods
    if not math.isclose(ratio, q / p, rel_tol=1e-6):
        raise InputError("the impulses come from different drive periods; use one scenario")
    length = measured.duration * (math.lcm(p, q) // p)
    if _same_grid(measured, simulated):
        # one fold's two sides (a record span): the measured side on its own grid, made
        # once for every law compared with it
        t, tq, left, fe, sup_e = _own_grid(measured)
    else:
        te, de = _grid_points(measured, length)
        tn, dn = _grid_points(simulated, length)
        t, tq, left = _query_grid(np.union1d(te, tn), np.union1d(te[de], tn[dn]))
        fe, sup_e = measured.evaluate(tq, left), measured.periodic_support(length)
    sup_n = simulated.periodic_support(length)
    fn = simulated.evaluate(tq, left)
    if measured.noise > 0:
        # fair to both signals: outside the contact windows (either support, widened by
        # 1 % of a period) the simulated force is zero and the measured one is only
        # noise (condition (3)); both are set to zero there, so noise over the long
        # free flight does not swamp the criteria of a short contact
        pad = 0.01 * measured.duration / measured.n_periods
        inside = _in_intervals(t, np.concatenate([sup_e, sup_n]), pad, length)
        fe, fn = np.where(inside, fe, 0.0), np.where(inside, fn, 0.0)
    return Comparison(t=t, fe=fe, fn=fn, support_e=sup_e, support_n=sup_n, length=length)


def _query_grid(base, jumps):
    """The common grid ``t`` of the knots ``base`` and the jumps' times ``jumps`` (each jump's
    time twice), and where to evaluate both sides on it: ``(t, tq, left)``, the left limit
    at every time, the right one at a jump's second time and at 0."""
    t = np.sort(np.concatenate([base, jumps]))
    right = np.zeros(t.size, dtype=bool)
    right[1:] = t[1:] == t[:-1]
    right[0] = True
    tq, left = t.copy(), ~right
    tq[0] = 0.0
    return t, tq, left


_OWN_GRIDS = Memo(256)
"""The measured side of :func:`compare` on its own grid, per impulse (see :func:`_own_grid`)."""


def _own_grid(imp):
    """``(t, tq, left, F, support)``: the grid of ``imp`` compared with an impulse on the same
    knots (one fold's two sides: the union of a grid with itself, over one cycle), ``imp``
    evaluated on it and its support; made once per impulse and kept (the fitting loops
    compare each measured block with every law; this was half of a comparison's time).
    What a :class:`Comparison` holds is read-only; ``tq`` and ``left`` stay writeable, as
    the compiled evaluation's signature has them (:meth:`~discovery.numerics.memo.Memo.of`)."""

    def made():
        te, de = _grid_points(imp, imp.duration)
        t, tq, left = _query_grid(np.unique(te), np.unique(te[de]))
        out = (t, tq, left, imp.evaluate(tq, left), imp.periodic_support(imp.duration))
        for a in (out[0], out[3], out[4]):
            a.setflags(write=False)
        return out

    return _OWN_GRIDS.of(imp, made)


def _same_grid(a, b):
    """Whether two impulses have the same knots over the same cycle."""
    return (
        a.duration == b.duration
        and a.n_periods == b.n_periods
        and (a.t is b.t or (a.t.shape == b.t.shape and np.array_equal(a.t, b.t)))
    )


def _in_intervals(t, iv, pad, length):
    """Whether each (sorted) time lies in one of the intervals ``iv`` widened by ``pad``
    (cyclic over ``length``)."""
    return in_widened_intervals(t, iv, pad, length)


def _int_abs(h, d):
    """Exact integral of |d| for d piecewise linear on a grid of steps ``h``."""
    from ...numerics.sampled import abs_areas  # (numba: not at import, see --help)

    h, d = (np.ascontiguousarray(a, dtype=float) for a in (h, d))
    return float(np.sum(abs_areas(h, d)))


def _int_sq(h, d):
    """Exact integral of d^2 for d piecewise linear on a grid of steps ``h``."""
    a, b = d[:-1], d[1:]
    return float(np.sum(h * (a * a + a * b + b * b) / 3.0))


def _measure(iv):
    return float(np.sum(iv[:, 1] - iv[:, 0])) if len(iv) else 0.0


def _intersection(a, b):
    i = j = 0
    total = 0.0
    while i < len(a) and j < len(b):
        lo, hi = max(a[i, 0], b[j, 0]), min(a[i, 1], b[j, 1])
        total += max(0.0, hi - lo)
        if a[i, 1] < b[j, 1]:
            i += 1
        else:
            j += 1
    return total


def _safe(num, den, name):
    if den <= 0:
        raise NoContactError(f"{name} is undefined: the measured impulse is zero")
    return num / den


def _once(fn):
    """A function of a :class:`Comparison` computed once for it: the parts several
    criteria share (I0 is made of I1 and I4, which are asked for too; every integral takes
    the grid's steps, three the force difference)."""

    @functools.wraps(fn)
    def once(c):
        if fn not in c._values:
            c._values[fn] = fn(c)
        return c._values[fn]

    return once


@_once
def _steps(c):
    return np.diff(c.t)


@_once
def _difference(c):
    return c.fn - c.fe


@_once
def _i1(c):
    return _safe(float(np.max(np.abs(_difference(c)))), float(np.max(np.abs(c.fe))), "I1")


def _i2(c):
    return _safe(_int_abs(_steps(c), _difference(c)), _int_abs(_steps(c), c.fe), "I2")


def _i3(c):
    return math.sqrt(_safe(_int_sq(_steps(c), _difference(c)), _int_sq(_steps(c), c.fe), "I3"))


@_once
def _i4(c):
    me, mn = _measure(c.support_e), _measure(c.support_n)
    sym = me + mn - 2.0 * _intersection(c.support_e, c.support_n)
    return _safe(max(sym, 0.0), me, "I4")


def _i0(c):
    return 0.5 * (_i1(c) + _i4(c))


@dataclass(frozen=True)
class Criterion:
    """One criterion: its function and how every printout and report names it.

    The one definition of a criterion: ``print()`` of results, the CLI's tables and every
    report read ``formula``, ``meaning`` and ``unit`` from here (see :func:`definition`).
    Calling it computes it: ``CRITERIA["I2"](comparison)``.

    Attributes
    ----------
    name : str
        ``"I2"``.
    function : callable
        ``Comparison -> float``.
    formula : str
        Plain text, ``F_E`` measured and ``F_N`` simulated force, ``supp`` a contact
        support, ``|.|`` its measure.
    latex : str
        The formula as LaTeX (math mode).
    meaning : str
        What it measures, in a few words.
    unit : str
        ``"1"``: every criterion is a ratio (dimensionless).
    """

    name: str
    function: object
    formula: str
    latex: str
    meaning: str
    unit: str = "1"

    def __call__(self, comparison):
        return self.function(comparison)


CRITERIA = {
    c.name: c
    for c in (
        Criterion(
            "I0",
            _i0,
            "(I1 + I4) / 2",
            r"\tfrac12 (I_1 + I_4)",
            "mean of the peak-force error I1 and the contact-time mismatch I4",
        ),
        Criterion(
            "I1",
            _i1,
            "max |F_N - F_E| / max |F_E|",
            r"\max|F_N - F_E| \,/\, \max|F_E|",
            "largest force difference relative to the measured peak",
        ),
        Criterion(
            "I2",
            _i2,
            "int |F_N - F_E| dt / int |F_E| dt",
            r"\int|F_N - F_E|\,dt \,/\, \int|F_E|\,dt",
            "relative L1 distance of the force histories",
        ),
        Criterion(
            "I3",
            _i3,
            "sqrt( int (F_N - F_E)^2 dt / int F_E^2 dt )",
            r"\bigl(\int(F_N - F_E)^{2}\,dt \,/\, \int F_E^{2}\,dt\bigr)^{1/2}",
            "relative L2 distance of the force histories",
        ),
        Criterion(
            "I4",
            _i4,
            "|supp F_N (symmetric difference) supp F_E| / |supp F_E|",
            r"|\operatorname{supp}F_N \,\triangle\, \operatorname{supp}F_E| \,/\, "
            r"|\operatorname{supp}F_E|",
            "contact-time mismatch: symmetric difference of the contact supports",
        ),
    )
}
"""Registry: name -> :class:`Criterion` (callable on a :class:`Comparison`, returning a
float >= 0).  A new criterion is one entry here; a plain function registered here works
too (its printouts then say only its name, see :func:`definition`)."""


MOTION_DEFINITIONS = {
    "I5": Criterion(
        "I5",
        None,
        "sqrt( sum_b n_b (Z_N,b - Z_E,b)^2 / sum_b n_b Z_E,b^2 ) over the contact window",
        r"\bigl(\sum_b n_b (\zeta_{N,b} - \zeta_{E,b})^{2} \,/\, "
        r"\sum_b n_b \zeta_{E,b}^{2}\bigr)^{1/2}",
        "relative L2 distance of the recorded and simulated penetration over the contacts",
    )
}
"""Criteria of the recorded motion, computed over a record span's folds
(:mod:`~discovery.vibroimpact.verify.motion`: ``b`` a folded bin of ``n_b`` samples inside
the contact window, ``zeta`` the penetration ``w1 - w2``), not from a :class:`Comparison`
of forces; defined here beside the force's so that every printout reads one table."""


def definition(name):
    """The :class:`Criterion` of ``name`` for printouts and reports: the registry's entry
    (or the motion's, :data:`MOTION_DEFINITIONS`), or, for a name registered as a plain
    function or not registered, one that says only the name (and the function's first
    docstring line as its meaning)."""
    c = CRITERIA.get(name) or MOTION_DEFINITIONS.get(name)
    if isinstance(c, Criterion):
        return c
    doc = (getattr(c, "__doc__", None) or "").strip().splitlines()
    return Criterion(str(name), c, "", "", doc[0] if doc else "", "1")


def criterion(name):
    """The criterion function registered under ``name``."""
    try:
        return CRITERIA[name]
    except KeyError:
        raise InputError(
            f"unknown criterion {name!r}; valid names: {', '.join(CRITERIA)}"
        ) from None


@params(measured=(_IMPULSE, None), simulated=(_IMPULSE, None), names=(None, list, tuple))
def evaluate_criteria(measured, simulated, names=None):
    """``{name: value}`` for the requested criteria (default all), measured vs simulated."""
    names = list(CRITERIA) if names is None else list(names)
    counts.count("criteria" if set(names) >= set(CRITERIA) else "objectives")
    funcs = {n: criterion(n) for n in names}
    c = compare(measured, simulated)
    return {n: float(f(c)) for n, f in funcs.items()}


def criteria_lines(criteria, floor=None, limits=None, indent="  "):
    """The criteria table: value, noise floor, the limit (for the criteria the consistency
    rule judges; ``--`` for the others) and the meaning, from :data:`CRITERIA` (the one
    definition)."""
    if not criteria:
        return []
    out = [f"{indent}{'criterion':<10}{'value':>10}{'floor':>10}{'limit':>10}   meaning"]
    for k in (*CRITERIA, *(k for k in criteria if k not in CRITERIA)):
        if k in criteria:
            lim = (limits or {}).get(k)
            meaning = definition(k).meaning
            out.append(
                f"{indent}{k:<10}{fmt(criteria[k], 3):>10}"
                f"{fmt((floor or {}).get(k), 3):>10}"
                f"{fmt(lim, 3) if lim is not None else '--':>10}"
                + (f"   {meaning}" if meaning else "")
            )
    return out
