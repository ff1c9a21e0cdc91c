"""What the compiled integrators' status codes mean: one table for both systems.

Every compiled run returns a status (:data:`OK` or one of the failures below): the codes
are defined here once, and both integrators import them (the smooth advance of
:mod:`discovery.numerics._dopri` and the vibro-impact kernel, which adds :data:`CHATTER`).
:func:`check` turns a failure into one :class:`~discovery.errors.IntegrationError` line.
"""

from ..errors import IntegrationError

__all__ = [
    "OK",
    "STEP_BUDGET",
    "BLOW_UP",
    "STEP_UNDERFLOW",
    "CHATTER",
    "MESSAGES",
    "message",
    "check",
]

OK, STEP_BUDGET, BLOW_UP, STEP_UNDERFLOW, CHATTER = 0, 1, 2, 3, 4

MESSAGES = {
    STEP_BUDGET: "the step budget was exhausted",
    BLOW_UP: "the solution blew up (non-finite state)",
    STEP_UNDERFLOW: "the step size underflowed",
    CHATTER: "the contact mode switched back and forth without progress (chattering)",
}


def message(status, hints=None):
    """The meaning of ``status``, with the caller's hint for it when it has one."""
    text = MESSAGES.get(status, f"status {status}")
    hint = (hints or {}).get(status)
    return f"{text}{hint}" if hint else text


def check(status, t, what, hints=None):
    """Raise :class:`IntegrationError` ``"{what} stopped at t = ...: {meaning}"`` unless
    ``status`` is :data:`OK`."""
    if status != OK:
        raise IntegrationError(f"{what} stopped at t = {t:.6g}: {message(status, hints)}")
