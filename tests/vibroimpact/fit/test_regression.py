"""Sparse certified regression (discovery.vibroimpact.fit.regression.ConstrainedSparseRegressor)."""

import itertools
import math
import pickle
import warnings

import numpy as np
import pytest
from sklearn.base import clone
from sklearn.exceptions import NotFittedError
from sklearn.utils import estimator_checks
from sklearn.utils.validation import check_is_fitted

import discovery.vibroimpact.fit.constrained_lsq as constrained_lsq
from constraints import certify, constraint_rows
from constraints.errors import SolverError
from discovery.errors import InputError
from discovery.vibroimpact.data.samples import contact_samples
from discovery.vibroimpact.dynamics.synthetic import synthesize
from discovery.vibroimpact.fit.certified_fit import CertifiedSparseFit, RegressionSettings
from discovery.vibroimpact.fit.regression import SELECTIONS, ConstrainedSparseRegressor
from discovery.vibroimpact.model.law import ForceLaw
from discovery.vibroimpact.model.library import Library

LAW11 = "2.06e8*z + 1.28e7*zd"
LAW11_ZZD = "2.06e8*z + 1.28e7*zd + 2e10*z*zd"
HC = "2e10*z^1.5 + 5e11*z^1.5*zd"
LIB = "poly:3+hc"

CASES = [("paper", LAW11), ("paper", LAW11_ZZD), ("light", HC)]


@pytest.fixture(scope="module")
def clean(paper, light):
    """Noise-free steady-state records (20 periods) of the three laws: contact samples."""
    sc = {"paper": paper, "light": light}
    return {
        (s, law): contact_samples(synthesize(sc[s], ForceLaw.parse(law), periods=20))
        for s, law in CASES
    }


@pytest.fixture(scope="module")
def clean_fits(clean):
    return {
        k: ConstrainedSparseRegressor(library=LIB).fit(cs.X, cs.F, groups=cs.impact)
        for k, cs in clean.items()
    }


def _rel_errors(law_text, est):
    true = ForceLaw.parse(law_text).as_dict()
    got = est.law_.as_dict()
    assert set(got) == set(true), (got, true)
    return {k: abs(got[k] / v - 1) for k, v in true.items()}


# ------------------------------------------------------------------ noise-free


@pytest.mark.parametrize("case", CASES, ids=["paper-11", "paper-11+zzd", "light-hc"])
def test_noise_free_exact_support_and_coefficients(case, clean_fits):
    est = clean_fits[case]
    err = _rel_errors(case[1], est)
    # the data are the law to integrator/rounding precision (measured ~1e-12): 1e-6 relative
    assert max(err.values()) < 1e-6, err
    assert est.certificate_.holds
    assert est.support_.sum() == len(err)
    np.testing.assert_array_equal(est.coef_ != 0, est.support_)


@pytest.mark.parametrize("case", CASES, ids=["paper-11", "paper-11+zzd", "light-hc"])
def test_every_candidate_is_certified(case, clean_fits):
    est = clean_fits[case]
    assert len(est.candidates_) >= 2
    for c in est.candidates_:
        coef = np.array([c.coefficients.get(n, 0.0) for n in est.library_.names])
        cert = est.certify(coef)
        assert cert.holds and cert.worst_violation <= 1e-7, (c.terms, cert.worst_violation)
    # candidates are sorted by the score (bic)
    bics = [c.bic for c in est.candidates_]
    assert bics == sorted(bics)


@pytest.mark.parametrize("selection", SELECTIONS)
@pytest.mark.parametrize("case", CASES, ids=["paper-11", "paper-11+zzd", "light-hc"])
def test_every_selection_method_returns_a_certified_law(case, selection, clean):
    cs = clean[case]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        est = ConstrainedSparseRegressor(library=LIB, selection=selection, grid=201)
        est.fit(cs.X, cs.F, groups=cs.impact)
    assert est.certificate_.holds
    # on noise-free data every method fits the force to ~1e-6 of its scale (measured
    # <= 1e-9 relative RMS; spurious tiny terms of pysindy methods change nothing)
    r = est.predict(cs.X) - cs.F
    assert np.sqrt(np.mean(r**2)) < 1e-6 * np.sqrt(np.mean(cs.F**2))
    # the exact support and coefficients by best-subset and, on the paper, by the l1 path
    if selection == "best-subset" or (selection == "l1-path" and case[0] == "paper"):
        assert max(_rel_errors(case[1], est).values()) < 1e-6


