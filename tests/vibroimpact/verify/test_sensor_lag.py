"""A force sensor's lag in the verdict: ``verify(..., sensor_lag=tau)`` compares the
simulated force as the sensor sees it, and ``vidi verify`` passes the lag the machine's
calibration found (or ``--sensor-lag``)."""

import json

import pytest

from discovery.cli import main
from discovery.errors import InputError
from discovery.vibroimpact.verify import verify
from discovery.vibroimpact.verify.sensors import first_order_lag, observation
from tests.vibroimpact.explain.test_explain import lagged_record


@pytest.mark.parametrize("tau", [1e-4, 3e-4])
def test_the_true_law_is_consistent_as_its_sensor_sees_it(paper, tau):
    """The paper's record through a first-order sensor: the true law is rejected against
    the contact force (I2 0.30 at 0.1 ms, 0.61 at 0.3 ms) and consistent against the
    force the sensor sees."""
    rec = lagged_record(paper, tau=tau)
    plain = verify(paper, rec, paper.law)
    seen = verify(paper, rec, paper.law, sensor_lag=tau)
    assert not plain.consistent and seen.consistent
    assert seen.evaluation.criteria["I2"] < plain.evaluation.criteria["I2"] / 10
    assert f"a lag of {tau * 1e3:.4g} ms" in str(seen)
    assert seen.settings["sensor_lag"] == tau and plain.settings["sensor_lag"] == 0.0


def test_a_sensor_lag_is_one_checked_setting(paper):
    rec = lagged_record(paper, tau=1e-4)
    with pytest.raises(InputError, match=r"sensor_lag must be a number in \[0, 0.005\]"):
        verify(paper, rec, paper.law, sensor_lag=-1e-4)
    assert observation({}) is None and observation(None) is None
    lag = observation({"sensor_lag": 2e-4})
    assert lag.linear and callable(lag.at)
    assert first_order_lag.__module__ == "discovery.vibroimpact.verify.sensors"


def test_vidi_verify_takes_the_lag_the_calibration_found(tmp_path, capsys):
    from discovery import load_scenario

    paper = load_scenario("paper")
    rec = lagged_record(paper, tau=3e-4)
    rec.to_csv(tmp_path / "rec.csv")
    words = ["verify", "--data", str(tmp_path / "rec.csv"), "--n-boot", "8"]
    assert main([*words, "--out", str(tmp_path / "a")]) == 0
    summary = json.loads((tmp_path / "a" / "summary.json").read_text())
    found = summary["machine"]["parameters"].get("force_lag")
    assert found, "the calibration finds the sensor's lag"
    assert summary["verify_settings"]["sensor_lag"] == found["record"]
    assert summary["consistent"] is True
    assert "lag of" in capsys.readouterr().out
    # given: that lag; 0: none (the contact force, the true law rejected)
    assert main([*words, "--sensor-lag", "0", "--out", str(tmp_path / "b")]) == 0
    plain = json.loads((tmp_path / "b" / "summary.json").read_text())
    assert plain["verify_settings"]["sensor_lag"] == 0.0 and plain["consistent"] is False
    capsys.readouterr()
    assert main([*words, "--sensor-lag", "-1", "--out", str(tmp_path / "c")]) == 2
    err = capsys.readouterr().err.strip()
    assert "--sensor-lag: '-1' is out of range" in err and "\n" not in err
    assert not (tmp_path / "c").exists()
