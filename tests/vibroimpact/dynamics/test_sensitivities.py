"""Exact sensitivities of the compiled kernel (variational equations through the steps, the
saltation matrix at every event): checked against closed forms (a free flight's matrix
exponential, the wall impact's restitution and contact time) and against central
differences on every kind of event (onset, loss, unload, reload, release, resume)."""

import numpy as np
import pytest
from scipy.linalg import expm

from discovery.errors import InputError
from discovery.vibroimpact.dynamics.kernel import codes as K
from discovery.vibroimpact.dynamics.simulation import Tolerances, simulate
from discovery.vibroimpact.dynamics.steady_states import StroboscopicMap, steady_state
from discovery.vibroimpact.model.law import ForceLaw
from discovery.vibroimpact.model.scenario import Scenario, load_scenario

TIGHT = Tolerances(rtol=1e-11, hmax_fraction=1e-3)


# ------------------------------------------------------------------ closed forms
def test_free_flight_jacobian_is_the_matrix_exponential():
    """No contact: the frame is a linear forced oscillator (``expm``) and the moulding
    falls freely (``[[1, t], [0, 1]]``); the forcing does not enter the Jacobian."""
    sc = Scenario(
        m1=100.0, m2=1.0, k1=4e4, c1=40.0, A=50.0, frequency=5.0, initial=(0, 0, 1.0, 0.0)
    )
    law = ForceLaw.parse("1e6*z")
    t1 = 0.3  # the moulding falls 0.44 m: no contact
    tr = simulate(sc, law, (0.0, t1), tolerances=TIGHT, sensitivities="state")
    assert len(tr.event_t) == 0 and tr.sensitivity_names == ("w1", "v1", "w2", "v2")
    frame = expm(np.array([[0.0, 1.0], [-4e4 / 100.0, -40.0 / 100.0]]) * t1)
    np.testing.assert_allclose(tr.sensitivity[:2, :2], frame, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(tr.sensitivity[2:, 2:], [[1.0, t1], [0.0, 1.0]], atol=1e-13)
    np.testing.assert_array_equal(tr.sensitivity[:2, 2:], 0.0)
    np.testing.assert_array_equal(tr.sensitivity[2:, :2], 0.0)


M, KW, V0, GAP = 2.0, 1.0e6, 1.0, 1.0e-3  # two free masses: reduced mass 1, w0 = 1000 rad/s


def _restitution_and_loss(k, c):
    """The paper's law ``k z + c zd`` (unloading ``k z``) on two free masses: restitution
    ``exp(-xi phi)`` and the contact loss time (the closed form of
    tests/vibroimpact/dynamics/test_kernel.py)."""
    xi, w0 = c / (2.0 * np.sqrt(k)), np.sqrt(k)
    phi = np.arccos(xi) / np.sqrt(1 - xi**2) if xi < 1 else np.arccosh(xi) / np.sqrt(xi**2 - 1)
    return np.exp(-xi * phi), GAP / V0 + (phi + np.pi / 2) / w0


@pytest.mark.parametrize("xi", [0.05, 0.3, 1.5])
def test_coefficient_sensitivities_of_restitution_and_contact_time(xi):
    """d(rebound velocity)/d(k, c) and d(relative position at the end)/d(k, c) through an
    onset, the switch to unloading and the loss, against the closed form's derivatives
    (central differences of the formula, accurate to ~1e-10)."""
    c = float(2 * xi * np.sqrt(KW))
    sc = Scenario(m1=M, m2=M, k1=0, c1=0, A=0, frequency=1, g=9.81, initial=(0, 0, GAP, -V0))
    law = ForceLaw.parse(f"{KW!r}*z + {c!r}*zd")
    t_end = 0.02
    tr = simulate(sc, law, (0.0, t_end), tolerances=TIGHT, sensitivities="coefficients")
    assert list(tr.event_kind) == [K.EV_ONSET, K.EV_UNLOAD, K.EV_LOSS]
    assert tr.sensitivity_names == ("z", "zd")
    e0, t_loss = _restitution_and_loss(KW, c)
    for j, (k_of, c_of) in enumerate([(1.0, 0.0), (0.0, 1.0)]):
        d = 1e-6 * (KW * k_of + c * c_of)
        (ep, tp), (em, tm) = (
            _restitution_and_loss(KW + s * d * k_of, c + s * d * c_of) for s in (1.0, -1.0)
        )
        dv = -V0 * (ep - em) / (2 * d)  # the rebound dzeta = -e V0
        dzeta = dv * (t_end - t_loss) + e0 * V0 * (tp - tm) / (2 * d)
        S = tr.sensitivity[:, j]
        # measured within 1e-9 relative at rtol 1e-11
        assert S[1] - S[3] == pytest.approx(dv, rel=1e-7)
        assert S[0] - S[2] == pytest.approx(dzeta, rel=1e-7)
        # the loss time's own derivative (the onset's does not depend on the law)
        assert tr.event_time_sensitivity[2, j] == pytest.approx((tp - tm) / (2 * d), rel=1e-7)
        assert tr.event_time_sensitivity[0, j] == 0.0


# ------------------------------------------------- every event kind, central differences
PAPER, LIGHT = load_scenario("paper"), load_scenario("light")
CASES = {
    "paper": (PAPER, PAPER.law.to_text()),
    "clipping": (PAPER, "2e8*z - 1e12*z^2 + 1e7*zd"),  # release and resume
    "unloading terms": (PAPER, "1e8*z + 2e6*zd; unloading: 3e6*zd"),
    "hertz": (PAPER, "1e9*z^1.5 + 2e9*z^1.5*zd"),  # reload; a fractional power
    "recontact": (LIGHT, LIGHT.law.with_coefficients([2.3e10, 5.5e11]).to_text()),
    "supports and mass loss": (PAPER.replace(k3=1e12, mass_loss=0.01), PAPER.law.to_text()),
    "quadratic damping": (PAPER, "2e8*z + 3e6*zd + 1e7*zd^2"),
}


def _law_with(law, coef):
    n = len(law.coefficients)
    out = law.with_coefficients(coef[:n])
    return out.with_unloading(coefficients=coef[n:]) if law.unloading else out


@pytest.mark.parametrize("flight", ["closed", "integrate"])
@pytest.mark.parametrize("name", list(CASES))
def test_sensitivities_match_central_differences(name, flight):
    """The state's, the force's and the penetration's sensitivities, on both free-flight
    paths (the closed form's transition matrix; the integrator's steps)."""
    sc, text = CASES[name]
    law = ForceLaw.parse(text)
    tol, T = Tolerances(rtol=1e-10, free_flight=flight), sc.period
    y0 = simulate(sc, law, (0.0, 5 * T), tolerances=tol).y_final  # away from rest
    te = np.linspace(5 * T, 8 * T, 301)
    tr = simulate(sc, law, (5 * T, 8 * T), y0=y0, t_eval=te, tolerances=tol, sensitivities="all")
    coef = np.array(law.coefficients + law.unloading_coefficients)
    x, v = sc.scales()
    s4 = np.array([x, v, x, v])
    size = np.concatenate([s4, np.abs(coef)])  # the size of a perturbation per column
    dy, dF, dZ = [], [], []
    for j in range(size.size):
        runs = []
        for sign in (1.0, -1.0):
            y, c = y0.copy(), coef.copy()
            if j < 4:
                y[j] += sign * 1e-6 * size[j]
            else:
                c[j - 4] += sign * 1e-6 * size[j]
            runs.append(
                simulate(sc, _law_with(law, c), (5 * T, 8 * T), y0=y, t_eval=te, tolerances=tol)
            )
        dy.append((runs[0].y_final - runs[1].y_final) / (2e-6 * size[j]))
        dF.append((runs[0].force - runs[1].force) / (2e-6 * size[j]))
        z = [r.y[0] - r.y[2] for r in runs]
        dZ.append((z[0] - z[1]) / (2e-6 * size[j]))
    # state: scaled by the perturbation and the state's size; measured <= 9e-7
    err = np.abs(tr.sensitivity - np.array(dy).T) * size[None, :] / s4[:, None]
    assert err.max() < 1e-5
    # force, away from the events (a perturbed run switches a hair earlier or later):
    # scaled by the force's peak; measured <= 5e-5
    ev = np.sort(tr.event_t)
    k = np.clip(np.searchsorted(ev, te), 1, len(ev) - 1)
    far = np.minimum(np.abs(te - ev[k - 1]), np.abs(te - ev[k])) > 1e-3 * T
    ferr = np.abs(tr.force_sensitivity - np.array(dF)) * size[:, None] / np.abs(tr.force).max()
    assert ferr[:, far].max() < 5e-4
    # the penetration, at every sample (continuous at the events): scaled by the
    # perturbation and the motion's scale
    zerr = np.abs(tr.penetration_sensitivity - np.array(dZ)) * size[:, None] / x
    assert zerr.max() < 1e-5


def test_every_event_kind_was_differentiated():
    """The cases above cross every kind of switching surface over their span."""
    seen = set()
    for sc, text in CASES.values():
        law, T = ForceLaw.parse(text), sc.period
        tol = Tolerances(rtol=1e-10)
        y0 = simulate(sc, law, (0.0, 5 * T), tolerances=tol).y_final
        tr = simulate(sc, law, (5 * T, 8 * T), y0=y0, tolerances=tol, sensitivities="all")
        assert np.all(np.isfinite(tr.sensitivity))
        seen.update(tr.event_kind.tolist())
    assert seen == {K.EV_ONSET, K.EV_LOSS, K.EV_UNLOAD, K.EV_RELOAD, K.EV_RELEASE, K.EV_RESUME}


# ------------------------------------------------------------------ the period map
def test_exact_period_map_jacobian_is_more_accurate_than_finite_differences():
    """A period-2 orbit of a Hertz law: the exact Jacobian at the default tolerance is
    within 1e-6 of central differences at rtol 1e-13 (measured 6e-8); forward differences
    at the default tolerance are 100x further off (measured 3e-5)."""
    law = ForceLaw.parse("1e9*z**1.5 + 2e9*z**1.5*zd")
    ss = steady_state(PAPER, law)
    assert ss.regime == "P2"
    fine = StroboscopicMap(PAPER, law, Tolerances(rtol=1e-13))
    s = fine.scale
    truth = np.empty((4, 4))
    for j in range(4):
        e = np.zeros(4)
        e[j] = 1e-4 * s[j]
        a, b = (fine.advance(ss.y0 + sg * e, 2, remember=False) for sg in (1, -1))
        truth[:, j] = (a - b) / (2 * e[j])
    pm = StroboscopicMap(PAPER, law)
    exact, fd = pm.jacobian(ss.y0, 2), pm.fd_jacobian(ss.y0, 2)
    assert pm.n_exact == 1
    scaled = lambda J: np.abs(J - truth) * s[None, :] / s[:, None]  # noqa: E731
    assert scaled(exact).max() < 1e-6
    assert scaled(fd).max() > 10 * scaled(exact).max()


def test_a_permanent_set_takes_finite_differences():
    law = ForceLaw.parse("1.4e8*z + 8.24e6*zd; set: 0.3")
    pm = StroboscopicMap(PAPER, law)
    assert not pm.exact
    J = pm.jacobian(PAPER.initial_state())
    assert np.all(np.isfinite(J)) and pm.n_calls == 5 and pm.n_exact == 0
    with pytest.raises(InputError, match="permanent set"):
        simulate(PAPER, law, (0.0, 0.1), sensitivities="all")


def test_a_run_with_sensitivities_agrees_with_a_plain_run():
    """Its own steps (the sensitivities' error is controlled too), the same motion to the
    tolerance."""
    T = PAPER.period
    te = np.linspace(0.0, 10 * T, 500)
    a = simulate(PAPER, PAPER.law, (0.0, 10 * T), t_eval=te)
    b = simulate(PAPER, PAPER.law, (0.0, 10 * T), t_eval=te, sensitivities="coefficients")
    assert a.sensitivity is None and b.sensitivity.shape == (4, 2)
    assert b.force_sensitivity.shape == (2, te.size)
    x, v = PAPER.scales()
    np.testing.assert_allclose(a.y[0], b.y[0], atol=1e-6 * x)
    np.testing.assert_allclose(a.force, b.force, atol=1e-5 * np.abs(a.force).max())
    with pytest.raises(InputError, match="sensitivities"):
        simulate(PAPER, PAPER.law, (0.0, T), sensitivities="everything")


# ------------------------------------------------------------ the output-error Jacobian
@pytest.fixture(scope="module")
def span_record():
    from discovery.vibroimpact.dynamics.synthetic import synthesize
    from discovery.vibroimpact.verify import Reference

    rec = synthesize(PAPER, PAPER.law, periods=20, fs=20000, noise=0.01, seed=3)
    return Reference.from_measurement(rec, PAPER, n_boot=8, seed=0)


def _objective(model, span_record):
    from discovery.vibroimpact.fit.identification import _Objective, as_records

    return _Objective(as_records(PAPER, span_record), model, "I2", None, 10**6)


def _central(obj, x, h=1e-6):
    cols = []
    for i in range(x.size):
        e = np.zeros(x.size)
        e[i] = h
        cols.append((obj.residuals(x + e) - obj.residuals(x - e)) / (2 * h))
    return np.array(cols).T


def _models():
    from discovery.vibroimpact.explain.effects import Model, effect

    base = Model(ForceLaw.parse("1.5e8*z + 0.9e7*zd"))
    return {
        "law": (ForceLaw.parse("1.5e8*z + 0.9e7*zd"), [True, True]),
        "unloading damping": (base.with_effect(effect("unloading_damping"), 2e6), [True] * 3),
        "supports": (base.with_effect(effect("support_nonlinearity"), 1e11), [True, True, False]),
        "sensor lag": (base.with_effect(effect("sensor_lag"), 2e-5), [True, True, False]),
    }


@pytest.mark.parametrize("name", ["law", "unloading damping", "supports", "sensor lag"])
def test_output_error_jacobian_matches_central_differences(name, span_record):
    """The residuals' Jacobian on a record compared over its span: the law's coefficients
    (loading and unloading) from one run with the variational equations, through the
    onset blend, the sensor's lag (linear in the force) and the fold; a machine parameter
    and the lag's time constant by differences.  Measured within 4e-6 of central
    differences (relative, per column)."""
    model, exact = _models()[name]
    obj = _objective(model, span_record)
    cols, ok = obj._exact_columns()
    assert ok and [c is not None for c in cols] == exact
    x = np.linspace(1.1, 0.95, len(model.coefficients))
    n0 = obj.n
    J = obj.jacobian(x)
    # one run for the exact columns (the force's and the penetration's rows), one more per
    # column by differences (and the residual)
    assert obj.n - n0 <= 2 + exact.count(False)
    Jc = _central(obj, x)
    err = np.linalg.norm(J - Jc, axis=0) / np.linalg.norm(Jc, axis=0)
    assert err.max() < 1e-4


def test_a_nonlinear_observation_model_takes_differences(span_record):
    from discovery.vibroimpact.fit.identification import _Objective, as_records

    law = ForceLaw.parse("1.5e8*z + 0.9e7*zd")
    clipped = lambda imp: imp  # noqa: E731 - not declared linear in the force
    obj = _Objective(as_records(PAPER, span_record), law, "I2", None, 10**6, observe=clipped)
    assert not obj._exact_columns()[1]
    assert obj.jacobian(np.ones(2)).shape[1] == 2  # forward differences


def test_identify_with_the_exact_jacobian_needs_fewer_simulations(span_record, monkeypatch):
    """Same law as with forward differences (to the fit's tolerance), in fewer runs."""
    import importlib

    mod = importlib.import_module("discovery.vibroimpact.fit.identification")
    api = mod.identify
    start = ForceLaw.parse("1.5e8*z + 0.9e7*zd")
    exact = api(PAPER, span_record, start, check=False)
    monkeypatch.setattr(mod._Objective, "_exact_columns", lambda self: ([None, None], False))
    fd = api(PAPER, span_record, start, check=False)
    np.testing.assert_allclose(exact.law.coefficients, fd.law.coefficients, rtol=1e-4)
    assert exact.n_simulations < fd.n_simulations
    for k in exact.standard_errors:
        assert exact.standard_errors[k] == pytest.approx(fd.standard_errors[k], rel=0.02)


# ------------------------------------------------------------ the periodic orbit's
def _resolved(law, j, rel):
    from discovery.vibroimpact.dynamics.orbit_sensitivity import orbit_sensitivity

    c = np.array(law.coefficients)
    c[j] *= 1 + rel
    other = law.with_coefficients(c)
    return orbit_sensitivity(PAPER, other, steady_state(PAPER, other, tol=1e-12)).impacts[0]


@pytest.mark.parametrize(
    "text", ["2.06e8*z + 1.28e7*zd", "2.06e8*z + 1.28e7*zd + 2e10*z*zd", "1e9*z^1.5 + 2e9*z^1.5*zd"]
)
def test_orbit_sensitivities_match_resolved_steady_states(text):
    """How an impact's peak force, contact time and largest penetration move with each
    coefficient: (I - M)^-1 dPhi/dc and the events' derivatives, against central
    differences of steady states solved again at c (1 +- 1e-5).  Measured within 4e-7
    (integer powers) and 3.4e-5 (the Hertz law's period-2 orbit)."""
    from discovery.vibroimpact.dynamics.orbit_sensitivity import orbit_sensitivity

    law = ForceLaw.parse(text)
    ss = steady_state(PAPER, law, tol=1e-11)
    sens = orbit_sensitivity(PAPER, law, ss)
    assert sens.names == tuple(law.names) and len(sens.impacts) == ss.impacts
    for j, c in enumerate(law.coefficients):
        up, down = _resolved(law, j, 1e-5), _resolved(law, j, -1e-5)
        for q in ("peak_force", "contact_time", "max_penetration"):
            fd = (up[q] - down[q]) / (2e-5 * c)
            assert sens.impacts[0]["d_" + q][j] == pytest.approx(
                fd, rel=2e-4, abs=1e-6 * abs(up[q]) / c
            )
    el = sens.elasticities()[0]
    assert set(el) == {"peak_force", "contact_time", "max_penetration"}
    assert "orbit sensitivities" in str(sens)


def test_force_only_jacobian_matches_central_differences_and_saves_runs(monkeypatch):
    """A force-only record (compared with the law's steady orbit, aligned on an onset that
    moves with the coefficients): the Jacobian from the orbit's derivatives against central
    differences (measured 3.6e-5 and 6.7e-4 per column), and identify reaches the same law
    in fewer runs than with forward differences."""
    import importlib

    from discovery.vibroimpact.dynamics.synthetic import synthesize

    mod = importlib.import_module("discovery.vibroimpact.fit.identification")
    E = synthesize(PAPER, PAPER.law, periods=20, fs=20000).impulse(PAPER.period)
    start = ForceLaw.parse("1.5e8*z + 0.9e7*zd")
    obj = mod._Objective(mod.as_records(PAPER, E), start, "I2", None, 10**6)
    assert obj._exact_columns()[1]
    x = np.array([1.2, 1.3])
    err = np.linalg.norm(obj.jacobian(x) - _central(obj, x), axis=0)
    assert np.all(err / np.linalg.norm(_central(obj, x), axis=0) < 5e-3)
    exact = mod.identify(PAPER, E, start, check=False)
    monkeypatch.setattr(mod._Objective, "_exact_columns", lambda self: ([None, None], False))
    fd = mod.identify(PAPER, E, start, check=False)
    np.testing.assert_allclose(exact.law.coefficients, fd.law.coefficients, rtol=1e-3)
    assert exact.n_simulations < fd.n_simulations


def test_steady_cli_prints_and_writes_the_sensitivities(tmp_path, capsys):
    from discovery.cli import main

    law = "2.06e8*z + 1.28e7*zd + 2e10*z*zd"
    assert main(["steady", "--law", law, "--sensitivities", "--out", str(tmp_path / "s")]) == 0
    out = capsys.readouterr().out
    assert "impact 1 peak force: z +" in out and "contact time" in out
    import json

    saved = json.loads((tmp_path / "s" / "summary.json").read_text())["sensitivities"]
    assert set(saved["elasticities"][0]["peak_force"]) == {"z", "zd", "z*zd"}
    assert main(["steady", "--law", "1.4e8*z + 8.24e6*zd; set: 0.3", "--sensitivities"]) == 2
    err = capsys.readouterr().err
    assert "permanent set" in err and err.count("\n") == 1 and "Traceback" not in err