# --------------------------------------------------------------- noisy run-up


def _runup(sc, law, periods, noise, seed):
    m = synthesize(
        sc, ForceLaw.parse(law), periods=periods, fs=20000, noise=noise, seed=seed, from_rest=True
    )
    return contact_samples(m)


@pytest.mark.slow
@pytest.mark.parametrize(
    "case, periods",
    [(CASES[0], 300), (CASES[1], 300), (CASES[2], 30)],
    ids=["paper-11", "paper-11+zzd", "light-hc"],
)
def test_one_percent_noise_over_20_seeds(case, periods, paper, light):
    sc = {"paper": paper, "light": light}[case[0]]
    true = ForceLaw.parse(case[1]).as_dict()
    exact, worst = 0, 0.0
    for seed in range(20):
        cs = _runup(sc, case[1], periods, 0.01, seed)
        est = ConstrainedSparseRegressor(library=LIB, grid=201).fit(cs.X, cs.F, groups=cs.impact)
        assert est.certificate_.holds
        got = est.law_.as_dict()
        if set(got) == set(true):
            exact += 1
            worst = max(worst, max(abs(got[k] / v - 1) for k, v in true.items()))
    # run-up records identify the terms: measured 20/20, 20/20, 19/20 exact supports and
    # worst errors 1.7 %, 1.94 %, 0.26 %; the specification is >= 95 % and <= 2 %
    assert exact >= 19, exact
    assert worst <= 0.02, worst


@pytest.mark.parametrize("seed", range(4))
def test_five_percent_noise_fit_is_certified(seed, paper, light):
    for sc, law, periods in ((paper, LAW11_ZZD, 300), (light, HC, 30)):
        cs = _runup(sc, law, periods, 0.05, seed)
        est = ConstrainedSparseRegressor(library=LIB).fit(cs.X, cs.F, groups=cs.impact)
        cert = est.certificate_
        # support may be wrong at 5 %; the conditions never break (tolerance: the
        # certificate's own 1e-7 of the force scale)
        assert cert.holds and cert.worst_violation <= 1e-7, (law, seed, cert.worst_violation)
        # certificate covers the data: the box contains every sample
        assert cs.zeta.max() <= est.box_.zeta_max and cs.dzeta.max() <= est.box_.zd_max


def test_noise_on_second_scenario_recovers_hunt_crossley(light):
    cs = _runup(light, HC, 30, 0.01, 1)
    est = ConstrainedSparseRegressor(library=LIB).fit(cs.X, cs.F, groups=cs.impact)
    # measured 0.26 % worst over 19 exact seeds; 1 % allows for platform differences
    assert max(_rel_errors(HC, est).values()) < 0.01


# ------------------------------------------------------- constraints are needed


@pytest.fixture(scope="module")
def hc_wrong_library(light, light_ss):
    """Hunt-Crossley data fitted with a library that lacks z^1.5: the unconstrained
    least squares on the full support goes non-dissipative / adhesive."""
    cs = contact_samples(synthesize(light, light.law, periods=20, ss=light_ss))
    est = ConstrainedSparseRegressor(library="z,z^2,zd,z*zd").fit(cs.X, cs.F, groups=cs.impact)
    return cs, est


