"""Compiled event-driven Dormand–Prince 5(4) integrator for the two-body system (the
method's stages, error norm, dense output and step control are shared with every system:
:mod:`discovery.numerics._dopri`).

The right-hand side is smooth inside each *contact mode*; the mode changes only
at located events, and no step straddles an event: a step in which a switching
function changes sign is re-taken with its length cut to the root (found on the
dense output), so every step integrates one smooth vector field.

Modules, each named for what it holds: :mod:`.codes` (the modes, the events' kinds, the
parameter vector's slots, the compile options), :mod:`.forces` (the law's force in each
mode, its partials, the right-hand side and one step), :mod:`.events` (the switching
functions, the first crossing over a step, the event's record), :mod:`.sensitivities`
(the variational equations through the steps and the saltation at the events),
:mod:`.flight` (the free flight in closed form), :mod:`.contact_modes` (the contact modes'
modal decomposition) and :mod:`.contact` (a contact phase in closed form), :mod:`.loop`
(:func:`~.loop.integrate`, one run) and :mod:`.entries` (the other entries called from
Python: :func:`~.entries.strobe`, the work arrays, the contact modes' set-up, the checks).

Modes
    FREE     no force (``zeta <= 0``)
    LOAD     ``F = P(zeta, dzeta)``       (``zeta > 0``, ``dzeta > 0``)
    UNLOAD   ``F = P(zeta, 0)``           (``zeta > 0``, ``dzeta <= 0``)
    CLIPPED  ``F = 0`` with ``zeta > 0``  (``P`` would be adhesive, < 0)

Switching functions ``h`` are written so that an event fires when ``h`` goes from
``>= 0`` to ``< 0`` over a step (direction built in):

    FREE:    onset       h = -zeta
    LOAD:    loss        h = zeta,  unload  h = dzeta,   release h = P(zeta, dzeta)
    UNLOAD:  loss        h = zeta,  reload  h = -dzeta,  release h = P(zeta, 0)
    CLIPPED: loss        h = zeta,  resume  h = -P(zeta, max(dzeta, 0))

Inside a mode the force is extended smoothly past the switching surface (odd
extension of fractional powers) because Runge–Kutta stages may sample slightly
beyond it.

Detection (per accepted step, see :func:`~.events._first_crossing`): each function is
sampled on the dense output at ``theta = 0, 1/3, 2/3, 1``; an event needs a value
``> 0`` before one ``< 0``.  Right after an event a function may start a hair on
the wrong side (the re-taken step ends within rounding of the surface, not on its
side): it is then neither skipped nor fired at once, but the point where the flow
leaves the surface is searched for, so a contact loss followed by a re-contact
inside the next step is seen (and a function that starts across but comes back is
not fired).  In the free and clipped modes the contact surface is also checked at
the interior extremum of ``zeta`` (a graze between samples).  Mode switches that
hardly advance time (zero-length ones, or over a thousand events in a row each
within ``1e-3 hmax`` of the last) stop the run as chattering.

Free flight: by default (``p[P_FLIGHT] = 1``, :attr:`Tolerances.free_flight` ``"closed"``)
the free mode is not stepped: the flight is advanced in closed form to the first root of
the exact penetration, bracketed by a proven bound (:func:`~.flight._flight`).  Supports
with a cubic term, ``k1 <= 0`` or ``c1 < 0``, and a start across the surface that is not
closing take the integrator's steps, as does every free flight with ``p[P_FLIGHT] = 0``
(the cross-check path).

Contact: by default (``p[P_CONTACT] = 1``, :attr:`Tolerances.contact` ``"closed"``, only
with closed-form flights) a linear law's loading and unloading phases (``F = k z + c zd``,
nothing else acting during the contact) are not stepped either: each is advanced by its
modal solution to the first root of its switching functions, bracketed by a proven bound
(:func:`~.contact._contact`).  Other laws, the clipped mode, a mode whose eigenvectors are
ill-conditioned, a start across a switching surface, a law coefficient's sensitivities in
a mode with a zero eigenvalue (``k1 = 0``) and every contact with ``p[P_CONTACT] = 0`` take
the integrator's steps; the sensitivities follow the closed form too.

Compilation: numba inlines an ``inline="always"`` function in its own IR and types the
body again at every call site, so a chain of inlined functions costs compile time by the
product of their call sites.  Only the leaves called at every Runge-Kutta stage (the force
law, the right-hand side, the shared Dormand-Prince blocks) are inlined; the step, the
switching functions, the dense-output probe and the event record are compiled once each
and called (a call per step or per event, not per stage): a cold compile takes about 30 s
on two cores instead of 160 s with everything inlined, at the same run time (``bench/``).
Those calls pass their arrays borrowed: every function that allocates nothing is compiled
without numba's reference counting (:data:`~.codes.borrowed_njit`), :func:`~.loop.integrate`
included: its callers make the work arrays (:func:`~.entries.work_arrays`, kept from run to
run) and the contact modes (:func:`~.entries.set_up_modes`) and pass them in.  With the
counts, their atomic increments and decrements took about half of a period's time
(sampled); without them the arithmetic is the same, bit for bit.

The entries called from Python are :func:`~.loop.integrate`, :func:`~.entries.strobe`,
:func:`~.entries.work_arrays`, :func:`~.entries.set_up_modes` and the small checks; none
calls :func:`~.loop.integrate` with a constant argument: LLVM then inlines the loop into the
caller and optimises it again (:func:`~.entries.strobe` took 12 s of the cold compile that
way, 2 s with its constants passed in).  Their arguments come in tuples (the law ``(p,
coef, ea, eb, br)``, the step control, the outputs, the work arrays: see
:func:`~.loop.integrate`), which numba passes as their fields, at the cost of the separate
arguments; no kernel function takes more than 12.

Numba's cache: a cached function is stamped with its own source file only, and holds every
function it calls or inlines from the other modules.  Importing the package therefore
checks the sources of all its modules and of the shared Dormand-Prince blocks against the
stamp their cache was made with, and drops the cache when any changed
(:func:`discovery._startup._compile.refresh`): an edit to one module recompiles the whole kernel, as
it did when the kernel was one file.
"""

from ...._startup._compile import refresh

refresh("vibro-impact")
