"""Contact-force laws ``F(zeta, dzeta)`` built from terms ``zeta^a * zd^b``.

A :class:`ForceLaw` is a sum ``P(zeta, zd) = sum_i c_i * zeta^a_i * zd^b_i`` with
``zd = max(dzeta, 0)``.  The contact force is::

    F(zeta, dzeta) = max(P(zeta, max(dzeta, 0)), 0)   if zeta > 0
                   = 0                                  otherwise

so the paper's conditions (3) (no force without contact) and (5) (negative
penetration velocity has no effect) hold by construction, and the force is never
adhesive (4): where ``P`` would be negative the bodies exert no force.  Units are
SI: ``zeta`` [m], ``dzeta`` [m/s], ``F`` [N]; a coefficient of ``z^a*zd^b`` has
units N m^-a (m/s)^-b.
"""

from dataclasses import dataclass

import numpy as np
import sympy

from ._lawgrammar import parse_law_terms
from .errors import InputError

__all__ = ["Term", "ForceLaw", "ZETA", "ZD"]

ZETA, ZD = sympy.symbols("zeta zd", nonnegative=True)
_LATEX_NAMES = {ZETA: r"\zeta", ZD: r"\dot{\zeta}_{+}"}


def _fmt_exp(p):
    return str(int(p)) if float(p).is_integer() else repr(float(p))


@dataclass(frozen=True, order=True)
class Term:
    """One candidate term ``zeta^a * zd^b`` (``a, b >= 0``, not both 0).

    Parameters
    ----------
    a : float
        Exponent of the penetration ``zeta``.
    b : float
        Exponent of the loading velocity ``zd = max(dzeta, 0)``.
    """

    a: float
    b: float

    def __post_init__(self):
        a, b = float(self.a), float(self.b)
        if not (np.isfinite(a) and np.isfinite(b)) or a < 0 or b < 0 or (a == 0 and b == 0):
            raise InputError(
                f"term exponents must be finite, >= 0 and not both 0; got a={a}, b={b}"
            )
        object.__setattr__(self, "a", a)
        object.__setattr__(self, "b", b)

    @classmethod
    def parse(cls, name):
        """Term from its name, e.g. ``'z'``, ``'zd'``, ``'z*zd'``, ``'z^1.5'``, ``'z^2*zd'``."""
        terms = parse_law_terms(name)
        if len(terms) != 1 or terms[0][0] != 1.0:
            raise InputError(f"{name!r} is not a single term name; use e.g. 'z', 'zd', 'z^1.5*zd'")
        return cls(terms[0][1], terms[0][2])

    @property
    def name(self):
        """Canonical name: ``z`` part then ``zd`` part, exponent 1 omitted."""
        parts = []
        if self.a:
            parts.append("z" if self.a == 1 else f"z^{_fmt_exp(self.a)}")
        if self.b:
            parts.append("zd" if self.b == 1 else f"zd^{_fmt_exp(self.b)}")
        return "*".join(parts)

    @property
    def is_dissipative(self):
        """True when the term depends on the loading velocity (``b > 0``)."""
        return self.b > 0

    def __call__(self, zeta, zd):
        """Evaluate ``zeta^a * zd^b`` (arrays broadcast; inputs must be >= 0)."""
        zeta = np.asarray(zeta, dtype=float)
        zd = np.asarray(zd, dtype=float)
        return np.power(zeta, self.a) * np.power(zd, self.b)

    def sympy(self):
        """The term as a sympy expression in ``ZETA`` and ``ZD``."""
        return ZETA ** sympy.nsimplify(self.a) * ZD ** sympy.nsimplify(self.b)

    def __str__(self):
        return self.name


