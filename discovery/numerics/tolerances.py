"""Integrator tolerances, shared by both systems' integrators."""

import functools
from dataclasses import dataclass

import numpy as np

from .._api._validate import Real, check
from ..errors import InputError

__all__ = ["Tolerances", "FREE_FLIGHT", "CONTACT"]

#: the vibro-impact kernel's free-flight paths (:attr:`Tolerances.free_flight`)
FREE_FLIGHT = ("closed", "integrate")
#: the vibro-impact kernel's contact paths (:attr:`Tolerances.contact`)
CONTACT = ("closed", "integrate")


@dataclass(frozen=True)
class Tolerances:
    """Integrator settings.

    Parameters
    ----------
    rtol : float
        Relative tolerance of the embedded error estimate.
    atol_scale : float
        Absolute tolerance as a multiple of ``rtol`` times the scenario's
        characteristic displacement / velocity (see :meth:`Scenario.scales`).
    max_steps : int
        Step budget per call.
    hmax_fraction : float
        Largest step as a fraction of the drive period (also bounds how brief a
        contact can be and still be seen between step ends).
    free_flight : {"closed", "integrate"}
        The vibro-impact kernel's free flights: ``"closed"`` (default) advances them in
        closed form to the next onset, found as the first root of the exact penetration
        (supports without a cubic term; otherwise the integrator's steps), and integrates
        only the contact; ``"integrate"`` takes the integrator's steps throughout (the
        cross-check path).  Ueda's oscillators ignore it.
    contact : {"closed", "integrate"}
        The vibro-impact kernel's loading and unloading phases: ``"closed"`` (default)
        advances them in closed form to the next event, sensitivities included (a linear
        law, ``k z + c zd``, with nothing else acting during the contact; otherwise the
        integrator's steps); ``"integrate"`` takes the integrator's steps (the
        cross-check path).  Only with ``free_flight="closed"``: ``free_flight="integrate"``
        integrates the contacts too.  Ueda's oscillators ignore it.
    """

    rtol: float = 1e-9
    atol_scale: float = 1e-3
    max_steps: int = 2_000_000
    hmax_fraction: float = 0.02
    free_flight: str = "closed"
    contact: str = "closed"

    @classmethod
    @functools.cache
    def default(cls):
        """The default settings, made and checked once (a frozen object, shared): what a
        simulation uses when it is given none."""
        return cls()

    def __post_init__(self):
        for name, spec in (
            ("rtol", Real(0, 1, open_low=True)),
            ("atol_scale", Real(0, open_low=True)),
            ("max_steps", Real(1, integer=True)),
            ("hmax_fraction", Real(0, 1, open_low=True)),
        ):
            check(f"Tolerances: {name}", getattr(self, name), spec)
        if not (0 < self.rtol < 1):
            raise InputError(f"rtol must be in (0, 1), got {self.rtol!r}")
        if not self.atol_scale > 0:
            raise InputError(f"atol_scale must be > 0, got {self.atol_scale!r}")
        if not (isinstance(self.max_steps, int | np.integer) and self.max_steps > 0):
            raise InputError(f"max_steps must be a positive integer, got {self.max_steps!r}")
        if not (0 < self.hmax_fraction <= 1):
            raise InputError(f"hmax_fraction must be in (0, 1], got {self.hmax_fraction!r}")
        if self.free_flight not in FREE_FLIGHT:
            raise InputError(
                f"free_flight must be one of {', '.join(FREE_FLIGHT)}, got {self.free_flight!r}"
            )
        if self.contact not in CONTACT:
            raise InputError(f"contact must be one of {', '.join(CONTACT)}, got {self.contact!r}")

    def atol(self, scale):
        """Absolute tolerances ``rtol * atol_scale * scale`` for states of size ``scale``."""
        return self.rtol * self.atol_scale * np.asarray(scale, dtype=float)

    @property
    def atol_variational(self):
        """Absolute tolerance of the variational (tangent) equations: ``rtol * atol_scale``
        (tangent vectors are normalised)."""
        return self.rtol * self.atol_scale

    def as_dict(self):
        return {
            "rtol": self.rtol,
            "atol_scale": self.atol_scale,
            "max_steps": self.max_steps,
            "hmax_fraction": self.hmax_fraction,
            "method": "dopri5+events",
            "free_flight": self.free_flight,
            "contact": self.contact,
        }
