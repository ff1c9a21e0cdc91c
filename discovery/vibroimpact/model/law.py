"""Contact-force laws ``F(zeta, dzeta)`` built from terms ``zeta^a * zd^b``.

A :class:`ForceLaw` is a sum ``P(zeta, zd) = sum_i c_i * zeta^a_i * zd^b_i`` with
``zd = max(dzeta, 0)``.  The contact force is::

    F(zeta, dzeta) = max(P(zeta, max(dzeta, 0)), 0)   if zeta > 0
                   = 0                                  otherwise

so the paper's conditions (3) (no force without contact) and (5) (negative
penetration velocity has no effect) hold by construction, and the force is never
adhesive (4): where ``P`` would be negative the bodies exert no force.

Two optional extensions give the law an unloading branch of its own (``dzeta <= 0``),
for machines the paper's model does not describe:

* *unloading terms* ``d_j zeta^a_j dzeta^b_j`` (``b_j > 0``) act only while the bodies
  separate, at the signed velocity, so they lower the force (damping that also acts
  while unloading, as in a Kelvin-Voigt contact).  This departs from the paper's
  condition (5) on purpose: a real contact (wet sand, a rubber pad) can dissipate energy
  in restitution too, and then the force reaches zero before the penetration does;
* a *permanent set* ``s`` in [0, 0.95]: plastic indentation (Walton-Braun).  Unloading
  follows ``P(u, 0)`` at ``u = (zeta - s zeta_max) / (1 - s)``, ``zeta_max`` the contact's
  largest penetration: continuous at ``zeta_max`` and zero at the residual penetration
  ``s zeta_max`` (for a linear law: unloading stiffness ``k / (1 - s)``).  A contact that
  reloads before it ends climbs back along that line up to ``zeta_max``.  The set is
  recovered between impacts (each contact starts from the undeformed surface).

A third, ``impact_scaled``, divides every velocity term (loading and unloading) by the
approach velocity ``v0`` of the impact under way (the penetration rate at the contact's
onset, a per-contact memory like ``zeta_max``): the Lankarani-Nikravesh and Flores contact
models, whose hysteresis damping ``lambda = k r(e) / v0`` is set per impact
(:mod:`~discovery.vibroimpact.model.contact_models`).  Text part ``"; scale: v0"``.

Text form: ``"2e8*z + 1e7*zd; unloading: 4e6*zd; set: 0.2"``.  Units are
SI: ``zeta`` [m], ``dzeta`` [m/s], ``F`` [N]; a coefficient of ``z^a*zd^b`` has
units N m^-a (m/s)^-b.
"""

from dataclasses import dataclass, replace
from fractions import Fraction
from functools import lru_cache

import numpy as np

from ..._api._validate import Real, check
from ..._files._jsonable import reads_document
from ...errors import InputError
from ._lawgrammar import MAX_EXPONENT, parse_law_terms

__all__ = ["Term", "ForceLaw"]  # and ZETA, ZD, the sympy symbols (made on first use)


@lru_cache(maxsize=1)
def _symbols():
    """``(ZETA, ZD)``, the sympy symbols (sympy is imported on first use: ``vidi --help``
    and reading a law do not need it)."""
    import sympy

    return sympy.symbols("zeta zd", nonnegative=True)


def __getattr__(name):
    if name in ("ZETA", "ZD"):
        return _symbols()[name == "ZD"]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


