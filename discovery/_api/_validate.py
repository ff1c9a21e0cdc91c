"""One validation layer for the public API: wrong types and values stop at the boundary.

A public function declares what each argument must be with :func:`params`; a public dataclass
calls :func:`check` from its ``__post_init__``. Either way a wrong argument raises, before any
work, an error of the one hierarchy that is also the builtin a Python user expects (the
scikit-learn way): :class:`VidiTypeError` (a ``VidiError`` and a ``TypeError``) for a wrong
type, :class:`~discovery.errors.InputError` (a ``VidiError`` and a ``ValueError``) for a value
out of range. The message is one line naming the function, the parameter, what is allowed and
what was received.

A spec is a class (or a tuple of classes), a :class:`Real`, :class:`Choice`, :class:`Text`
or :class:`Array`, or ``None`` inside a tuple to allow ``None``.
"""

from __future__ import annotations

import functools
import inspect
import numbers

import numpy as np

from ..errors import InputError, VidiTypeError

__all__ = ["Real", "Choice", "Text", "Array", "Instance", "check", "params", "unchecked"]


def _received(value):
    text = repr(value)
    if len(text) > 40:
        text = text[:37] + "..."
    return f"{type(value).__name__} {text}"


class Real:
    """A real number (not a bool, not text) within ``[low, high]``, optionally an integer;
    with ``zero``, also 0 (a count whose 0 means none, e.g. bootstrap replicates)."""

    def __init__(
        self,
        low=None,
        high=None,
        *,
        integer=False,
        open_low=False,
        open_high=False,
        unit="",
        zero=False,
    ):
        self.low, self.high, self.integer, self.open_low = low, high, integer, open_low
        self.open_high, self.zero = open_high, zero
        self.unit = f" {unit}" if unit else ""

    def describe(self):
        return ("0 or " if self.zero else "") + self._range()

    def _range(self):
        kind = "an integer" if self.integer else "a number"
        if self.low is not None and self.high is not None:
            lo = "(" if self.open_low else "["
            hi = ")" if self.open_high else "]"
            return f"{kind} in {lo}{self.low:g}, {self.high:g}{hi}{self.unit}"
        if self.low is not None:
            return f"{kind} {'>' if self.open_low else '>='} {self.low:g}{self.unit}"
        return f"a finite {kind[2:] if kind.startswith('a ') else kind[3:]}"

    def __call__(self, where, value):
        ok_type = (
            isinstance(value, numbers.Integral) if self.integer else isinstance(value, numbers.Real)
        )
        if isinstance(value, (bool, np.bool_)) or not ok_type:
            raise VidiTypeError(f"{where} must be {self.describe()}; got {_received(value)}")
        # an integer compared as itself (2**63 - 1 is no float)
        v = int(value) if self.integer else float(value)
        if self.zero and v == 0:
            return
        bad = (
            (not self.integer and not np.isfinite(v))
            or (self.low is not None and (v <= self.low if self.open_low else v < self.low))
            or (self.high is not None and (v >= self.high if self.open_high else v > self.high))
        )
        if bad:
            raise InputError(f"{where} must be {self.describe()}; got {value!r}")


class Instance:
    """An instance of a class named by its module, imported at the first check (so that a
    light module need not import a heavy one for its signature)."""

    def __init__(self, module, name):
        self.module, self.name = module, name

    def describe(self):
        return _a(self.name)

    def __call__(self, where, value):
        import importlib

        cls = getattr(importlib.import_module(self.module), self.name)
        if not isinstance(value, cls):
            raise VidiTypeError(f"{where} must be {self.describe()}; got {_received(value)}")


class Choice:
    """One of a fixed set of values."""

    def __init__(self, *values):
        self.values = values

    def describe(self):
        return "one of " + ", ".join(repr(v) for v in self.values)

    def __call__(self, where, value):
        if not isinstance(value, (str, numbers.Number)) or value not in self.values:
            raise InputError(f"{where} must be {self.describe()}; got {_received(value)}")


class Text:
    """A non-empty string of at most ``max_chars`` characters."""

    def __init__(self, max_chars=10_000, empty=False):
        self.max_chars, self.empty = max_chars, empty

    def describe(self):
        return "text"

    def __call__(self, where, value):
        if not isinstance(value, str):
            raise VidiTypeError(f"{where} must be text; got {_received(value)}")
        if (not value and not self.empty) or len(value) > self.max_chars:
            raise InputError(
                f"{where} must be {'' if self.empty else 'non-empty '}text of at "
                f"most {self.max_chars} characters; got {len(value)} characters"
            )


