"""Issue 51: a settings object and the function it is given accept and refuse the same values.

Every settings class (found, not listed: a new class is covered without editing this file) is
made with each numeric field at its bounds (the bound itself and the next value beyond it):
the object accepts exactly what its field's spec declares, and the keyword path of the
function that takes it (:meth:`Settings.of`) exactly what the object accepts.  The function
then checks nothing of the object again: no function that takes settings, nor a helper it
hands a field to, holds a second validator of a field (an ``if`` on the field alone that
raises an InputError).
"""

import ast
import dataclasses
import importlib
import inspect
import math
import pkgutil
import textwrap

import pytest

import discovery
from discovery._api._validate import Real, check
from discovery.errors import InputError, VidiTypeError

from .test_settings import SETTINGS


def _reals(spec):
    """The :class:`Real` specs of a field's spec (itself, or those in its tuple)."""
    return [s for s in (spec if isinstance(spec, tuple) else (spec,)) if isinstance(s, Real)]


def _beyond(real, bound, direction):
    """The value next to ``bound`` in ``direction`` (+1, -1): the next integer, or float."""
    if real.integer:
        return int(bound) + direction
    return math.nextafter(float(bound), direction * math.inf)


def _edges(real):
    """The values at ``real``'s bounds: each bound and its neighbours (0's with ``zero``)."""
    values = []
    for bound in (real.low, real.high):
        if bound is not None:
            b = int(bound) if real.integer else float(bound)
            values += [_beyond(real, b, -1), b, _beyond(real, b, +1)]
    if real.zero:
        values += [_beyond(real, 0, -1), 0, _beyond(real, 0, +1)]
    return values


def _declared(real, v):
    """Whether ``v`` is within ``real`` as its attributes declare (an oracle apart from
    :meth:`Real.__call__`)."""
    if real.zero and v == 0:
        return True
    low_ok = real.low is None or (v > real.low if real.open_low else v >= real.low)
    high_ok = real.high is None or (v < real.high if real.open_high else v <= real.high)
    return low_ok and high_ok


def _cases():
    for cls in SETTINGS:
        for f in dataclasses.fields(cls):
            for real in _reals(f.metadata.get("spec")):
                for v in _edges(real):
                    yield pytest.param(cls, f.name, v, id=f"{cls.__name__}.{f.name}={v!r}")


def _accepts(make):
    try:
        make()
    except InputError:
        return False
    return True


def _together_ok(cls, name, value):
    """Whether ``value`` in ``name`` (the rest at their defaults) keeps the class's rules
    across fields (:meth:`Settings._check_together`)."""
    obj = object.__new__(cls)
    obj.__dict__.update(cls.defaults().__dict__)
    obj.__dict__[name] = value
    return _accepts(lambda: obj._check_together(cls.__name__))


CASES = list(_cases())


def test_every_numeric_field_declares_its_bounds():
    """A field whose default is a number has a spec that bounds it (else it has no bound to
    test, and the function would be left to check it)."""
    bare = [
        f"{cls.__name__}.{f.name}"
        for cls in SETTINGS
        for f in dataclasses.fields(cls)
        if isinstance(getattr(cls.defaults(), f.name), int | float)
        and not isinstance(getattr(cls.defaults(), f.name), bool)
        and f.metadata.get("spec") is None
    ]
    assert not bare, bare
    assert len(CASES) > 200


@pytest.mark.parametrize(("cls", "name", "value"), CASES)
def test_the_object_and_its_function_accept_the_same_values_at_the_bounds(cls, name, value):
    spec = next(f.metadata["spec"] for f in dataclasses.fields(cls) if f.name == name)
    real = next(r for r in _reals(spec) if value in _edges(r))
    declared = _declared(real, value)
    assert _accepts(lambda: check(name, value, spec)) == declared
    made = _accepts(lambda: cls(**{name: value}))
    assert made == (declared and _together_ok(cls, name, value))
    # the function's own check of a keyword (its settings made from its options)
    assert _accepts(lambda: cls.of("function", None, {name: value})) == made
    if made:  # and the object handed to it is taken as it is
        obj = cls(**{name: value})
        assert cls.of("function", obj, {}) is obj


