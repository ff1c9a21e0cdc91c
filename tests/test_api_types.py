"""Every public API entry refuses wrong types and values at its boundary.

Table-driven: each row calls one public function or constructor with one wrong argument
and names the parameter the message must mention. The error must be a ``VidiError`` and
the builtin a Python user expects (``TypeError`` for a wrong type, ``ValueError`` for a
value out of range), with one line naming the parameter, and raised before any work.
"""

import os

import numpy as np
import pytest

import discovery as d
import discovery.ueda as osc
from discovery.errors import InputError, VidiError, VidiTypeError
from discovery.ueda.regime_chart import chart as ueda_chart
from discovery.vibroimpact.verify import verify

SC = d.load_scenario("paper")
LAW = d.ForceLaw.parse("2.06e8*z + 1.28e7*zd")
T = np.linspace(0.0, 0.1, 50)
F = np.zeros(50)
REC = d.Measurement(t=T, F=F, channels={"w1": np.zeros(50), "w2": np.zeros(50)})
UEDA = osc.UedaSystem("negres", mu=0.2, gamma=8.0, k=0.0, B=0.9, nu=1.0)

TYPE, VALUE = VidiTypeError, InputError

CASES = [
    # (id, call, error, parameter named in the message)
    ("Term a text", lambda: d.Term("x", 1), TYPE, "a"),
    ("ContactModel values text", lambda: d.ContactModel("flores", "abc"), TYPE, "values"),
    ("ContactModel name int", lambda: d.ContactModel(5, (1.0,)), TYPE, "name"),
    ("parse_law int", lambda: d.parse_law(5), VALUE, "text"),
    (
        "fit_contact_models scenario text",
        lambda: d.fit_contact_models("paper", REC),
        TYPE,
        "scenario",
    ),
    ("Term b None", lambda: d.Term(1, None), TYPE, "b"),
    ("calibrate scenario text", lambda: d.calibrate("paper", REC), TYPE, "scenario"),
    ("calibrate n_boot -1", lambda: d.calibrate(SC, REC, n_boot=-1), VALUE, "n_boot"),
    ("Term exponent 1e4", lambda: d.Term(1e4, 0), VALUE, "a"),
    ("Term bool", lambda: d.Term(True, 0), TYPE, "a"),
    ("ForceLaw terms text", lambda: d.ForceLaw("z", (1.0,)), TYPE, "terms"),
    ("ForceLaw term not Term", lambda: d.ForceLaw((5,), (1.0,)), TYPE, "term"),
    ("ForceLaw coefficient text", lambda: d.ForceLaw((d.Term(1, 0),), ("a",)), TYPE, "coefficient"),
    (
        "ForceLaw set 2",
        lambda: d.ForceLaw((d.Term(1, 0),), (1.0,), permanent_set=2.0),
        VALUE,
        "permanent_set",
    ),
    ("ForceLaw.parse int", lambda: d.ForceLaw.parse(5), VALUE, "text"),
    ("law exponent 1e300", lambda: d.ForceLaw.parse("2e8*z^1e300"), VALUE, "exponent"),
    ("Scenario name int", lambda: d.Scenario(1, 1, 1, 1, 1, 1, name=5), TYPE, "name"),
    ("Scenario m1 text", lambda: d.Scenario("a", 1, 1, 1, 1, 1), VALUE, "m1"),
    ("Scenario law text", lambda: d.Scenario(1, 1, 1, 1, 1, 1, law="2e8*z"), TYPE, "law"),
    ("Measurement t text", lambda: d.Measurement(t="abc", F=F), TYPE, "t"),
    ("Measurement F 2-D", lambda: d.Measurement(t=T, F=np.zeros((50, 2))), VALUE, "F"),
    ("Measurement channels list", lambda: d.Measurement(t=T, F=F, channels=[1]), TYPE, "channels"),
    ("Measurement channel text", lambda: d.Measurement(t=T, F=F, channels={"w1": "x"}), TYPE, "w1"),
    ("Tolerances rtol text", lambda: d.Tolerances(rtol="a"), TYPE, "rtol"),
    ("Tolerances max_steps float", lambda: d.Tolerances(max_steps=1.5), TYPE, "max_steps"),
    ("simulate scenario text", lambda: d.simulate("paper", LAW, (0, 0.1)), TYPE, "scenario"),
    ("simulate law text", lambda: d.simulate(SC, "2e8*z", (0, 0.1)), TYPE, "law"),
    ("simulate t_span text", lambda: d.simulate(SC, LAW, "0,1"), TYPE, "t_span"),
    ("simulate unknown keyword", lambda: d.simulate(SC, LAW, (0, 1), t_end=1), TYPE, "t_end"),
    ("steady_state law int", lambda: d.steady_state(SC, 5), TYPE, "law"),
    (
        "steady_state max_period 0",
        lambda: d.steady_state(SC, LAW, max_period=0),
        VALUE,
        "max_period",
    ),
    (
        "steady_state tolerances dict",
        lambda: d.steady_state(SC, LAW, tolerances={}),
        TYPE,
        "tolerances",
    ),
    ("Library text", lambda: d.Library("z"), TYPE, "terms"),
    ("Library of ints", lambda: d.Library([5]), TYPE, "term"),
    ("discover scenario int", lambda: d.discover(5, REC), TYPE, "scenario"),
    ("discover measurement text", lambda: d.discover(SC, "D.csv"), TYPE, "measurement"),
    ("discover max_terms text", lambda: d.discover(SC, REC, max_terms="4"), TYPE, "max_terms"),
    ("identify reference text", lambda: d.identify(SC, "D.csv", LAW), TYPE, "reference"),
    ("identify seed -1", lambda: d.identify(SC, REC, LAW, seed=-1), VALUE, "seed"),
    ("verify law text", lambda: verify(SC, REC, "2e8*z"), TYPE, "law"),
    ("verify n_boot float", lambda: verify(SC, REC, LAW, n_boot=2.5), TYPE, "n_boot"),
    ("study config int", lambda: d.study(5, "out"), TYPE, "config"),
    ("study workers 0", lambda: d.study({}, "out", workers=0), VALUE, "workers"),
    ("study executor text", lambda: d.study({}, "out", executor="pool"), TYPE, "executor"),
    ("load_study list", lambda: d.load_study([1]), TYPE, "path_or_mapping"),
    ("field_record law text", lambda: d.field_record(SC, "2e8*z"), TYPE, "law"),
    (
        "field_record noise 2",
        lambda: d.field_record(SC, LAW, force_noise=2.0),
        VALUE,
        "force_noise",
    ),
    ("make_executor workers text", lambda: d.make_executor("2"), TYPE, "workers"),
    ("advise scenario text", lambda: d.advise("paper", [LAW, LAW], None, None), TYPE, "scenario"),
    ("advise knobs text", lambda: d.advise(SC, [LAW, LAW], "3e5:6e5", None), TYPE, "knobs"),
    ("Knobs amplitude text", lambda: d.Knobs("abc", (20, 30)), VALUE, "amplitude"),
    ("NoiseModel relative text", lambda: d.NoiseModel("a"), VALUE, "relative"),
    ("SafeRegion max_force 0", lambda: d.SafeRegion(max_force=0), VALUE, "max_force"),
    ("landscape axis text", lambda: d.landscape(SC, LAW, "1,2", [1, 2]), TYPE, "axis0"),
    (
        "landscape workers 0",
        lambda: d.landscape(SC, LAW, [1, 2], [1, 2], workers=0),
        VALUE,
        "workers",
    ),
    ("explain alpha 2", lambda: d.explain(SC, REC, alpha=2.0), VALUE, "alpha"),
    ("explain start int", lambda: d.explain(SC, REC, start=5), TYPE, "start"),
    ("impulse period 0", lambda: d.impulse_from_samples(T, F, 0.0), VALUE, "period"),
    ("impulse F text", lambda: d.impulse_from_samples(T, "F", 0.04), TYPE, "F"),
    ("synthesize periods text", lambda: d.synthesize(SC, LAW, periods="a"), TYPE, "periods"),
    ("synthesize noise 5", lambda: d.synthesize(SC, LAW, noise=5.0), VALUE, "noise"),
    ("response law int", lambda: d.response(SC, 5), TYPE, "law"),
    ("contact_samples int", lambda: d.contact_samples(5), TYPE, "measurement"),
    ("evaluate_criteria int", lambda: d.evaluate_criteria(5, 5), TYPE, "measured"),
    ("ueda strobe system text", lambda: osc.strobe_points("negres"), TYPE, "system"),
    ("ueda lyapunov periods 0", lambda: osc.lyapunov(UEDA, periods=0), VALUE, "periods"),
    ("ueda attractor y0 text", lambda: osc.attractor(UEDA, y0="0,0"), TYPE, "y0"),
    ("ueda chart nu text", lambda: ueda_chart(UEDA, "1", [0.9]), TYPE, "nu"),
    ("ueda discover x None", lambda: osc.discover(T, None, 0.9, 1.0), TYPE, "x"),
    ("ueda discover nu 0", lambda: osc.discover(T, F, 0.9, 0.0), VALUE, "nu"),
    ("ueda explain alpha text", lambda: osc.explain(T, F, 0.9, 1.0, alpha="a"), TYPE, "alpha"),
    ("ueda periodic n 0", lambda: osc.periodic_orbit(UEDA, [0.0, 0.0], n=0), VALUE, "n"),
    ("ueda record periods text", lambda: osc.simulate_record(UEDA, periods="a"), TYPE, "periods"),
    # issue 29's sweep: each of these raised outside the hierarchy
    ("from_csv None", lambda: d.Measurement.from_csv(None), TYPE, "path"),
    ("from_csv an int (a file descriptor)", lambda: d.Measurement.from_csv(123), TYPE, "path"),
    ("simulate y0 of 2", lambda: d.simulate(SC, LAW, (0, 0.1), y0=[0.0, 0.0]), VALUE, "y0"),
    ("synthesize periods 1e12", lambda: d.synthesize(SC, LAW, periods=10**12), VALUE, "periods"),
    ("identify start text", lambda: d.identify(SC, REC, "2e8*z"), TYPE, "start"),
    (
        "regressor fit texts",
        lambda: d.ConstrainedSparseRegressor().fit("a", "b"),
        TYPE,
        "X",
    ),
    ("load path number", lambda: d.load(5), TYPE, "path"),
    ("load path missing", lambda: d.load("no-such-run-dir"), VALUE, "no-such-run-dir"),
    # the settings objects: each field checked when made, an unknown keyword named
    ("DiscoverSettings max_terms 0", lambda: d.DiscoverSettings(max_terms=0), VALUE, "max_terms"),
    ("discover unknown keyword", lambda: d.discover(SC, REC, shortlst=2), TYPE, "shortlst"),
    ("discover settings dict", lambda: d.discover(SC, REC, settings={}), TYPE, "settings"),
    ("SimulateSettings max_events", lambda: d.SimulateSettings(max_events=-1), VALUE, "max_events"),
    (
        "SteadyStateSettings max_period 0",
        lambda: d.SteadyStateSettings(max_period=0),
        VALUE,
        "max_period",
    ),
    ("SynthesizeSettings fs 0", lambda: d.SynthesizeSettings(fs=0), VALUE, "fs"),
    ("LandscapeSettings workers 0", lambda: d.LandscapeSettings(workers=0), VALUE, "workers"),
    ("FieldRecordSettings seed -1", lambda: d.FieldRecordSettings(seed=-1), VALUE, "seed"),
    ("AdviseSettings workers text", lambda: d.AdviseSettings(workers="a"), TYPE, "workers"),
    (
        "campaign scenario text",
        lambda: d.campaign("paper", REC, print, d.Knobs((3e5, 6e5), (20, 30))),
        TYPE,
        "scenario",
    ),
    (
        "campaign knobs text",
        lambda: d.campaign(SC, REC, print, "3e5:6e5"),
        TYPE,
        "knobs",
    ),
    (
        "CampaignSettings max_records 1",
        lambda: d.CampaignSettings(max_records=1),
        VALUE,
        "max_records",
    ),
    ("IdentifySettings xtol text", lambda: d.IdentifySettings(xtol="a"), TYPE, "xtol"),
    ("ExplainSettings alpha 2", lambda: d.ExplainSettings(alpha=2.0), VALUE, "alpha"),
    ("VerifySettings n_boot -1", lambda: d.VerifySettings(n_boot=-1), VALUE, "n_boot"),
    (
        "ContactModelsSettings workers 0",
        lambda: d.ContactModelsSettings(workers=0),
        VALUE,
        "workers",
    ),
    (
        "ueda UedaChartSettings periods 0",
        lambda: osc.UedaChartSettings(periods=0),
        VALUE,
        "periods",
    ),
]