class Array:
    """Numbers convertible to a float array (a list, a tuple or an array), optionally 1-D."""

    def __init__(self, ndim=None):
        self.ndim = ndim

    def describe(self):
        return "a 1-D array of numbers" if self.ndim == 1 else "an array of numbers"

    def __call__(self, where, value):
        if isinstance(value, (str, bytes, dict)) or value is None:
            raise VidiTypeError(f"{where} must be {self.describe()}; got {_received(value)}")
        try:
            arr = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            raise VidiTypeError(
                f"{where} must be {self.describe()}; got {_received(value)}"
            ) from None
        if self.ndim is not None and arr.ndim != self.ndim:
            raise InputError(
                f"{where} must be {self.describe()}; got {arr.ndim}-D of shape {arr.shape}"
            )


def _describe(spec):
    if isinstance(spec, tuple):
        return " or ".join("None" if s is None else _describe(s) for s in spec)
    if isinstance(spec, type):
        return _a(spec.__name__)
    return spec.describe()


def _a(name):
    from ..wording import a

    return a(name)


def check(where, value, spec):
    """Check ``value`` against ``spec``; ``where`` names it (``'simulate: law'``)."""
    if isinstance(spec, tuple):
        if value is None and None in spec:
            return
        classes = tuple(s for s in spec if isinstance(s, type))
        if classes and isinstance(value, classes):
            return
        others = [s for s in spec if s is not None and not isinstance(s, type)]
        for s in others:
            try:
                s(where, value)
                return
            except VidiTypeError:
                continue
        raise VidiTypeError(f"{where} must be {_describe(spec)}; got {_received(value)}")
    if isinstance(spec, type):
        if not isinstance(value, spec):
            hint = ""
            if spec.__name__ == "ForceLaw" and isinstance(value, str):
                hint = f" (parse text with ForceLaw.parse({value[:30]!r}))"
            elif spec.__name__ == "Scenario" and isinstance(value, str):
                hint = f" (load one with load_scenario({value[:30]!r}))"
            raise VidiTypeError(
                f"{where} must be {_a(spec.__name__)}{hint}; got {_received(value)}"
            )
        return
    spec(where, value)


def _binder(signature):
    """A function ``(args, kwargs) -> {name: value}`` of the arguments a call gives, as
    ``signature.bind`` would name them, for a call that binds plainly (positionals within
    the positional parameters, keywords by name, each once, every required one given);
    ``None`` for any other call (``signature.bind`` then names the problem).  Binding is
    most of a check's cost, and the checked functions are called in inner loops."""
    kinds = inspect.Parameter
    ps = list(signature.parameters.values())
    if any(p.kind == kinds.VAR_POSITIONAL for p in ps):
        return lambda args, kwargs: None
    # the ``**options`` of a function that takes settings (discovery._api._settings)
    rest = next((p.name for p in ps if p.kind == kinds.VAR_KEYWORD), None)
    ps = [p for p in ps if p.kind != kinds.VAR_KEYWORD]
    positional = [
        p.name for p in ps if p.kind in (kinds.POSITIONAL_ONLY, kinds.POSITIONAL_OR_KEYWORD)
    ]
    by_keyword = {p.name for p in ps if p.kind != kinds.POSITIONAL_ONLY}
    required = {p.name for p in ps if p.default is inspect.Parameter.empty}

    def arguments(args, kwargs):
        if len(args) > len(positional):
            return None
        given = dict(zip(positional, args, strict=False))
        for k, v in kwargs.items():
            if k in given:
                return None
            if k in by_keyword:
                given[k] = v
            elif rest is not None:
                given.setdefault(rest, {})[k] = v
            else:
                return None
        return given if required.issubset(given) else None

    return arguments


def params(**specs):
    """Decorator: check the named arguments of every call against their specs."""

    def wrap(func):
        signature = inspect.signature(func)
        unknown = set(specs) - set(signature.parameters)
        if unknown:  # a programming error in this package, caught at import
            raise AssertionError(f"{func.__qualname__}: no parameters {sorted(unknown)}")
        owner = func.__qualname__.replace(".__init__", "")
        arguments = _binder(signature)

        @functools.wraps(func)
        def checked(*args, **kwargs):
            given = arguments(args, kwargs)
            if given is None:  # an unusual call: the signature says what is wrong with it
                try:
                    given = signature.bind(*args, **kwargs).arguments
                except TypeError as exc:
                    raise VidiTypeError(f"{owner}: {exc}") from None
            for name, spec in specs.items():
                if name in given:
                    check(f"{owner}: {name}", given[name], spec)
            return func(*args, **kwargs)

        checked.__vidi_params__ = dict(specs)  # for callers that check options up front
        return checked

    return wrap


def unchecked(func):
    """``func`` without the argument checks of :func:`params`: for the package's inner
    loops, whose arguments are its own, checked where they came in (a fit simulates each
    block thousands of times; the checks were a twentieth of an explain's time)."""
    return getattr(func, "__wrapped__", func)