FASTEST_CONTACT = 2 * np.pi * 1e7  # contact rate x drive period: a contact of 1e-7 periods
_MAX_SET = 0.95  # largest permanent-set fraction (1 would be a rigid-plastic contact)
_LATEX = (r"\zeta", r"\dot{\zeta}_{+}")  # names of (ZETA, ZD) in LaTeX
_LATEX_UNLOADING = (r"\zeta", r"|\dot{\zeta}|")


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
        check("Term: exponent a", self.a, Real(0, MAX_EXPONENT))
        check("Term: exponent b", self.b, Real(0, MAX_EXPONENT))
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

    def __call__(self, zeta, zd):
        """Evaluate ``zeta^a * zd^b`` (arrays broadcast; inputs must be >= 0)."""
        zeta = np.asarray(zeta, dtype=float)
        zd = np.asarray(zd, dtype=float)
        return np.power(zeta, self.a) * np.power(zd, self.b)

    def sympy(self):
        """The term as a sympy expression in ``ZETA`` and ``ZD``."""
        import sympy

        zeta, zd = _symbols()
        return zeta ** sympy.nsimplify(self.a) * zd ** sympy.nsimplify(self.b)

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
    unloading: tuple = ()
    unloading_coefficients: tuple = ()
    permanent_set: float = 0.0
    impact_scaled: bool = False

    def __post_init__(self):
        for name in ("terms", "coefficients", "unloading", "unloading_coefficients"):
            check(f"ForceLaw: {name}", getattr(self, name), (tuple, list))
        for term in (*self.terms, *self.unloading):
            check("ForceLaw: each term", term, Term)
        for c in (*self.coefficients, *self.unloading_coefficients):
            check("ForceLaw: each coefficient", c, Real())
        check("ForceLaw: permanent_set", self.permanent_set, Real(0, _MAX_SET))
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
        tiny = [c for c in coefs if c != 0.0 and abs(c) < np.finfo(float).tiny]
        if tiny:
            raise InputError(
                f"force-law coefficient {tiny[0]:.3g} is below the smallest normal "
                f"number ({np.finfo(float).tiny:.3g}): no arithmetic on it is exact;"
                " give the coefficient in N, m and s (e.g. 2.06e8*z)"
            )
        object.__setattr__(self, "terms", terms)
        object.__setattr__(self, "coefficients", coefs)
        uterms = tuple(self.unloading)
        ucoefs = tuple(float(c) for c in self.unloading_coefficients)
        if len(uterms) != len(ucoefs):
            raise InputError(f"{len(uterms)} unloading terms but {len(ucoefs)} coefficients")
        if len(set(uterms)) != len(uterms):
            raise InputError("a force law lists the same unloading term twice; merge them")
        if any(t.b == 0 for t in uterms):
            raise InputError(
                "an unloading term must depend on the velocity (e.g. 'zd' or "
                "'z*zd'), so the force is continuous when the motion reverses"
            )
        if not all(np.isfinite(ucoefs)):
            raise InputError("unloading coefficients must be finite numbers")
        rho = self.permanent_set
        if (
            isinstance(rho, bool)
            or not isinstance(rho, int | float | np.number)
            or not (0.0 <= float(rho) <= _MAX_SET)
        ):
            raise InputError(
                f"the permanent set must be a number in [0, {_MAX_SET}] (the "
                f"residual share of the largest penetration); got {rho!r}"
            )
        object.__setattr__(self, "unloading", uterms)
        object.__setattr__(self, "unloading_coefficients", ucoefs)
        object.__setattr__(self, "permanent_set", float(rho))
        if not isinstance(self.impact_scaled, bool | np.bool_):
            raise InputError(f"impact_scaled must be True or False; got {self.impact_scaled!r}")
        object.__setattr__(self, "impact_scaled", bool(self.impact_scaled))

    # ----------------------------------------------------------- construction
    @classmethod
    def parse(cls, text):
        """Law from text like ``"2.06e8*z + 1.28e7*zd"`` (like terms are summed), with
        optional parts ``"; unloading: 4e6*zd"``, ``"; set: 0.2"`` and ``"; scale: v0"``
        (velocity terms over each impact's approach velocity)."""
        if not isinstance(text, str):
            return cls(*cls._merged(text))  # the grammar's own "must be text" error
        main, *parts = text.split(";")
        extra = {}
        for part in parts:
            key, sep, value = part.partition(":")
            key = key.strip().lower()
            if not sep or key not in ("unloading", "set", "scale") or key in extra:
                raise InputError(
                    f"force law {text!r}: after ';' give 'unloading: <terms>', "
                    "'set: <fraction>' or 'scale: v0' once each, e.g. '2e8*z + 1e7*zd; "
                    "unloading: 4e6*zd; set: 0.2'"
                )
            extra[key] = value.strip()
        terms, coefs = cls._merged(main)
        uterms, ucoefs = cls._merged(extra["unloading"]) if "unloading" in extra else ((), ())
        rho = 0.0
        if "set" in extra:
            try:
                rho = float(extra["set"])
            except ValueError:
                raise InputError(
                    f"force law {text!r}: 'set:' needs a number in [0, "
                    f"{_MAX_SET}], got {extra['set']!r}"
                ) from None
        if "scale" in extra and extra["scale"].lower() != "v0":
            raise InputError(
                f"force law {text!r}: 'scale:' takes only 'v0' (velocity terms divided by "
                f"each impact's approach velocity), got {extra['scale']!r}"
            )
        return cls(terms, coefs, uterms, ucoefs, rho, "scale" in extra)

    @staticmethod
    def _merged(text):
        merged = {}
        for c, a, b in parse_law_terms(text):
            t = Term(a, b)
            merged[t] = merged.get(t, 0.0) + c
        return tuple(merged), tuple(merged.values())

    @classmethod
    @reads_document
    def from_dict(cls, coefficients):
        """Law from ``{term name: coefficient}``."""
        terms = tuple(Term.parse(k) for k in coefficients)
        return cls(terms, tuple(float(v) for v in coefficients.values()))

    def with_coefficients(self, values):
        """The same terms with new coefficients (sequence of floats); the unloading branch
        is kept."""
        return replace(self, coefficients=tuple(float(v) for v in values))

    def with_springs_scaled(self, factor):
        """The law with its loading branch's elastic terms (those without a velocity
        factor) scaled by ``factor``; the damping terms and the unloading branch kept."""
        pairs = zip(self.terms, self.coefficients, strict=True)
        return self.with_coefficients([c * factor if t.b == 0 else c for t, c in pairs])

    def with_unloading(self, terms=None, coefficients=None, permanent_set=None):
        """The same loading branch with another unloading branch (None keeps a part)."""
        return replace(
            self,
            unloading=self.unloading if terms is None else tuple(terms),
            unloading_coefficients=self.unloading_coefficients
            if coefficients is None
            else tuple(coefficients),
            permanent_set=self.permanent_set if permanent_set is None else permanent_set,
        )

    @property
    def has_memory(self):
        """True when the force depends on a contact's history (a permanent set's largest
        penetration, an impact-scaled law's approach velocity), which the state does not
        hold."""
        return self.permanent_set > 0 or self.impact_scaled

    def at_impact(self, v0):
        """The plain law of one impact of an impact-scaled law: every velocity term's
        coefficient divided by the approach velocity ``v0`` [m/s] (the law itself when it
        is not scaled)."""
        if not self.impact_scaled:
            return self
        v0 = float(v0)
        if not (np.isfinite(v0) and v0 > 0):
            raise InputError(f"an impact's approach velocity must be > 0; got {v0!r}")
        return replace(
            self,
            coefficients=tuple(
                c / v0 if t.b > 0 else c for c, t in zip(self.coefficients, self.terms, strict=True)
            ),
            unloading_coefficients=tuple(c / v0 for c in self.unloading_coefficients),
            impact_scaled=False,
        )

    @property
    def has_unloading_branch(self):
        """True when unloading is not the paper's ``P(zeta, 0)`` (unloading terms or a set)."""
        return bool(self.unloading) or self.permanent_set > 0

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

        def exact(c):
            num = repr(abs(c))  # shortest text that reads back exactly
            return num[:-2] if num.endswith(".0") else num

        return self._text(exact, repr)

    def format(self, digits=6):
        """Readable text with ``digits`` significant digits (``to_text`` is exact)."""
        return self._text(lambda c: f"{abs(c):.{digits}g}", lambda r: f"{r:.{digits}g}")

    def _text(self, number, fraction):
        def poly(terms, coefs):
            out = [
                f"{'-' if c < 0 else '+'} {number(c)}*{t.name}"
                for c, t in zip(coefs, terms, strict=True)
            ]
            text = " ".join(out)
            return text[2:] if text.startswith("+ ") else "-" + text[2:]

        text = poly(self.terms, self.coefficients)
        if self.unloading:
            text += "; unloading: " + poly(self.unloading, self.unloading_coefficients)
        if self.permanent_set:
            text += f"; set: {fraction(self.permanent_set)}"
        if self.impact_scaled:
            text += "; scale: v0"
        return text

    def __str__(self):
        return self.format()

    @property
    def has_elastic_term(self):
        """True when a term is the penetration's alone (``zeta^a``, ``b = 0``): without one
        every term carries the rate and the law has no force at rest in contact."""
        return any(t.b == 0 for t in self.terms)

    @property
    def has_jump(self):
        """True when the force jumps at contact onset (a term ``zd^b`` with ``a = 0``)."""
        return any(t.a == 0 for t in self.terms)

    def contact_defects(self):
        """Why this law is not a contact law, as short reasons (empty when it is one).

        A contact pushes the bodies apart by its elastic branch ``F(zeta, 0)``: a law
        without an elastic term with a positive coefficient (``F(zeta, 0) = 0``: no spring)
        only damps, and its unloading never returns the stored energy.  Its dissipative
        terms (``zd^b``, ``b > 0``) must not have negative coefficients: a damper that
        pulls harder the faster the bodies meet is not dissipation.  A record's noise can
        make such a law fit as well as the truth; the ranking puts it last, with these
        reasons, unless the user asks for it.
        """
        out = []
        if not any(t.b == 0 and c > 0 for t, c in zip(self.terms, self.coefficients, strict=True)):
            out.append("no spring: F(zeta, 0) = 0 (no elastic term with a positive coefficient)")
        neg = [
            t.name for t, c in zip(self.terms, self.coefficients, strict=True) if t.b > 0 and c < 0
        ]
        if neg:
            out.append(
                f"dissipative term{'s' if len(neg) > 1 else ''} {', '.join(neg)} with "
                "a negative coefficient"
            )
        return out

    # ------------------------------------------------------------ evaluation
    def polynomial(self, zeta, zd):
        """Raw ``P(zeta, zd)`` without the contact conditions (inputs >= 0)."""
        zeta = np.asarray(zeta, dtype=float)
        zd = np.asarray(zd, dtype=float)
        out = np.zeros(np.broadcast(zeta, zd).shape)
        for c, t in zip(self.coefficients, self.terms, strict=True):
            out = out + c * t(zeta, zd)
        return out

    def check_physical(self, scenario, what="law", *, dissipative_below=False):
        """Refuse a law no machine could have (one clear line, :class:`InputError`).

        On the box ``0 < zeta <= x``, ``0 <= zd <= 4 v`` (``x, v`` the scenario's motion
        scales, :meth:`Scenario.scales`): the law must push the bodies apart somewhere
        (else the moulding falls through the grid and no steady state exists), have no
        negative stiffness (``P(zeta, 0) < 0`` everywhere: the unloading branch of
        condition (5) would pull the bodies together; damping alone, a template whose
        stiffness a landscape varies, passes), and satisfy the paper's condition (6), dissipativity
        ``P(zeta, zd) >= P(zeta, 0)`` (damping never feeds energy into an impact).
        Conditions (3)-(5) hold by construction.  With ``dissipative_below`` condition (6)
        is left to :meth:`dissipative_rate` (a fit's rival certified on the rates it was
        fitted on, which an operating point may or may not leave).
        """
        if not any(self.coefficients):
            raise InputError(
                f"{what} '{self}' has no non-zero coefficient; give a law such "
                "as '2.06e8*z + 1.28e7*zd'"
            )
        if self.impact_scaled:  # judged as the impact at the motion's velocity scale
            return self.at_impact(scenario.scales()[1]).check_physical(
                scenario, what, dissipative_below=dissipative_below
            )
        x, v = scenario.scales()
        Z, V = x, 4.0 * v
        zz, vv = np.meshgrid(np.linspace(Z / 64, Z, 64), np.linspace(0.0, V, 65))
        P = self.polynomial(zz, vv)
        if not np.max(P) > 0:
            raise InputError(
                f"{what} '{self}' never pushes the bodies apart (P <= 0 for every "
                f"penetration up to {Z:.3g} m and velocity up to {V:.3g} m/s): the moulding "
                "would fall through the grid; a contact law needs a positive stiffness term "
                "such as 2e8*z"
            )
        elastic = self.polynomial(zz, np.zeros_like(vv))
        if not np.max(elastic) > 0 and np.min(elastic) < 0:
            raise InputError(
                f"{what} '{self}' has a negative stiffness: F(zeta, 0) < 0 for every "
                f"penetration up to {Z:.3g} m, an elastic force that pulls the bodies "
                "together, so once they stop nothing pushes them apart (the unloading "
                "follows F(zeta, 0), conditions (4)-(5)); make the stiffness positive, "
                "e.g. 2.06e8*z"
            )
        if any(c < 0 for c in self.unloading_coefficients):
            raise InputError(
                f"{what} '{self}' has a negative unloading coefficient: it would "
                "push the bodies apart harder while they separate (energy fed "
                "into the rebound); make the unloading terms non-negative"
            )
        D = P - self.polynomial(zz, np.zeros_like(vv))
        worst = np.unravel_index(int(np.argmin(D)), D.shape)
        if D[worst] < -1e-9 * float(np.max(np.abs(P))) and not dissipative_below:
            raise InputError(
                f"{what} '{self}' breaks the paper's condition (6), dissipativity: F(zeta, zd) "
                f"< F(zeta, 0) at zeta = {zz[worst]:.3g} m, zd = {vv[worst]:.3g} m/s (damping "
                "that feeds energy into the impact); make the velocity terms non-negative"
            )
        # a contact far shorter than any step the drive period allows cannot be simulated
        m = scenario.m1 * scenario.m2 / (scenario.m1 + scenario.m2)
        with np.errstate(over="ignore", divide="ignore", invalid="ignore"):  # a tiny mass: inf
            rate = max(
                float(np.sqrt(np.max(self.polynomial(zz, np.zeros_like(vv)) / zz) / m)),
                float(np.max(D / np.maximum(vv, 1e-300)) / m),
            )
        if rate * scenario.period > FASTEST_CONTACT:
            raise InputError(
                f"{what} '{self}' is too stiff for this machine: a contact would last about "
                f"{scenario.period * 2 * np.pi / min(rate * scenario.period, 1e300):.2g} s, "
                f"under 1e-7 of the drive period {scenario.period:.3g} s, which no simulation "
                "resolves; check the coefficients' units (N/m, N s/m) and the scenario's masses"
            )

    def dissipative_rate(self, scenario, up_to=None):
        """The largest penetration rate [m/s] up to which the paper's condition (6),
        ``P(zeta, zd) >= P(zeta, 0)``, holds for every penetration up to the scenario's
        motion scale (``inf`` when it holds on the whole box: rates up to ``up_to``, by
        default 4 times the velocity scale as in :meth:`check_physical`): the domain a rival
        certified on its record's rates is physical on.  A law scaled by each impact's
        approach velocity is judged at the velocity scale."""
        if self.impact_scaled:
            return self.at_impact(scenario.scales()[1]).dissipative_rate(scenario, up_to)
        x, v = scenario.scales()
        top = 4.0 * v if up_to is None else float(up_to)
        zz, vv = np.meshgrid(np.linspace(x / 64, x, 64), np.linspace(0.0, top, 257))
        P = self.polynomial(zz, vv)
        D = P - self.polynomial(zz, np.zeros_like(vv))
        bad = np.any(D < -1e-9 * max(float(np.max(np.abs(P))), 1e-300), axis=1)
        if not bad.any():
            return float("inf")
        return float(vv[int(np.argmax(bad)) - 1, 0]) if np.argmax(bad) > 0 else 0.0

    def __call__(self, zeta, dzeta, zeta_max=None, v0=None):
        """Contact force ``F(zeta, dzeta)`` [N] with conditions (3)-(5) applied (and the
        law's unloading branch, if it has one: ``zeta_max`` is then the contact's largest
        penetration, default ``zeta`` itself; ``v0`` the impact's approach velocity of an
        impact-scaled law, required for one).

        Parameters
        ----------
        zeta : array_like
            Interpenetration [m].
        dzeta : array_like
            Penetration velocity [m/s] (negative values act as 0).
        """
        if self.impact_scaled:
            if v0 is None:
                raise InputError(
                    f"law '{self}' scales its damping by each impact's approach velocity: "
                    "give v0 (the penetration rate at the contact's onset)"
                )
            return self.at_impact(v0)(zeta, dzeta, zeta_max)
        zeta = np.asarray(zeta, dtype=float)
        dzeta = np.asarray(dzeta, dtype=float)
        zp = np.maximum(zeta, 0.0)
        p = self.polynomial(zp, np.maximum(dzeta, 0.0))
        if self.has_unloading_branch:
            zm = zp if zeta_max is None else np.maximum(np.asarray(zeta_max, float), zp)
            if self.permanent_set:
                # reloading below z_max follows the elastic unloading line (Walton-Braun)
                elastic = self.polynomial(zp, np.zeros_like(zp))
                p = (
                    p
                    - elastic
                    + np.where(zp < zm, self.unloading_force(zp, np.zeros_like(zp), zm), elastic)
                )
            p = np.where(dzeta > 0, p, self.unloading_force(zp, dzeta, zm))
        return np.where(zeta > 0, np.maximum(p, 0.0), 0.0)

    def unloading_force(self, zeta, dzeta, zeta_max):
        """Raw unloading branch (``dzeta <= 0``, before clipping at 0): ``P(u, 0)`` at
        ``u = (zeta - s zeta_max) / (1 - s)`` (negative below the residual penetration)
        plus the unloading terms at the signed velocity (see the module docstring)."""
        zeta = np.asarray(zeta, dtype=float)
        dzeta = np.minimum(np.asarray(dzeta, dtype=float), 0.0)
        s = self.permanent_set
        u = (zeta - s * np.asarray(zeta_max, dtype=float)) / (1.0 - s)
        out = np.where(u > 0, self.polynomial(np.maximum(u, 0.0), np.zeros_like(u)), -1.0)
        for c, t in zip(self.unloading_coefficients, self.unloading, strict=True):
            out = out - c * t(zeta, -dzeta)
        return out

    def kernel_arrays(self):
        """``(coef, a, b, branch)`` float arrays for the compiled integrator: the loading
        terms (branch 0), then the unloading terms (branch 1)."""
        terms = self.terms + self.unloading
        return (
            np.array(self.coefficients + self.unloading_coefficients, dtype=np.float64),
            np.array([t.a for t in terms], dtype=np.float64),
            np.array([t.b for t in terms], dtype=np.float64),
            np.array([0.0] * len(self.terms) + [1.0] * len(self.unloading), dtype=np.float64),
        )

    # --------------------------------------------------------------- export
    def sympy(self):
        """``P`` as a sympy expression in ``ZETA`` (zeta) and ``ZD`` (max(dzeta, 0))."""
        import sympy

        return sympy.Add(
            *[
                sympy.Float(c, 15) * t.sympy()
                for c, t in zip(self.coefficients, self.terms, strict=True)
            ]
        )

    def latex(self, digits=4):
        """LaTeX of ``F`` for ``zeta > 0``, in law order.

        ``\\dot\\zeta_+`` stands for ``max(dzeta, 0)``.
        """
        text = _latex_sum(self.coefficients, self.terms, digits, _LATEX)
        if self.unloading:
            text += r"\quad\text{unloading: } P(\zeta, 0) - " + _latex_sum(
                self.unloading_coefficients, self.unloading, digits, _LATEX_UNLOADING, paren=True
            )
        if self.permanent_set:
            text += rf"\quad\text{{set }} s = {self.permanent_set:.{digits}g}"
        if self.impact_scaled:
            text += r"\quad\text{velocity terms over the impact velocity } v_0"
        return text


