"""The executor the package hands out (:func:`discovery.make_executor`): the shared floor's
:func:`~discovery.numerics.executor.make_executor` with both systems' kernels compiled on
a Dask cluster's workers before any job (:func:`discovery.warm.warm`)."""

from ._api._validate import Real, Text, params
from .numerics.executor import make_executor as _make_executor
from .warm import warm

__all__ = ["make_executor"]


@params(workers=(None, Real(1, 4096, integer=True)), scheduler=(None, Text()))
def make_executor(workers=None, scheduler=None):
    """The executor for ``workers`` local processes (``None``: one per CPU; 1: serial), or
    a Dask cluster when ``scheduler`` is given (``"local"`` or a scheduler address), whose
    workers compile the kernels of both systems first."""
    return _make_executor(workers, scheduler, warm=warm)