def test_a_rule_across_fields_is_kept_by_the_object_and_the_keywords():
    from discovery.ueda import UedaChartSettings

    with pytest.raises(InputError, match=r"^UedaChartSettings: periods \(40\) must be at least"):
        UedaChartSettings(periods=40, max_period=16)
    with pytest.raises(InputError, match=r"^chart: periods \(8\) must be at least 4 x"):
        UedaChartSettings.of("chart", UedaChartSettings(), {"periods": 8})
    assert UedaChartSettings(periods=64, max_period=16).periods == 64


def test_a_zero_or_bounded_count_says_so():
    with pytest.raises(InputError, match="must be 0 or an integer >= 5; got 3"):
        discovery.DiscoverSettings(n_boot_intervals=3)
    with pytest.raises(VidiTypeError):
        discovery.DiscoverSettings(n_boot_intervals=0.0)


def _hand_ons():
    """``(settings class, field, class of the function it is handed to, its field, off)``:
    a field a function passes on to another settings function (``off``: its 0 means none,
    and nothing is passed on)."""
    from discovery import ueda
    from discovery.vibroimpact.fit.intervals import BootstrapIntervalsSettings as Boot

    out = [
        (discovery.DiscoverSettings, "n_boot_intervals", Boot, "n_boot", True),
        (discovery.ExplainSettings, "n_boot_intervals", Boot, "n_boot", True),
        (discovery.IdentifySettings, "n_boot_intervals", Boot, "n_boot", True),
        (discovery.ContactModelsSettings, "n_boot", Boot, "n_boot", True),
    ]
    for name in ("transient", "periods", "resamples", "seed"):
        out.append((ueda.UedaExplainSettings, name, ueda.UedaVerifySettings, name, False))
    for name in ("half_width", "order"):
        out.append((ueda.UedaExplainSettings, name, ueda.UedaDiscoverSettings, name, False))
    return out


@pytest.mark.parametrize("hand_on", _hand_ons(), ids=lambda h: f"{h[0].__name__}.{h[1]}")
def test_a_field_handed_on_accepts_what_the_next_function_accepts(hand_on):
    outer, name, inner, inner_name, off = hand_on
    specs = [
        f.metadata["spec"]
        for c, n in ((outer, name), (inner, inner_name))
        for f in dataclasses.fields(c)
        if f.name == n
    ]
    values = {v for spec in specs for r in _reals(spec) for v in _edges(r)}
    for v in sorted(values):
        if off and v == 0:
            continue
        given = _accepts(lambda v=v: outer(**{name: v}))
        taken = _accepts(lambda v=v: inner(**{inner_name: v}))
        assert given == taken, (v, given, taken)


# ------------------------------------------------------------------ no second validator
def _functions():
    """``(function, settings class)`` of every function that takes settings."""
    seen = {}
    for info in pkgutil.walk_packages(discovery.__path__, "discovery."):
        if ".cli" in info.name:
            continue
        module = importlib.import_module(info.name)
        for obj in vars(module).values():
            cls = getattr(obj, "__vidi_settings__", None)
            if cls is not None and getattr(obj, "__module__", None) == module.__name__:
                seen[inspect.unwrap(obj)] = cls
    return list(seen.items())


def _tree(func):
    return ast.parse(textwrap.dedent(inspect.getsource(func)))


def _settings_name(tree):
    """The name the function gives its settings (``s = Cls.of(...)``)."""
    for node in ast.walk(tree):
        if (
            isinstance(node, ast.Assign)
            and isinstance(node.value, ast.Call)
            and isinstance(node.value.func, ast.Attribute)
            and node.value.func.attr == "of"
        ):
            target = node.targets[0]
            return (target.elts[0] if isinstance(target, ast.Tuple) else target).id
    return None


