"""The consistency rule: a criterion within ``max(f x floor, floor + 3 sd) + 0.005`` of its
noise floor, for I2, I4 and (with positions) I5; an I2 limit that would pass a law without
force decides nothing.
"""

__all__ = [
    "consistency_limits",
    "CONSISTENCY_CRITERIA",
    "CONSISTENCY_SPREAD",
    "CONSISTENCY_FACTOR",
    "CONSISTENCY_FACTORS",
    "CONSISTENCY_SLACK",
    "NO_FORCE_I2",
]

CONSISTENCY_CRITERIA = ("I2", "I4", "I5")
"""The criteria the rule holds to their limits: I2 (the force history), I4 (the contact
support) and, where positions are recorded, I5 (the penetration over the contacts,
:mod:`~discovery.vibroimpact.verify.motion`); a criterion the record cannot give is not
held."""
CONSISTENCY_FACTOR = 2.0
"""The factor on the floor of the force criteria (I2, I4)."""
CONSISTENCY_FACTORS = {"I2": CONSISTENCY_FACTOR, "I4": CONSISTENCY_FACTOR, "I5": 1.25}
"""The factor on each criterion's floor.  The force criteria keep a factor 2: the force is
compared after averaging and alignment, and a true law's I2 sits up to 1.6 times its floor
on independent records (processing, sub-sample onsets).  The penetration's I5 is white
position noise compared sample by sample: a true law's I5 is its floor within 10 % on every
corpus record (0.91-1.06), with a spread over the replicates of a few per cent, so a factor
2 would pass a law whose penetration is off by nearly the noise itself (a spring four times
too soft behind unloading damping: I5 1.8 times its floor)."""
CONSISTENCY_SLACK = 0.005  # numerical agreement of two simulators, sampling effects
CONSISTENCY_SPREAD = 3.0
"""The spread term's factor: a limit at least the floor plus this many standard deviations
of the criterion over the floor's replicates."""

NO_FORCE_I2 = 1.0
"""I2 of a law without force (the relative L1 distance of the record's force from zero).
An I2 limit this high or higher decides nothing (it is undefined, like an infinite floor):
the law's own noisy replicates score as far from its force as a zero force does (survey
draw 39: a short contact whose noise-free runs from the drawn block states miss each
other's timing, floor 0.97), and every law with a contact would pass."""


def consistency_limits(floor, sd=None):
    """``{criterion: limit}`` of the consistency rule for a noise floor: ``max(f x floor,
    floor + 3 sd) + 0.005`` with ``f`` the criterion's :data:`CONSISTENCY_FACTORS` (2 for
    I2 and I4, 1.25 for I5) and ``sd`` the spread of the criterion over the floor's
    replicates (when known).  The spread term matters for I4: the contact support's edges
    move with the noise, so the true law's I4 is spread like a half-normal whose 99th
    percentile is about 3.2 times its mean; twice the mean alone rejected the true law in
    about one record in ten."""
    sd = sd or {}
    lim = {
        k: max(CONSISTENCY_FACTORS[k] * floor[k], floor[k] + CONSISTENCY_SPREAD * sd.get(k, 0.0))
        + CONSISTENCY_SLACK
        for k in CONSISTENCY_CRITERIA
        if k in floor
    }
    if lim.get("I2", 0.0) >= NO_FORCE_I2:  # a law without force would pass: no test
        lim["I2"] = float("inf")
    return lim