def test_constrained_fit_certified_where_unconstrained_lstsq_is_not(hc_wrong_library):
    cs, est = hc_wrong_library
    full = [c for c in est.candidates_ if c.size == 4]
    assert len(full) == 1
    cand = full[0]
    assert cand.constrained  # a constraint was active at the solution
    lib = Library.parse(",".join(cand.terms))
    coef = np.array([cand.coefficients[n] for n in lib.names])
    conditions = ["non_adhesion", "dissipativity"]
    ok = certify(coef, lib.exponents, est.box_, conditions)
    assert ok.holds and ok.worst_violation <= 1e-7
    # plain numpy least squares on the same support breaks a condition by far more than
    # the 1e-7 tolerance (measured 7 % of the force scale)
    x = np.linalg.lstsq(lib.transform(cs.X), cs.F, rcond=None)[0]
    bad = certify(x, lib.exponents, est.box_, conditions)
    assert not bad.holds and bad.worst_violation > 1e-3
    # the price of the constraints: a larger residual, never a smaller one
    r_unc = float(np.sum((lib.transform(cs.X) @ x - cs.F) ** 2))
    assert cand.rss >= r_unc * (1 - 1e-9)


def test_selected_law_of_wrong_library_is_certified(hc_wrong_library):
    _, est = hc_wrong_library
    assert est.certificate_.holds and est.certificate_.worst_violation <= 1e-7


# ------------------------------------------------------------ best-subset exact


def _unphysical_data(seed=0, n=400):
    """Data from a non-dissipative polynomial (negative zd term): many supports need the
    constraints, so the branch and bound has real work."""
    rng = np.random.default_rng(seed)
    z = rng.uniform(0, 1e-3, n)
    v = rng.uniform(-0.5, 0.5, n)
    zd = np.maximum(v, 0)
    y = 2e8 * z - 4e6 * zd + 3e10 * z * zd + 1e11 * z**2 + rng.normal(0, 2e3, n)
    return np.column_stack([z, v]), y


def _reference_constrained_rss(prob, idx):
    """Certified least squares on a support, solved independently of the estimator:
    cvxpy + Clarabel with the same rows (rows that vanish on the support removed)."""
    import cvxpy as cp

    from constraints import solve

    x, rss = prob.precise(idx)
    if prob.feasible(idx, x):
        return rss
    Q, R = np.linalg.qr(prob.A[:, idx])
    keep = np.abs(prob.M[:, idx]).max(axis=1) > 0
    xv = cp.Variable(len(idx))
    pr = cp.Problem(
        cp.Minimize(cp.sum_squares(R @ xv - Q.T @ prob.b)),
        [prob.M[keep][:, idx] @ xv + prob.off[keep] >= 0],
    )
    solve(pr, "CLARABEL")
    r = prob.A[:, idx] @ xv.value - prob.b
    return float(r @ r)


@pytest.mark.parametrize("source", ["unphysical", "hc-on-poly2"])
def test_best_subset_is_exact_against_brute_force(source, light):
    if source == "unphysical":
        X, y = _unphysical_data(1)
        groups = None
    else:
        cs = _runup(light, HC, 30, 0.01, 3)
        X, y, groups = cs.X, cs.F, cs.impact
    est = ConstrainedSparseRegressor(library="poly:2", max_terms=3).fit(X, y, groups=groups)
    prob = est.certified_fit_._problem(X, y, np.ones(len(y)))
    n = len(est.library_)
    n_active = 0
    for k in (1, 2, 3):
        rss = {}
        for s in itertools.combinations(range(n), k):
            rss[s] = _reference_constrained_rss(prob, list(s))
            n_active += not prob.feasible(list(s), prob.precise(list(s))[0])
        best = min(rss.values())
        cand = [c for c in est.candidates_ if c.size == k]
        assert len(cand) == 1
        # same objective to the interior-point accuracy (~1e-8 relative): 1e-6
        assert cand[0].rss / prob.fscale**2 <= best * (1 + 1e-6), (k, cand[0].terms)
    assert n_active > 0  # the constraints mattered for some subsets


def test_constrained_solve_on_support_with_vanishing_rows():
    X, y = _unphysical_data(0)
    est = ConstrainedSparseRegressor(library="poly:2", max_terms=3).fit(X, y)
    prob = est.certified_fit_._problem(X, y, np.ones(len(y)))
    idx = [est.library_.names.index(n) for n in ("z", "z^2", "zd^2")]
    x, rss, active, solver = prob.fit_support(idx)
    assert active and solver == "CLARABEL"
    assert rss == pytest.approx(_reference_constrained_rss(prob, idx), rel=1e-6)


