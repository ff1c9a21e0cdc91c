"""The period map of a law with contact memory, on the state that memory extends
(:class:`MemoryMap`), and the Floquet multipliers of an orbit shot on it."""

import numpy as np

from ...numerics.shooting import floquet_multipliers, is_stable

__all__ = ["MemoryMap", "orbit_multipliers"]


class MemoryMap:
    """The period map of a law with contact memory, on the state that memory extends.

    A law with a permanent set unloads from the contact's largest penetration, and a law
    scaled by each impact's approach velocity (Flores, Lankarani-Nikravesh) carries that
    velocity through the contact: where a strobe point falls inside a contact, the next
    period depends on them as much as on the four states.  This map's state is
    ``(w1, v1, w2, v2, zeta_max, v0)``; its Jacobian (finite differences along all six)
    includes how the memory moves the orbit, so Newton closes the memory too and the
    Floquet multipliers are those of the motion.  Where a strobe point is out of contact
    the memory's columns vanish (the next onset resets it) and its multipliers are 0.

    Parameters
    ----------
    pm : StroboscopicMap
        The four-state map of the same scenario and law.
    """

    def __init__(self, pm):
        self.pm = pm
        x, v = pm.scale[0], pm.scale[1]
        self.scale = np.concatenate([pm.scale, [x, v]])

    @property
    def n_calls(self):
        return self.pm.n_calls

    def extend(self, y):
        """The extended state of ``y`` with the memory the four-state map now holds."""
        return np.concatenate([np.asarray(y, dtype=float), [self.pm.zeta_max, self.pm.impact_v0]])

    def advance(self, z, n=1):
        """``Phi^n`` of the extended state ``z``."""
        self.pm.zeta_max, self.pm.impact_v0 = float(z[4]), float(z[5])
        y = self.pm.advance(z[:4], n)
        return self.extend(y)

    def jacobian(self, z, n=1, fz=None):
        """Finite-difference Jacobian of ``Phi^n`` at ``z`` (forward steps of ``1e-6`` of
        each component's scale; the memory's step only ever increases it, so a probe
        never crosses the kernel's 'no onset known' value 0)."""
        fz = self.advance(z, n) if fz is None else fz
        J = np.empty((6, 6))
        for j in range(6):
            zp = np.array(z, dtype=float)
            zp[j] += 1e-6 * self.scale[j]
            J[:, j] = (self.advance(zp, n) - fz) / (1e-6 * self.scale[j])
        return J

    @staticmethod
    def multipliers(J):
        """The four multipliers of largest modulus of the extended map's Jacobian (the
        memory adds at most two, which vanish where a strobe point is out of contact)."""
        mult = floquet_multipliers(J)
        return mult[np.argsort(-np.abs(mult))][:4]


def orbit_multipliers(shot, z, n, J):
    """The Floquet multipliers of the period-``n`` orbit through ``z`` from its Jacobian
    ``J`` on the map ``shot``.  On a :class:`MemoryMap`, an orbit without an onset never
    resets its contact's memory (a contact that never ends): the memory is then a constant
    of the motion, not a state it returns to (its multiplier is exactly 1), and the
    multipliers are the four states' with the memory held."""
    if J is None:
        return floquet_multipliers(None, 4)
    if not isinstance(shot, MemoryMap):
        return floquet_multipliers(J)
    mult = MemoryMap.multipliers(J)
    if not is_stable(mult):
        shot.pm.zeta_max, shot.pm.impact_v0 = float(z[4]), float(z[5])
        if shot.pm.onsets(z[:4], n) == 0:
            return floquet_multipliers(J[:4, :4])
    return mult
