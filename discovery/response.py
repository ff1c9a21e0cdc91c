"""The simulated response of a law: steady state and exact impulse.

To compare with a measurement, the exact impulse is "sampled like the
measurement" with :meth:`~discovery.impulse.Impulse.resampled_like`: evaluated at
the measurement's sample times since its onset, and its support taken with the
measurement's contact threshold.
"""

from dataclasses import dataclass

from ._validate import Real, params
from .dynamics import Tolerances
from .dynamics.steady_state import steady_state
from .impulse import Impulse, impulse_from_steady_state
from .law import ForceLaw
from .scenario import Scenario

__all__ = ["Response", "response"]


@dataclass(frozen=True)
class Response:
    """A law's steady state and its impulse (``None`` if nonperiodic or no contact)."""

    steady: object
    impulse: Impulse | None

    @property
    def regime(self):
        return self.steady.regime

    def like(self, measured):
        """The impulse sampled like ``measured`` (``None`` if there is none)."""
        if self.impulse is None:
            return None
        return self.impulse.resampled_like(measured)


@params(
    scenario=Scenario,
    law=ForceLaw,
    tolerances=(Tolerances, None),
    points_per_period=Real(16, integer=True),
)
def response(scenario, law, *, tolerances=None, points_per_period=2000, **steady_kwargs):
    """Steady state of ``law`` in ``scenario`` and its exact impulse.

    Parameters
    ----------
    scenario : Scenario
    law : ForceLaw
    tolerances : Tolerances, optional
    points_per_period : int
        Resolution of the exact impulse.
    **steady_kwargs
        Passed to :func:`~discovery.dynamics.steady_state.steady_state`.

    Returns
    -------
    Response
    """
    ss = steady_state(scenario, law, tolerances=tolerances, **steady_kwargs)
    if not ss.periodic:
        return Response(ss, None)
    return Response(ss, impulse_from_steady_state(scenario, law, ss, points_per_period, tolerances))