# ---------------------------------------------------------- predict, score, ...


def test_predict_is_the_law_and_the_library_model(clean_fits, clean):
    key = ("paper", LAW11_ZZD)
    est, cs = clean_fits[key], clean[key]
    rng = np.random.default_rng(0)
    X = np.column_stack([rng.uniform(-1e-4, 3e-4, 500), rng.uniform(-1, 1, 500)])
    p = est.predict(X)
    # contact conditions: no force without contact, never adhesive
    assert np.all(p[X[:, 0] <= 0] == 0) and np.all(p >= 0)
    np.testing.assert_array_equal(p, est.law_(X[:, 0], X[:, 1]))
    # in contact (and where P >= 0) predict is Theta @ coef_: the law and the library
    # agree term by term; relative 1e-12 covers summation order
    inside = X[:, 0] > 0
    lin = est.library_.transform(X) @ est.coef_
    np.testing.assert_allclose(
        p[inside], np.maximum(lin[inside], 0), rtol=1e-12, atol=1e-12 * np.abs(lin).max()
    )
    # on the training samples predict reproduces F (noise-free) to 1e-9 of peak force
    assert np.abs(est.predict(cs.X) - cs.F).max() < 1e-9 * cs.F.max()


def test_stability_frequencies(paper):
    cs = _runup(paper, LAW11, 60, 0.01, 0)
    est = ConstrainedSparseRegressor(library="poly:2")
    freq = est.stability(cs.X, cs.F, cs.impact, n_resamples=10, random_state=0)
    assert list(freq) == Library.parse("poly:2").names
    assert all(0.0 <= f <= 1.0 for f in freq.values())
    # easy data: the true terms are in every resample's support
    assert freq["z"] == 1.0 and freq["zd"] == 1.0
    # ... and the spurious ones are not always selected
    assert max(freq[k] for k in ("z^2", "z*zd", "zd^2")) < 1.0
    # deterministic for a fixed random_state
    assert est.stability(cs.X, cs.F, cs.impact, n_resamples=10, random_state=0) == freq


# --------------------------------------------------------------- bad input


@pytest.mark.parametrize(
    "kwargs, name",
    [
        (dict(selection="foo"), "selection"),
        (dict(scoring="x"), "scoring"),
        (dict(max_terms=0), "max_terms"),
        (dict(max_terms=2.5), "max_terms"),
        (dict(cv=1), "cv"),
        (dict(margin=-1), "margin"),
        (dict(box_margin=-0.5), "box_margin"),
        (dict(library="poly:0"), "poly"),
    ],
)
def test_bad_parameters_raise_input_error_naming_them(kwargs, name):
    X, y = _unphysical_data(0, 50)
    with pytest.raises(InputError, match=name):
        ConstrainedSparseRegressor(**kwargs).fit(X, y)


@pytest.mark.parametrize(
    "kwargs, name", [(dict(signs=[1, 1]), "signs"), (dict(margin="x"), "margin")]
)
def test_more_bad_parameters_raise_input_error(kwargs, name):
    X, y = _unphysical_data(0, 50)
    with pytest.raises(InputError, match=name):
        ConstrainedSparseRegressor(**kwargs).fit(X, y)


@pytest.mark.parametrize("box_margin", [0.0, 0.1])
def test_certificate_box_always_contains_the_data(box_margin):
    X, y = _unphysical_data(0, 200)
    est = ConstrainedSparseRegressor(library="poly:1", box_margin=box_margin).fit(X, y)
    assert est.box_.zeta_max == pytest.approx(X[:, 0].max() * (1 + box_margin), rel=1e-15)
    assert est.box_.zd_max == pytest.approx(X[:, 1].max() * (1 + box_margin), rel=1e-15)
    assert est.certificate_.domain == est.box_.as_dict()


@pytest.mark.parametrize(
    "X, y",
    [
        (np.zeros((5, 3)), np.zeros(5)),
        (np.zeros((5, 2)), np.zeros(4)),
        (np.array([[1e-4, 0.1], [2e-4, np.nan], [3e-4, 0.2]]), np.ones(3)),
        (np.column_stack([-np.ones(5), np.ones(5)]), np.ones(5)),  # never in contact
    ],
)
def test_bad_data_raise_input_error(X, y):
    with pytest.raises(InputError):
        ConstrainedSparseRegressor().fit(X, y)