def _raises_input_error(body):
    for stmt in body:
        if isinstance(stmt, ast.Raise) and stmt.exc is not None:
            exc = stmt.exc.func if isinstance(stmt.exc, ast.Call) else stmt.exc
            if getattr(exc, "id", None) in ("InputError", "VidiTypeError"):
                return True
    return False


def _field_checks(tree, fields_of, known):
    """The tests of ``if`` statements that raise an InputError over ``fields_of(node)``
    alone: the names they read are those fields and ``known`` (modules, constants,
    builtins), no other argument (a check against the record, the scenario, is no field's
    bound)."""
    found = []
    for node in ast.walk(tree):
        if not (
            isinstance(node, ast.If)
            and (_raises_input_error(node.body) or _raises_input_error(node.orelse))
        ):
            continue
        fields = fields_of(node.test)
        names = {n.id for n in ast.walk(node.test) if isinstance(n, ast.Name)}
        if fields and names <= known | fields_of.names:
            found.append(ast.unparse(node.test))
    return found


class _Reads:
    """The fields of the settings a node reads (``s.alpha``), or the parameters named."""

    def __init__(self, settings=None, parameters=()):
        self.settings, self.parameters = settings, set(parameters)
        self.names = {settings} if settings else set(parameters)

    def __call__(self, node):
        out = set()
        for n in ast.walk(node):
            if (
                self.settings
                and isinstance(n, ast.Attribute)
                and getattr(n.value, "id", None) == self.settings
            ):
                out.add(n.attr)
            elif isinstance(n, ast.Name) and n.id in self.parameters:
                out.add(n.id)
        return out


def _known(func):
    import builtins

    return set(vars(builtins)) | set(func.__globals__)


def _helpers_given_fields(func, tree, settings, package="discovery"):
    """``(helper, parameter names)`` of the ``package``'s functions that ``func`` hands a
    field of its settings to (``helper(..., s.order)``)."""
    reads = _Reads(settings)
    for node in ast.walk(tree):
        if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)):
            continue
        helper = func.__globals__.get(node.func.id)
        if not (inspect.isfunction(helper) and helper.__module__.startswith(package)):
            continue
        params = list(inspect.signature(helper).parameters)
        given = [p for p, a in zip(params, node.args, strict=False) if reads(a)]
        given += [k.arg for k in node.keywords if k.arg in params and reads(k.value)]
        if given:
            yield inspect.unwrap(helper), given


@pytest.mark.parametrize(("func", "cls"), _functions(), ids=lambda x: x.__qualname__)
def test_no_function_holds_a_second_validator(func, cls):
    tree = _tree(func)
    settings = _settings_name(tree)
    assert settings is not None, f"{func.__qualname__} does not make its {cls.__name__}"
    known = _known(func) - {settings}
    found = _field_checks(tree, _Reads(settings), known)
    for helper, params in _helpers_given_fields(func, tree, settings):
        checks = _field_checks(_tree(helper), _Reads(parameters=params), _known(helper))
        found += [f"{helper.__name__}: {c}" for c in checks]
    assert not found, f"{func.__qualname__} checks its settings again: {found}"


def test_the_scan_finds_a_second_validator():
    """The scan above sees the checks it forbids (a function and its helper)."""

    def _check_order(order, other):
        if order < 2:
            raise InputError("order")

    def made_up(settings=None, **options):
        s = discovery.DiscoverSettings.of("made_up", settings, options)
        if not 0 < s.max_terms < 3:
            raise InputError("max_terms")
        _check_order(s.stepwise, 1)

    tree = _tree(made_up)
    assert _field_checks(tree, _Reads("s"), _known(made_up)) == ["not 0 < s.max_terms < 3"]
    made_up.__globals__["_check_order"] = _check_order
    try:
        ((helper, params),) = _helpers_given_fields(made_up, tree, "s", package="tests")
    finally:
        del made_up.__globals__["_check_order"]
    assert params == ["order"]
    assert _field_checks(_tree(helper), _Reads(parameters=params), _known(helper)) == ["order < 2"]
