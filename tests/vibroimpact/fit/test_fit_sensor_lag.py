"""A known force sensor's lag in the fit: ``discover(..., sensor_lag=tau)`` and
``fit_contact_models(..., sensor_lag=tau)`` regress the force before the lag and compare
every simulated force as the sensor sees it; ``vidi fit`` takes the lag the machine's
calibration found (or ``--sensor-lag``), as ``vidi verify`` and ``vidi explain`` do."""

import json

import numpy as np
import pytest

from discovery.cli import main
from discovery.vibroimpact.data.measurement import Measurement
from discovery.vibroimpact.explain.effects import Model
from discovery.vibroimpact.fit.contact_fit import fit_contact_models
from discovery.vibroimpact.fit.discovery import discover
from discovery.vibroimpact.fit.records import model_parts
from discovery.vibroimpact.model.contact_models import parse_law
from discovery.vibroimpact.verify.sensors import observation
from tests.vibroimpact.explain.test_explain import _record, lagged_record

TAU = 3e-4  # a 0.3 ms sensor on the paper's 2.4 ms contact


def test_unlagged_inverts_a_first_order_sensor_in_closed_form():
    """``F + tau dF/dt`` of a sine seen through the sensor (its steady response
    ``(sin wt - w tau cos wt) / (1 + (w tau)^2)``) is the sine, to the central differences'
    ``(w h)^2 / 6``."""
    w, tau = 2 * np.pi * 50.0, 1e-3
    t = np.arange(0.0, 0.2, 1e-5)
    seen = (np.sin(w * t) - w * tau * np.cos(w * t)) / (1 + (w * tau) ** 2)
    rec = Measurement(t, seen, {}, source="sine")
    back = rec.unlagged(tau)
    inner = slice(1, -1)  # one-sided differences at the ends
    assert np.max(np.abs(back.F[inner] - np.sin(w * t[inner]))) < (w * 1e-5) ** 2
    assert rec.unlagged(0.0) is rec and back.t is rec.t


def test_a_known_lag_is_read_where_the_model_has_none():
    lag = observation({"sensor_lag": TAU})
    law = parse_law("2e8*z + 1e7*zd")
    assert model_parts(law, lag)[2] is lag
    named = parse_law("kelvin-voigt: k=2e8, c=1e7")
    assert model_parts(named, lag)[2] is lag and model_parts(named)[2] is None
    own = Model(law, observation={"sensor_lag": 1e-4})
    assert model_parts(own, lag)[2] is not lag  # an explained model's own lag is fitted


@pytest.fixture(scope="module")
def record(paper):
    return lagged_record(paper, tau=TAU)


def test_discover_recovers_the_law_behind_a_known_lag(paper, record):
    """Read through the sensor, the law's force is 17 % off; without the lag the fit
    selects another support (``z^2 + z*zd + zd^2``, I2 0.27, not consistent); with it the
    true law to 0.3 %, its 95 % intervals holding the truth."""
    plain = discover(paper, record, n_boot_intervals=0, progress=False).selected
    seen = discover(paper, record, sensor_lag=TAU, n_boot_intervals=8, progress=False)
    sel = seen.selected
    assert not plain.consistent and sel.consistent
    assert list(sel.law.names) == ["z", "zd"]
    for name, truth in paper.law.as_dict().items():
        assert sel.law.as_dict()[name] == pytest.approx(truth, rel=5e-3)
        lo, hi = sel.intervals.bounds[name]
        assert lo <= truth <= hi
    assert seen.settings["sensor_lag"] == TAU
    assert f"a lag of {TAU * 1e3:.4g} ms" in str(seen)


def test_the_named_models_fit_behind_a_known_lag(paper):
    """A Kelvin-Voigt record through the sensor: no named model is consistent without the
    lag; with it Kelvin-Voigt is selected, its intervals holding the truth."""
    kv = parse_law("kelvin-voigt: k=2.06e8, c=1.28e7")
    rec = lagged_record(paper, tau=TAU, law=kv)
    models = ["kelvin-voigt", "hertz-damper"]
    plain = fit_contact_models(paper, rec, models=models, n_boot=0, progress=False)
    seen = fit_contact_models(paper, rec, models=models, n_boot=8, sensor_lag=TAU, progress=False)
    assert plain.selected is None and seen.selected == "kelvin-voigt"
    fit = next(f for f in seen.fits if f.model == "kelvin-voigt")
    for name, truth in (("k", 2.06e8), ("c", 1.28e7)):
        lo, hi = fit.intervals[name]
        assert lo <= truth <= hi
    assert seen.settings["sensor_lag"] == TAU and "a lag of 0.3 ms" in str(seen)


