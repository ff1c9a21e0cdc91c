"""Settings objects: the options of a public function with many, in one named, checked object.

A public function with more options than a signature should carry takes them as keywords
(``discover(scenario, record, library="poly:3", shortlist=4)``) or as one object
(``discover(scenario, record, settings=DiscoverSettings(library="poly:3"))``), or both: the
keywords then override the object's fields.  The object is a frozen dataclass derived from
:class:`Settings`; each field declares its default and the spec of :mod:`discovery._api._validate`
that checks it (:func:`option`).

* :meth:`Settings.of` merges an object and keywords for a function: an unknown keyword is one
  line naming it, the closest field and the settings class (a ``TypeError``, as Python's own
  unexpected keyword is); a wrong value is one line naming the function and the field.
* A settings object checks its fields when it is made (``DiscoverSettings(max_terms=0)``
  raises), so an object passed around is valid: each field by its spec, and fields that
  bound each other by the class's :meth:`Settings._check_together`.  The function that
  takes the object checks nothing of it again (``tests/test_settings_bounds.py``).
* ``to_dict()`` / ``from_dict()`` give a JSON-safe document and back, for records of the
  settings a result was made with.
* ``repr()`` is what one would type to make the object (its fields not at their default);
  ``print()`` lists every field.  A settings class is declared ``@dataclass(frozen=True,
  repr=False)`` so that it keeps this ``repr``.
"""

from __future__ import annotations

import dataclasses
import difflib
import functools

from .._files._jsonable import reads_document
from ..errors import VidiTypeError
from ._validate import _received, check

__all__ = ["Settings", "option", "takes", "options_of"]


def option(default=None, spec=None, *, factory=None):
    """A settings field: its default (or a ``factory`` of it) and the spec that checks it."""
    metadata = {"spec": spec}
    if factory is not None:
        return dataclasses.field(default_factory=factory, metadata=metadata)
    return dataclasses.field(default=default, metadata=metadata)


#: the spec of a field whose annotation is one of these and that names no spec of its own
_PLAIN = {"bool": bool, "str": str}