# ------------------------------------------------------- infeasible supports


def _law11_data(seed=0, n=400, groups_of=20):
    """Samples of k zeta + c zd with the elastic term dominant, impacts of ``groups_of``
    samples: the best single term is z, which a dissipativity margin rules out."""
    rng = np.random.default_rng(seed)
    z = rng.uniform(0, 1e-3, n)
    v = rng.uniform(-0.5, 0.5, n)
    y = 2e8 * z + 1e5 * np.maximum(v, 0) + rng.normal(0, 1e2, n)
    return np.column_stack([z, v]), y, np.arange(n) // groups_of


def test_margin_skips_a_support_without_a_zd_term():
    X, y, g = _law11_data()
    # {z} has the smallest unconstrained residual of the one-term supports, but with a
    # margin Q = sum c zeta^a zd^(b-1) >= margin has no term to act on: infeasible
    est = ConstrainedSparseRegressor(library="z,zd", margin=1e4, max_terms=2, grid=201)
    est.fit(X, y, groups=g)
    assert [s["support"] for s in est.infeasible_] == [("z",)]
    assert "margin" in est.infeasible_[0]["reason"]
    assert sorted(c.terms for c in est.candidates_) == [("z", "zd"), ("zd",)]
    assert est.certificate_.holds
    assert est.coef_[est.library_.names.index("zd")] >= 1e4 * (1 - 1e-6)


@pytest.mark.parametrize(
    "kwargs, needle",
    [
        # every support is infeasible: {z} has no zd term, {zd} and {z, zd} need c_zd <= 0
        (dict(library="z,zd", signs=[1, -1]), "no proposed support"),
        # no term of the library can meet a margin at all
        (dict(library="z,z^2"), "impossible"),
    ],
)
def test_no_feasible_support_is_a_one_line_input_error(kwargs, needle):
    X, y, g = _law11_data()
    with pytest.raises(InputError, match=needle) as info:
        ConstrainedSparseRegressor(margin=1e4, max_terms=2, **kwargs).fit(X, y, groups=g)
    assert "\n" not in str(info.value)


# ----------------------------------------------------------- solver fallback


def _failing(monkeypatch, failing):
    real = constrained_lsq.solve  # the certified fit of a support solves here

    def solve(problem, solver=None, **options):
        if solver in failing:
            raise SolverError(
                f"solver {solver} failed (status 'solver_error')",
                status="solver_error",
                solver=solver,
            )
        return real(problem, solver, **options)

    monkeypatch.setattr(constrained_lsq, "solve", solve)


def test_solver_fallback_is_recorded(monkeypatch):
    _failing(monkeypatch, {"CLARABEL"})
    X, y = _unphysical_data(0)
    est = ConstrainedSparseRegressor(library="poly:2", max_terms=3).fit(X, y)
    assert est.fallbacks_
    for f in est.fallbacks_:
        assert (f["solver"], f["failed"], f["status"], f["stage"]) == (
            "OSQP",
            "CLARABEL",
            "solver_error",
            "fit",
        )
    constrained = [c for c in est.candidates_ if c.constrained]
    assert constrained  # the data need the constraints on some selected supports
    assert all(c.extra["solver"] == "OSQP" for c in constrained)
    assert all(c.extra["solver"] == "lstsq" for c in est.candidates_ if not c.constrained)
    assert {c.terms for c in constrained} <= {f["support"] for f in est.fallbacks_}
    assert est.certificate_.holds


def test_no_fallback_recorded_when_the_solver_works():
    X, y = _unphysical_data(0)
    est = ConstrainedSparseRegressor(library="poly:2", max_terms=3).fit(X, y)
    assert est.fallbacks_ == []
    assert {c.extra["solver"] for c in est.candidates_ if c.constrained} == {"CLARABEL"}