def test_vidi_fit_takes_the_lag_the_calibration_found(tmp_path, record, capsys):
    record.to_csv(tmp_path / "rec.csv")
    words = ["fit", "--data", str(tmp_path / "rec.csv"), "--no-pdf", "--intervals", "0"]
    assert main([*words, "--out", str(tmp_path / "a")]) == 0
    summary = json.loads((tmp_path / "a" / "summary.json").read_text())
    found = summary["machine"]["parameters"]["force_lag"]["record"]
    assert summary["fit_settings"]["sensor_lag"] == found > 0
    assert summary["selected"]["consistent"] is True
    out = capsys.readouterr().out
    assert "note: the simulated force is compared as a force sensor with a lag of" in out
    # 0: none (the force as recorded, the true support not consistent with it)
    assert main([*words, "--sensor-lag", "0", "--out", str(tmp_path / "b")]) == 0
    plain = json.loads((tmp_path / "b" / "summary.json").read_text())
    assert plain["fit_settings"]["sensor_lag"] == 0.0
    assert plain["selected"]["consistent"] is False
    capsys.readouterr()
    assert main([*words, "--sensor-lag", "-1", "--out", str(tmp_path / "c")]) == 2
    err = capsys.readouterr().err.strip()
    assert "--sensor-lag: '-1' is out of range" in err and "\n" not in err
    assert not (tmp_path / "c").exists()


def test_the_campaigns_joint_fit_takes_the_calibrations_lag(paper, record):
    """``advise --until-settled`` fits its records jointly with what the calibration found:
    the machine's scale range and the force sensor's lag (``Calibration.sensor_lag``), as
    ``vidi fit`` does; the sheets add nothing."""
    from types import SimpleNamespace

    from discovery.vibroimpact.advise.campaign_loop import _machines
    from discovery.vibroimpact.calibration import calibrate

    state = SimpleNamespace(sheets=[paper], records=[record])
    machines, found = _machines(state, SimpleNamespace(machine="record", seed=0))
    assert found["sensor_lag"] == pytest.approx(TAU, rel=0.05)
    assert found["machine_scale"][0] < 1.0 < found["machine_scale"][1]
    assert _machines(state, SimpleNamespace(machine="sheet", seed=0)) == ([paper], {})
    assert calibrate([paper], [lagged_record(paper, tau=TAU)]).sensor_lag == found["sensor_lag"]
    assert calibrate([paper], [_record(paper, paper.law, seed=4)]).sensor_lag == 0.0


def test_vidi_identify_takes_the_lag_the_calibration_found(tmp_path, record, capsys):
    """``vidi identify`` reads the simulated force through the sensor the calibration found,
    as fit, verify and explain do: the true law to 0.2 %, consistent, its intervals holding
    it; with ``--sensor-lag 0`` (what it did before) the law came out 11 % and 16 % soft."""
    record.to_csv(tmp_path / "rec.csv")
    words = ["identify", "--data", str(tmp_path / "rec.csv"), "--start", "1.5e8*z + 1e7*zd"]
    words += ["--intervals", "8", "--quiet"]
    assert main([*words, "--out", str(tmp_path / "a")]) == 0
    s = json.loads((tmp_path / "a" / "summary.json").read_text())
    assert s["sensor_lag"] == s["machine"]["parameters"]["force_lag"]["record"] > 0
    assert s["consistent"] is True
    for name, truth in (("z", 2.06e8), ("zd", 1.28e7)):
        assert s["coefficients"][name] == pytest.approx(truth, rel=2e-3)
        lo, hi = s["intervals"]["bounds"][name]
        assert lo <= truth <= hi
    assert "a lag of" in capsys.readouterr().out
    assert main([*words, "--sensor-lag", "0", "--out", str(tmp_path / "b")]) == 0
    plain = json.loads((tmp_path / "b" / "summary.json").read_text())
    assert plain["sensor_lag"] == 0.0 and plain["consistent"] is False
    assert plain["coefficients"]["z"] < 0.95 * 2.06e8


def test_vidi_landscape_reads_the_force_through_the_calibration_s_sensor(tmp_path, record):
    """``vidi landscape`` against a lagged record compares every point's force as the sensor
    the calibration found sees it: its lowest I2 at the true law, consistent there; with
    ``--sensor-lag 0`` (what it did before) no point is consistent and the lowest lies at
    the grid's edge, a damping 16 % low."""
    record.to_csv(tmp_path / "rec.csv")
    words = ["landscape", "--data", str(tmp_path / "rec.csv"), "--grid", "5x5", "--quiet"]
    words += ["--range0", "1.86e8:2.26e8", "--range1", "1.08e7:1.48e7", "--workers", "1"]
    found = {}
    for name, extra in (("a", []), ("b", ["--sensor-lag", "0"])):
        assert main([*words, *extra, "--out", str(tmp_path / name)]) == 0
        s = json.loads((tmp_path / name / "summary.json").read_text())
        i, j = np.unravel_index(np.nanargmin(np.array(s["I2"], dtype=float)), (5, 5))
        found[name] = (s["sensor_lag"], s["alpha1"][i], s["alpha2"][j], np.sum(s["consistent"]))
    lag, z, zd, n_consistent = found["a"]
    assert lag > 0 and (z, zd) == (2.06e8, 1.28e7) and n_consistent >= 1
    lag, z, zd, n_consistent = found["b"]
    assert lag == 0.0 and zd == 1.08e7 and n_consistent == 0