def test_an_unfitted_regressor_is_a_vidi_error_and_sklearns():
    from sklearn.exceptions import NotFittedError

    with pytest.raises(VidiError) as info:
        d.ConstrainedSparseRegressor().predict(np.zeros((3, 2)))
    assert isinstance(info.value, NotFittedError)


def test_from_csv_never_reads_a_file_descriptor(tmp_path):
    r, w = os.pipe()
    try:
        with pytest.raises(VidiTypeError):
            d.Measurement.from_csv(r)
    finally:
        os.close(r)
        os.close(w)


@pytest.mark.parametrize("call, error, name", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_wrong_argument_is_refused_at_the_boundary(call, error, name):
    with pytest.raises(VidiError) as info:
        call()
    exc = info.value
    assert isinstance(exc, error), f"{type(exc).__name__}: {exc}"
    assert isinstance(exc, TypeError if error is TYPE else ValueError)
    message = str(exc)
    assert "\n" not in message and len(message) < 300, message
    assert name in message, message


def test_the_cases_cover_every_public_entry():
    """A new public function or class must get a row here."""
    covered = " ".join(c[0] for c in CASES).lower()
    entries = [
        "term",
        "forcelaw",
        "scenario",
        "measurement",
        "tolerances",
        "simulate",
        "steady_state",
        "library",
        "discover",
        "identify",
        "verify",
        "landscape",
        "explain",
        "impulse",
        "synthesize",
        "response",
        "contact_samples",
        "evaluate_criteria",
        "ueda strobe",
        "ueda lyapunov",
        "ueda attractor",
        "ueda chart",
        "ueda discover",
        "ueda explain",
        "ueda periodic",
        "ueda record",
        "contactmodel",
        "parse_law",
        "fit_contact_models",
    ]
    missing = [e for e in entries if e not in covered]
    assert not missing, missing
    public = {n for n in d.__all__ if callable(getattr(d, n)) and not n.endswith("Error")}
    data_only = {
        "SteadyState",
        "Landscape",
        "DiscoveryResult",
        "RankedModel",
        "Impulse",
        "Response",
        "ContactSamples",
        "Candidate",
        "IdentificationResult",
        "ExplainResult",
        "VerifyResult",
        "Calibration",
        "AdviseResult",
        "CampaignResult",
        "NextRecord",
        "ContactModelsResult",
        "builtin_scenarios",
        "load_scenario",
        "impulse_from_steady_state",
        "Report",
        "report",
        "StudyResult",
        "Result",
        "Executor",
        # a scikit-learn estimator checks its parameters in fit, not in __init__
        # (tests/vibroimpact/fit/test_regression.py)
        "ConstrainedSparseRegressor",
    }
    unlisted = (
        public
        - data_only
        - {
            "Term",
            "ForceLaw",
            "Scenario",
            "Measurement",
            "Tolerances",
            "simulate",
            "steady_state",
            "Library",
            "discover",
            "identify",
            "landscape",
            "explain",
            "impulse_from_samples",
            "synthesize",
            "response",
            "contact_samples",
            "evaluate_criteria",
            "study",
            "load_study",
            "field_record",
            "make_executor",
            "verify",
            "load",
            "advise",
            "Knobs",
            "NoiseModel",
            "SafeRegion",
            "ContactModel",
            "parse_law",
            "fit_contact_models",
            "calibrate",
            "campaign",
        }
        # a settings class with a row of its own (rows are named after the class)
        - {n for n in public if n.endswith("Settings") and n.lower() in covered}
    )
    assert not unlisted, f"public entries without a row: {sorted(unlisted)}"


def test_the_checks_name_the_arguments_as_the_signature_binds_them():
    """The checked functions' fast binding (no ``inspect.Signature.bind`` on a plain call)
    names every argument as ``bind`` does, and leaves every other call to ``bind``."""
    import inspect
    import itertools

    from discovery._api._validate import _binder

    def f1(a, b, c=1, *, d, e=2):
        pass

    def f2(a, /, b, *, c=3):
        pass

    def f3(self, x=1):
        pass

    def f4(a, b=1, *, settings=None, **options):
        pass

    for f in (f1, f2, f3, f4):
        sig = inspect.signature(f)
        arguments = _binder(sig)
        names = [*sig.parameters, "unknown"]
        for n_args in range(5):
            for keys in itertools.chain.from_iterable(
                itertools.combinations(names, k) for k in range(4)
            ):
                args, kwargs = tuple(range(n_args)), {k: k for k in keys}
                try:
                    expected = dict(sig.bind(*args, **kwargs).arguments)
                except TypeError:
                    expected = None
                assert arguments(args, kwargs) == expected, (f.__name__, args, kwargs)


def test_unchecked_is_the_function_past_its_checks(paper):
    """The inner loops' way past the argument checks runs the same function (the same
    result for a valid call), while the public name still checks every call."""
    from discovery._api._validate import unchecked
    from discovery.vibroimpact.dynamics import simulate

    raw = unchecked(simulate)
    assert raw is not simulate and unchecked(raw) is raw
    T = paper.period
    a = simulate(paper, paper.law, (0.0, T), t_eval=[0.5 * T])
    b = raw(paper, paper.law, (0.0, T), t_eval=[0.5 * T])
    assert np.array_equal(a.y, b.y) and np.array_equal(a.event_t, b.event_t)
    with pytest.raises(VidiTypeError, match="simulate: law must be a ForceLaw"):
        simulate(paper, "2e8*z", (0.0, T))