def test_failure_of_both_solvers_raises_and_is_never_skipped(monkeypatch):
    _failing(monkeypatch, {"CLARABEL", "OSQP"})
    X, y = _unphysical_data(0)
    with pytest.raises(SolverError, match="CLARABEL.*fallback.*OSQP") as info:
        ConstrainedSparseRegressor(library="poly:2", max_terms=3).fit(X, y)
    assert info.value.status == "solver_error"


# ------------------------------------------------------------- shared rows


def test_problem_rows_are_the_constraints_package_rows():
    X, y, _ = _law11_data()
    est = ConstrainedSparseRegressor(
        library="poly:2", margin=1e3, monotone=True, signs=[1, 1, 0, 0, 0]
    ).fit(X, y)
    prob = est.certified_fit_._problem(X, y, np.ones(len(y)))
    rows, rhs = constraint_rows(
        est.library_.exponents,
        est.box_,
        margin=1e3,
        monotone=True,
        signs=[1, 1, 0, 0, 0],
        force_unit=prob.fscale,
    )
    np.testing.assert_array_equal(prob.M, rows)
    np.testing.assert_array_equal(prob.off, rhs)
    assert np.any(rhs < 0)  # the margin is in the offsets, in units of the force scale


# ------------------------------------------------------------ cross-validation


def test_cross_validation_only_when_scored_by_it_or_asked(monkeypatch):
    X, y, g = _law11_data()
    made = []
    real = CertifiedSparseFit._problem

    def spy(self, *args):
        made.append(len(args[1]))
        return real(self, *args)

    monkeypatch.setattr(CertifiedSparseFit, "_problem", spy)
    kw = dict(library="poly:2", max_terms=3, cv=4, grid=101)
    bic = ConstrainedSparseRegressor(**kw).fit(X, y, groups=g)
    assert made == [len(y)]  # one problem: the fit, no fold
    assert all(math.isnan(c.cv_error) for c in bic.candidates_)
    made.clear()
    rep = ConstrainedSparseRegressor(**kw, cv_report=True).fit(X, y, groups=g)
    assert len(made) == 1 + 4 and all(n < len(y) for n in made[1:])
    assert all(0 <= c.cv_error < 1 for c in rep.candidates_)
    # reporting changes nothing else
    assert [(c.terms, c.bic) for c in rep.candidates_] == [
        (c.terms, c.bic) for c in bic.candidates_
    ]
    cv = ConstrainedSparseRegressor(**{**kw, "scoring": "cv"}).fit(X, y, groups=g)
    errs = [c.cv_error for c in cv.candidates_]
    assert errs == sorted(errs) and not any(math.isnan(e) for e in errs)
    assert {c.terms: c.cv_error for c in cv.candidates_} == {
        c.terms: c.cv_error for c in rep.candidates_
    }


# ------------------------------------------------------------------ stability


def test_stability_refits_with_the_weights_and_one_group_per_drawn_impact(monkeypatch):
    X, y, g = _law11_data(n=300, groups_of=30)
    w = np.random.default_rng(1).uniform(0.5, 2.0, y.size)
    seen = []
    real = CertifiedSparseFit.fit

    def spy(self, X, y, groups=None, sample_weight=None):
        seen.append((y.copy(), np.asarray(groups).copy(), np.asarray(sample_weight).copy()))
        return real(self, X, y, groups=groups, sample_weight=sample_weight)

    monkeypatch.setattr(CertifiedSparseFit, "fit", spy)
    est = ConstrainedSparseRegressor(library="z,zd", max_terms=2)
    est.stability(X, y, g, n_resamples=4, random_state=0, sample_weight=w)
    assert len(seen) == 4
    duplicated = 0
    for yr, gr, wr in seen:
        src = np.array([np.flatnonzero(y == v)[0] for v in yr])  # y values are unique
        np.testing.assert_array_equal(wr, w[src])
        # as many groups as impacts drawn, each one whole impact of the data
        assert np.unique(gr).size == 10 and np.all(np.bincount(gr) == 30)
        for k in np.unique(gr):
            assert np.unique(g[src[gr == k]]).size == 1
        duplicated += np.unique(g[src]).size < 10
    assert duplicated  # some draw repeats an impact: distinct ids were needed


