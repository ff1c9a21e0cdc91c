"""A refit's springs scanned for a lower basin: one mechanism for ``discover``'s refinements
and ``explain``'s refits.

Over a record's transient, or a subharmonic's several contacts a period, the contact
sequence changes with the spring, so the sum of squares has basins, and a least-squares fit
stops in the one its start lies in.  A refit that ends inconsistent is scanned along its
springs (the loading branch's elastic terms scaled together); where one scanned spring's sum
of squares is :data:`RESCAN_DROP` below the refit's end, the caller refits from there and
keeps the better of the two.
"""

import numpy as np

from ..model.law import ForceLaw

__all__ = ["RESCAN_DROP", "WIDE_SPRING_SCAN", "springs_scaled", "lower_basin"]

#: the share by which a scanned spring's sum of squares must fall below a refit's end for
#: the refit to start again from it.  Nearer, the scan meets the roughness of a transient's
#: squares (1.5-7 % at +-1-2 % of the spring on the bench record's refits, whose refits
#: from there ended where they began)
RESCAN_DROP = 0.1

#: the spring factors scanned round a refinement of a regression's law: the penetration's
#: noise attenuates the regression's slopes, so its spring can be tens of percent soft.  On
#: a random subharmonic machine at 2 % noise the regression's spring was 45 % soft and its
#: refinement stopped 35 % soft (its penetration inconsistent); x 1.45 had a sum of
#: squares half the refinement's end, and a refit from there reached the true law
WIDE_SPRING_SCAN = (0.7, 0.85, 1.2, 1.45, 1.75, 2.1)


def springs_scaled(model, factor):
    """``model`` (a law, or an explained model with its law) with the loading branch's
    elastic terms scaled by ``factor``."""
    if isinstance(model, ForceLaw):
        return model.with_springs_scaled(factor)
    return model.with_law(model.law.with_springs_scaled(factor))


def lower_basin(model, factors, squares):
    """``(factor, scaled model, its squares, the model's squares)`` of the scanned spring
    with the lowest sum of squares (``squares(model)``, inf where a record has no steady
    cycle) when that is :data:`RESCAN_DROP` below the model's own; else None."""
    base = squares(model)
    scan = [springs_scaled(model, f) for f in factors]
    values = [squares(m) for m in scan]
    i = int(np.argmin(values))
    if not values[i] < (1.0 - RESCAN_DROP) * base:
        return None
    return factors[i], scan[i], values[i], base