@dataclass(frozen=True)
class ForceLaw:
    """A contact-force law: coefficients on terms.

    Parameters
    ----------
    terms : tuple of Term
        Distinct terms.
    coefficients : tuple of float
        One coefficient per term, SI units.

    Examples
    --------
    >>> law = ForceLaw.parse("2.06e8*z + 1.28e7*zd")
    >>> float(law(1e-3, 0.5))
    6606000.0
    """

    terms: tuple
    coefficients: tuple

    def __post_init__(self):
        terms = tuple(self.terms)
        coefs = tuple(float(c) for c in self.coefficients)
        if len(terms) != len(coefs):
            raise InputError(f"{len(terms)} terms but {len(coefs)} coefficients")
        if not terms:
            raise InputError("a force law needs at least one term, e.g. '2.06e8*z'")
        if len(set(terms)) != len(terms):
            raise InputError("a force law lists the same term twice; merge them")
        if not all(np.isfinite(coefs)):
            raise InputError("force-law coefficients must be finite numbers")
        object.__setattr__(self, "terms", terms)
        object.__setattr__(self, "coefficients", coefs)

    # ----------------------------------------------------------- construction
    @classmethod
    def parse(cls, text):
        """Law from text like ``"2.06e8*z + 1.28e7*zd"`` (like terms are summed)."""
        merged = {}
        for c, a, b in parse_law_terms(text):
            t = Term(a, b)
            merged[t] = merged.get(t, 0.0) + c
        return cls(tuple(merged), tuple(merged.values()))

    @classmethod
    def from_dict(cls, coefficients):
        """Law from ``{term name: coefficient}``."""
        terms = tuple(Term.parse(k) for k in coefficients)
        return cls(terms, tuple(float(v) for v in coefficients.values()))

    def with_coefficients(self, values):
        """The same terms with new coefficients (sequence of floats)."""
        return ForceLaw(self.terms, tuple(float(v) for v in values))

    # ------------------------------------------------------------- properties
    @property
    def names(self):
        """Term names, in order."""
        return [t.name for t in self.terms]

    def as_dict(self):
        """``{term name: coefficient}``."""
        return dict(zip(self.names, self.coefficients, strict=True))

    def to_text(self):
        """Text that :meth:`parse` reads back to the same law."""
        out = []
        for c, t in zip(self.coefficients, self.terms, strict=True):
            sign = "-" if c < 0 else "+"
            num = repr(abs(c))  # shortest text that reads back exactly
            num = num[:-2] if num.endswith(".0") else num
            out.append(f"{sign} {num}*{t.name}")
        text = " ".join(out)
        return text[2:] if text.startswith("+ ") else "-" + text[2:]

    def format(self, digits=6):
        """Readable text with ``digits`` significant digits (``to_text`` is exact)."""
        out = []
        for c, t in zip(self.coefficients, self.terms, strict=True):
            sign = "-" if c < 0 else "+"
            out.append(f"{sign} {abs(c):.{digits}g}*{t.name}")
        text = " ".join(out)
        return text[2:] if text.startswith("+ ") else "-" + text[2:]

    def __str__(self):
        return self.format()

    @property
    def has_jump(self):
        """True when the force jumps at contact onset (a term ``zd^b`` with ``a = 0``)."""
        return any(t.a == 0 for t in self.terms)

    # ------------------------------------------------------------ evaluation
    def polynomial(self, zeta, zd):
        """Raw ``P(zeta, zd)`` without the contact conditions (inputs >= 0)."""
        zeta = np.asarray(zeta, dtype=float)
        zd = np.asarray(zd, dtype=float)
        out = np.zeros(np.broadcast(zeta, zd).shape)
        for c, t in zip(self.coefficients, self.terms, strict=True):
            out = out + c * t(zeta, zd)
        return out

    def check_physical(self, scenario, what="law"):
        """Refuse a law no machine could have (one clear line, :class:`InputError`).

        On the box ``0 < zeta <= x``, ``0 <= zd <= 4 v`` (``x, v`` the scenario's motion
        scales, :meth:`Scenario.scales`): the law must push the bodies apart somewhere
        (else the moulding falls through the grid and no steady state exists), and satisfy
        the paper's condition (6), dissipativity ``P(zeta, zd) >= P(zeta, 0)`` (damping
        never feeds energy into an impact).  Conditions (3)-(5) hold by construction.
        """
        if not any(self.coefficients):
            raise InputError(f"{what} '{self}' has no non-zero coefficient; give a law such "
                             "as '2.06e8*z + 1.28e7*zd'")
        x, v = scenario.scales()
        Z, V = x, 4.0 * v
        zz, vv = np.meshgrid(np.linspace(Z / 64, Z, 64), np.linspace(0.0, V, 65))
        P = self.polynomial(zz, vv)
        if not np.max(P) > 0:
            raise InputError(
                f"{what} '{self}' never pushes the bodies apart (P <= 0 for every "
                f"penetration up to {Z:.3g} m and velocity up to {V:.3g} m/s): the moulding "
                "would fall through the grid; a contact law needs a positive stiffness term "
                "such as 2e8*z")
        D = P - self.polynomial(zz, np.zeros_like(vv))
        worst = np.unravel_index(int(np.argmin(D)), D.shape)
        if D[worst] < -1e-9 * float(np.max(np.abs(P))):
            raise InputError(
                f"{what} '{self}' breaks the paper's condition (6), dissipativity: F(zeta, zd) "
                f"< F(zeta, 0) at zeta = {zz[worst]:.3g} m, zd = {vv[worst]:.3g} m/s (damping "
                "that feeds energy into the impact); make the velocity terms non-negative")

    def __call__(self, zeta, dzeta):
        """Contact force ``F(zeta, dzeta)`` [N] with conditions (3)-(5) applied.

        Parameters
        ----------
        zeta : array_like
            Interpenetration [m].
        dzeta : array_like
            Penetration velocity [m/s] (negative values act as 0).
        """
        zeta = np.asarray(zeta, dtype=float)
        dzeta = np.asarray(dzeta, dtype=float)
        zp = np.maximum(zeta, 0.0)
        p = self.polynomial(zp, np.maximum(dzeta, 0.0))
        return np.where(zeta > 0, np.maximum(p, 0.0), 0.0)

    def kernel_arrays(self):
        """``(coef, a, b)`` float arrays for the compiled integrator."""
        return (
            np.array(self.coefficients, dtype=np.float64),
            np.array([t.a for t in self.terms], dtype=np.float64),
            np.array([t.b for t in self.terms], dtype=np.float64),
        )

    # --------------------------------------------------------------- export
    def sympy(self):
        """``P`` as a sympy expression in ``ZETA`` (zeta) and ``ZD`` (max(dzeta, 0))."""
        return sympy.Add(
            *[sympy.Float(c, 15) * t.sympy()
              for c, t in zip(self.coefficients, self.terms, strict=True)]
        )

    def latex(self, digits=4):
        """LaTeX of ``F`` for ``zeta > 0``, in law order.

        ``\\dot\\zeta_+`` stands for ``max(dzeta, 0)``.
        """
        out = []
        for c, t in zip(self.coefficients, self.terms, strict=True):
            mant, _, exp = f"{abs(c):.{digits - 1}e}".partition("e")
            num = mant if int(exp) == 0 else rf"{mant} \cdot 10^{{{int(exp)}}}"
            sym = sympy.latex(t.sympy(), symbol_names=_LATEX_NAMES)
            out.append(("-" if c < 0 else "+") + rf" {num}\,{sym}")
        text = " ".join(out)
        return text[2:] if text.startswith("+ ") else text