def test_stability_follows_the_weights():
    # impacts 0-4 follow k zeta + c zd, impacts 5-9 a quadratic law; weight zero on the
    # latter leaves only the first law to find
    X, y, g = _law11_data(n=300, groups_of=30)
    late = g >= 5
    y = np.where(late, 5e11 * X[:, 0] ** 2 + 3e10 * X[:, 0] * np.maximum(X[:, 1], 0), y)
    w = np.where(late, 0.0, 1.0)
    est = ConstrainedSparseRegressor(library="poly:2", max_terms=3)
    freq = est.stability(X, y, g, n_resamples=6, random_state=0, sample_weight=w)
    assert freq["z"] == 1.0 and freq["zd"] == 1.0
    assert freq["z^2"] < 0.5 and freq["z*zd"] < 0.5
    # impacts of zero weight are no data: the same draws as without them
    early = ~late
    assert est.stability(X[early], y[early], g[early], n_resamples=6, random_state=0) == freq
    # without the weights the quadratic impacts pull the support to their terms
    free = est.stability(X, y, g, n_resamples=6, random_state=0)
    assert freq != free


# -------------------------------------------------- scikit-learn contract


_SKLEARN_CHECKS = [
    # the checks of sklearn.utils.estimator_checks that apply to a 2-column (zeta, dzeta)
    # estimator; the others fit on 3+ random columns, which this estimator refuses
    "check_estimator_cloneable",
    "check_estimator_repr",
    "check_no_attributes_set_in_init",
    "check_estimators_overwrite_params",
    "check_estimators_fit_returns_self",
    "check_do_not_raise_errors_in_init_or_set_params",
    "check_mixin_order",
    "check_parameters_default_constructible",
    "check_get_params_invariance",
    "check_set_params",
    "check_fit_idempotent",
    "check_fit_check_is_fitted",
    "check_n_features_in",
    "check_estimators_unfitted",
    "check_fit1d",
    "check_sample_weights_not_an_array",
    "check_sample_weights_not_overwritten",
    "check_sample_weights_shape",
    "check_supervised_y_no_nan",
]


@pytest.mark.parametrize("check", _SKLEARN_CHECKS)
def test_sklearn_estimator_checks(check):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        getattr(estimator_checks, check)(
            check, ConstrainedSparseRegressor(library="z,zd", max_terms=2, grid=51)
        )


def test_estimator_contract_on_contact_data():
    X, y, g = _law11_data()
    est = ConstrainedSparseRegressor(library="z,zd,z*zd", max_terms=2, grid=101)
    params = est.get_params()
    # unfitted: no learned attribute; check_is_fitted and predict raise NotFittedError
    assert not [a for a in vars(est) if a.endswith("_")]
    with pytest.raises(NotFittedError):
        check_is_fitted(est)
    with pytest.raises(NotFittedError):
        est.predict(X)
    # clone round trip; set_params returns the estimator and touches only the clone
    c = clone(est)
    assert type(c) is type(est) and c is not est and c.get_params() == params
    assert c.set_params(max_terms=1, cv_report=True) is c
    assert (c.max_terms, c.cv_report, est.max_terms, est.cv_report) == (1, True, 2, False)
    # fit returns self, keeps the parameters and learns only underscored attributes
    assert est.fit(X, y, groups=g) is est
    assert est.get_params() == params
    learned = set(vars(est)) - set(params)
    assert learned >= {"coef_", "support_", "candidates_", "infeasible_", "fallbacks_"}
    assert all(a.endswith("_") for a in learned), learned
    check_is_fitted(est)
    with pytest.raises(NotFittedError):
        check_is_fitted(clone(est))
    # refitting gives the same model; a pickled model predicts the same
    coef = est.coef_.copy()
    np.testing.assert_array_equal(est.fit(X, y, groups=g).coef_, coef)
    back = pickle.loads(pickle.dumps(est))
    np.testing.assert_array_equal(back.predict(X), est.predict(X))
    with pytest.raises(InputError, match="features"):
        est.predict(X[:, :1])