@dataclasses.dataclass(frozen=True)
class Settings:
    """Base of the settings classes: a frozen dataclass of checked options."""

    def __post_init__(self):
        self._check(type(self).__name__)

    def _check(self, where, names=None):
        for f in self._fields():
            if names is not None and f.name not in names:
                continue
            spec = f.metadata.get("spec")
            if spec is None:
                # a field without a spec of its own: a switch is a bool, a name is text
                spec = _PLAIN.get(f.type if isinstance(f.type, str) else f.type.__name__)
            if spec is not None:
                check(f"{where}: {f.name}", getattr(self, f.name), spec)
        self._check_together(where)

    def _check_together(self, where):
        """Refuse fields each within its spec but not together (``periods`` at least four
        times ``max_period``): a class with such a rule overrides this (an InputError
        naming ``where`` and the fields); the base has none."""

    @classmethod
    @functools.cache
    def _fields(cls):
        return dataclasses.fields(cls)

    @classmethod
    @functools.cache
    def names(cls):
        """The fields' names, in order."""
        return tuple(f.name for f in cls._fields())

    @classmethod
    @functools.cache
    def defaults(cls):
        """The settings every field at its default."""
        return cls()

    @classmethod
    def of(cls, where, settings=None, options=None, *, rest=()):
        """The settings a call of ``where`` asks for: ``settings`` (an instance or None)
        with the keyword ``options`` over its fields.  With ``rest`` (the names a function
        passes on, e.g. an estimator's parameters), keywords that are no field but one of
        those are returned beside the settings (``(settings, rest)``); any other keyword is
        refused."""
        if settings is not None and not isinstance(settings, cls):
            raise VidiTypeError(
                f"{where}: settings must be a {cls.__name__} or None; got {_received(settings)}"
            )
        options = dict(options or {})
        known = cls.names()
        unknown = {k: options.pop(k) for k in list(options) if k not in known}
        wrong = [k for k in unknown if k not in rest]
        if wrong:
            name = wrong[0]
            close = difflib.get_close_matches(name, (*known, *rest), n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise VidiTypeError(
                f"{where}: unexpected keyword {name!r}{hint}; the options are the fields of "
                f"{cls.__name__}"
            )
        base = cls.defaults() if settings is None else settings
        if options:  # only the given values need a check (naming the function called)
            new = object.__new__(cls)  # a copy with the options (a frozen dataclass's fields)
            new.__dict__.update(base.__dict__)
            new.__dict__.update(options)
            new._check(where, options)
            base = new
        return (base, unknown) if rest else base

    def __repr__(self):
        """What one would type to make these settings: the fields not at their default."""
        body = ", ".join(f"{k}={v!r}" for k, v in self.changed().items())
        return f"{type(self).__name__}({body})"

    def __str__(self):
        changed = self.changed()
        names = self.names()
        width = max(len(n) for n in names)
        head = f"{type(self).__name__}: {len(changed)} of {len(names)} options changed"
        rows = [
            f"  {n:<{width}} = {getattr(self, n)!r}" + ("   (changed)" if n in changed else "")
            for n in names
        ]
        return "\n".join([head, *rows])

    def changed(self):
        """``{name: value}`` of the fields not at their default."""
        d = self.defaults()
        return {
            n: getattr(self, n) for n in self.names() if not _same(getattr(self, n), getattr(d, n))
        }

    def to_dict(self):
        """A JSON-safe ``{name: value}`` of every field."""
        from .._files._io import to_jsonable

        def plain(v):
            return dataclasses.asdict(v) if dataclasses.is_dataclass(v) else v

        return {n: to_jsonable(plain(getattr(self, n))) for n in self.names()}

    @classmethod
    @reads_document
    def from_dict(cls, doc):
        """The settings a :meth:`to_dict` document holds (missing fields at their
        default; lists back as tuples where the default is a tuple; an object's fields
        back as the object its spec names, e.g. a ``Tolerances``)."""
        d = cls.defaults()
        values = {}
        for f in cls._fields():
            if f.name in doc:
                v = doc[f.name]
                if isinstance(getattr(d, f.name), tuple) and isinstance(v, list):
                    v = tuple(v)
                values[f.name] = _rebuilt(f.metadata.get("spec"), v)
        return dataclasses.replace(d, **values)


def _same(a, b):
    """Whether two field values are equal (an array against anything: only itself)."""
    try:
        return bool(a == b)
    except (TypeError, ValueError):
        return a is b


def _rebuilt(spec, value):
    """``value`` as the dataclass its spec allows, when it is that dataclass's fields."""
    if not isinstance(value, dict):
        return value
    for kind in spec if isinstance(spec, tuple) else (spec,):
        if isinstance(kind, type) and dataclasses.is_dataclass(kind):
            return kind(**value)
    return value


def takes(cls):
    """Decorator of a public function whose options are the fields of ``cls`` (a
    :class:`Settings`): :func:`options_of` then lists them beside its parameters, and the
    function's signature shows each as a keyword with its default in place of
    ``**options`` (``help()``, an editor's hints and the API pages read it; the function
    still takes them through ``**options``)."""

    def mark(func):
        func.__vidi_settings__ = cls
        func.__signature__ = _signature_with(func, cls)
        return func

    return mark


def _signature_with(func, cls):
    """``func``'s signature with its ``**options`` written out as the keyword-only fields
    of ``cls`` that it does not name itself, at their defaults."""
    import inspect

    sig = inspect.signature(func)
    params = [p for p in sig.parameters.values() if p.kind is not p.VAR_KEYWORD]
    if len(params) == len(sig.parameters):
        return sig  # no **options: nothing to write out
    named = {p.name for p in params}
    defaults = cls.defaults()
    fields = [
        inspect.Parameter(n, inspect.Parameter.KEYWORD_ONLY, default=getattr(defaults, n))
        for n in cls.names()
        if n not in named
    ]
    return sig.replace(parameters=params + fields)


def options_of(func):
    """``{name: default}`` of every option of ``func``: its named parameters (other than
    ``settings``) and the fields of the settings class it takes."""
    import inspect

    out = {
        n: p.default
        for n, p in inspect.signature(func).parameters.items()
        if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD) and n != "settings"
    }
    cls = getattr(func, "__vidi_settings__", None)
    if cls is not None:
        d = cls.defaults()
        out.update({n: getattr(d, n) for n in cls.names()})
    return out
