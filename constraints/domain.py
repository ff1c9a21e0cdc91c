"""The box D = [0, zeta_max] x [0, zd_max] on which the physical conditions are enforced."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .errors import InputError

__all__ = ["Box"]


def _check_positive(name: str, value: object) -> float:
    try:
        number = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a positive finite number, got {value!r}") from None
    if not math.isfinite(number) or number <= 0.0:
        raise InputError(f"{name} must be a positive finite number, got {value!r}")
    return number


@dataclass(frozen=True)
class Box:
    """Rectangular domain ``D = [0, zeta_max] x [0, zd_max]``.

    Parameters
    ----------
    zeta_max : float
        Largest interpenetration ``Z`` [m]; positive and finite.
    zd_max : float
        Largest penetration velocity ``V`` [m/s]; positive and finite.

    Raises
    ------
    ValueError
        If a bound is not a positive finite number (the message names the field and the
        received value).
    """

    zeta_max: float
    zd_max: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "zeta_max", _check_positive("zeta_max", self.zeta_max))
        object.__setattr__(self, "zd_max", _check_positive("zd_max", self.zd_max))

    @classmethod
    def from_data(cls, zeta: ArrayLike, zd: ArrayLike, margin: float = 0.1) -> Box:
        """Smallest box containing the samples, enlarged by a relative margin.

        Parameters
        ----------
        zeta : array_like, shape (n_samples,)
            Interpenetration samples [m]; negative values (no contact) are ignored.
        zd : array_like, shape (n_samples,)
            Penetration-velocity samples [m/s]; negative values are ignored.
        margin : float, optional
            Relative enlargement, ``bound = max(positive part) * (1 + margin)``; >= 0.

        Returns
        -------
        Box

        Raises
        ------
        ValueError
            If the margin is negative or not finite, if the data contain non-finite values,
            or if a variable has no strictly positive sample.
        """
        margin_value = float(margin)
        if not math.isfinite(margin_value) or margin_value < 0.0:
            raise InputError(f"margin must be a finite number >= 0, got {margin!r}")
        bounds = {}
        for name, field, data in (("zeta", "zeta_max", zeta), ("zd", "zd_max", zd)):
            values = np.asarray(data, dtype=float).ravel()
            if not np.all(np.isfinite(values)):
                raise InputError(f"{name} contains non-finite values; cannot build a Box")
            top = float(np.max(values, initial=0.0))
            if top <= 0.0:
                raise InputError(f"{name} has no strictly positive sample; cannot infer {field}")
            bounds[field] = top * (1.0 + margin_value)
        return cls(**bounds)

    def as_dict(self) -> dict[str, float]:
        """JSON-ready ``{"zeta_max": Z [m], "zd_max": V [m/s]}``."""
        return {"zeta_max": self.zeta_max, "zd_max": self.zd_max}
