"""The vibro-impact kernel's codes: the contact modes, the events' kinds and the slots of
the parameter vector ``p``, and how the kernel's functions are compiled
(:data:`borrowed_njit`, the shared Dormand-Prince blocks :data:`DP`)."""

from numba import njit

from ...._startup._compile import borrowing_options
from ....numerics._dopri import blocks

# Every kernel function that allocates nothing takes its arrays borrowed: compiled without
# numba's reference counting (``_nrt=False``, where this numba has the option:
# :func:`~discovery._startup._compile.borrowing_options`), a call passes its arrays without an
# atomic increment and decrement of each one's count.  A function that allocates (the work
# arrays, a contact mode's set-up) keeps the counts; numba refuses to compile an allocation in
# a borrowing function.
borrowed_njit = njit(cache=True, **borrowing_options())

# the shared Dormand-Prince blocks for this system's four states (w1, v1, w2, v2)
DP = blocks(4)

FREE, LOAD, UNLOAD, CLIPPED = 0, 1, 2, 3
EV_ONSET, EV_LOSS, EV_UNLOAD, EV_RELOAD, EV_RELEASE, EV_RESUME = 1, 2, 3, 4, 5, 6

# the parameter vector ``p``: the scenario's m1, m2, k1, c1, A, omega, g (0-6), the supports' cubic
# stiffness, the mass fraction shed per impact, the law's permanent-set fraction, one contact state:
# the current contact's largest penetration, and the choice of the free-flight path (``p[P_FLIGHT] =
# 1``: in closed form where it applies, 0: the integrator's steps throughout).  The kernel updates
# m2 and z_max in place (callers pass a copy:
# :func:`~discovery.vibroimpact.dynamics.simulation.kernel_params`).  A law whose velocity terms are
# scaled by each impact's approach velocity (``p[P_VSCALE] = 1``: Lankarani-Nikravesh, Flores)
# divides their coefficients by ``p[P_V0]``, the current contact's penetration rate at its onset (a
# second contact state, set at every onset).  ``p[P_CONTACT] = 1`` advances the contact in closed
# form where it applies (0: the integrator's steps).
P_K3, P_LOSS, P_SET, P_ZMAX, P_FLIGHT, P_V0, P_VSCALE = 7, 8, 9, 10, 11, 12, 13
# ``p[P_V0MIN]``: the smallest approach velocity the velocity terms are divided by
# (:meth:`~discovery.vibroimpact.model.scenario.Scenario.impact_v0_floor`; a contact that begins
# at rest has none).
P_CONTACT, P_V0MIN, N_PARAMS = 14, 15, 16