def test_contact_by_force_where_the_penetration_is_buried_in_its_noise():
    """Issue 48: a stiff contact whose peak penetration is a few noise deviations deep
    leaves no sample above five deviations of zeta, and the regression had no start; the
    force tells contact there (on a clean record, samples where the bodies overlap)."""
    from discovery import load_scenario
    from discovery.vibroimpact.data.measurement import Measurement

    sc = load_scenario("paper")
    law = ForceLaw.parse("2.06e9*z + 4e7*zd")  # ten times the paper's spring
    rec = synthesize(sc.with_law(law), law, periods=12, noise=0.01, seed=3)
    clean_f = contact_samples(rec, contact="force")
    # where the force says contact, the bodies overlap (the geometry holds them longer: the
    # loading-only damper's force ends before the penetration does)
    assert np.all(clean_f.zeta > 0) and len(clean_f.F) <= len(contact_samples(rec).F)
    rng = np.random.default_rng(0)
    z = rec.channels["w1"] - rec.channels["w2"]
    sd = 0.5 * float(np.max(z))  # the peak penetration two noise deviations deep
    ch = {
        k: v + rng.normal(0.0, sd, v.size) if k in ("w1", "w2") else v
        for k, v in rec.channels.items()
    }
    noisy = Measurement(rec.t, rec.F, ch, source="noisy positions")
    with pytest.raises(InputError, match="fewer than 10 contact samples"):
        contact_samples(noisy)
    by_force = contact_samples(noisy, contact="force")
    assert abs(len(by_force.F) - len(clean_f.F)) <= 0.05 * len(clean_f.F)
    assert np.all(by_force.F > 0)


# ------------------------------------------------- the core without sklearn


def test_the_estimator_and_its_sklearn_free_core_fit_alike():
    """The estimator is its core's fit: the same candidates, coefficients and certificate."""
    X, y, g = _law11_data()
    kw = dict(library="poly:2", max_terms=3, margin=1e3, grid=101)
    est = ConstrainedSparseRegressor(**kw).fit(X, y, groups=g)
    core = CertifiedSparseFit(RegressionSettings(**kw)).fit(X, y, groups=g)
    assert [(c.terms, c.coefficients, c.bic) for c in est.candidates_] == [
        (c.terms, c.coefficients, c.bic) for c in core.candidates_
    ]
    np.testing.assert_array_equal(est.coef_, core.coef_)
    np.testing.assert_array_equal(est.predict(X), core.predict(X))
    assert est.score(X, y) == pytest.approx(core.score(X, y), rel=1e-12)
    assert core.get_params() == {**RegressionSettings().__dict__, **kw}
    assert est.certified_fit_.get_params() == est.get_params()
    assert str(core).startswith("CertifiedSparseFit(max_terms=3, margin=1000.0")
    assert "support z + zd" in str(core)
    assert "not fitted" in str(CertifiedSparseFit())


def test_an_unfitted_core_raises_the_estimators_not_fitted_error():
    with pytest.raises(NotFittedError, match="CertifiedSparseFit"):
        CertifiedSparseFit().predict(np.zeros((3, 2)))


def test_a_fit_and_an_explain_import_no_scikit_learn():
    """The commands' regression is the sklearn-free core: a discovery's modules and a core
    fit load neither scikit-learn nor pandas (0.8 s of import; make bench times it)."""
    from tests.interpreter import loaded_after

    code = (
        "import numpy as np\n"
        "import discovery.vibroimpact.fit.discovery, discovery.vibroimpact.explain\n"
        "import discovery.cli.fit, discovery.cli.explain\n"
        "from discovery.vibroimpact.fit.certified_fit import CertifiedSparseFit\n"
        "rng = np.random.default_rng(0)\n"
        "X = np.column_stack([rng.uniform(0, 1e-3, 200), rng.uniform(-0.5, 0.5, 200)])\n"
        "y = 2e8 * X[:, 0] + 1e5 * np.maximum(X[:, 1], 0)\n"
        "CertifiedSparseFit().fit(X, y)"
    )
    out = loaded_after(code, ("sklearn", "pandas"))
    assert out == [], f"a fit imports {','.join(out)}"