def _latex_power(symbol, p):
    """``symbol^p`` in LaTeX, a fractional exponent as a fraction (``\\zeta^{\\frac{3}{2}}``)."""
    f = Fraction(float(p)).limit_denominator(1000)
    if f == 1:
        return symbol
    e = str(f.numerator) if f.denominator == 1 else rf"\frac{{{f.numerator}}}{{{f.denominator}}}"
    return rf"{symbol}^{{{e}}}"


def _latex_term(term, latex_names):
    """A term in LaTeX, penetration first (written here: sympy took 0.2 s a law)."""
    powers = zip(latex_names, (term.a, term.b), strict=True)
    return " ".join(_latex_power(n, p) for n, p in powers if p)


def _latex_sum(coefficients, terms, digits, latex_names, paren=False):
    out = []
    for c, t in zip(coefficients, terms, strict=True):
        mant, _, exp = f"{abs(c):.{digits - 1}e}".partition("e")
        num = mant if int(exp) == 0 else rf"{mant} \cdot 10^{{{int(exp)}}}"
        sym = _latex_term(t, latex_names)
        out.append(("-" if c < 0 else "+") + rf" {num}\,{sym}")
    text = " ".join(out)
    text = text[2:] if text.startswith("+ ") else text
    return rf"\left({text}\right)" if paren and len(out) > 1 else text
