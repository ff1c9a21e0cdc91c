"""bench/corpus_bench.py's judgement of what each side found, against the record's truth
(the bench itself runs both codes on the corpus: ``make bench-corpus``)."""

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "bench"))
corpus_bench = pytest.importorskip("corpus_bench")


def test_a_finding_is_read_from_each_command_s_summary():
    explain = {"iterations": [{"effect": "unloading_damping"}, {"effect": None}], "consistent": 1}
    assert corpus_bench.found("explain", explain) == {
        "named": ["unloading_damping"],
        "consistent": True,
    }
    fit = {"selected": {"terms": ["zd", "z"], "consistent": False}}
    assert corpus_bench.found("fit", fit) == {"terms": ["z", "zd"], "consistent": False}
    assert corpus_bench.found("verify", {"consistent": True}) == {"consistent": True}


def test_right_is_the_truth_s_effects_support_and_verdict():
    both = {"law": "1.5e8*z + 4e6*zd", "hidden_effect": ["unloading_damping", "offset"]}
    clean = {"law": "1.5e8*z + 4e6*zd", "hidden_effect": None}
    coupled = {
        "law": "1.5e8*z + 3e6*zd + 8e10*z*zd",
        "hidden_effect": "penetration_velocity_coupling",
    }
    right = corpus_bench.right
    assert right("explain", {"named": ["offset", "unloading_damping"]}, both)
    assert not right("explain", {"named": ["unloading_damping"]}, both)
    assert right("explain", {"named": []}, clean)
    assert right("fit", {"terms": ["z", "z*zd", "zd"]}, coupled)
    assert not right("fit", {"terms": ["z", "zd"]}, coupled)
    # a truth outside the library (an unloading branch) does not judge the support
    assert right("fit", {"terms": ["z", "zd"]}, both) is None
    # a truth outside the law grammar is not verified
    offset = {"law": "2e8*(z - 0.0015) + 5e6*zd for z > 0.0015 (0 otherwise)"}
    assert corpus_bench.words("verify", Path("c11"), offset) is None


def test_the_summary_counts_agreement_and_rightness_over_the_records():
    def side(found, right, seconds):
        return {"found": found, "right": right, "seconds": seconds}

    rows = {
        "c01": {
            "explain": {
                "new": side({"named": []}, True, 2.0),
                "old": side({"named": []}, True, 4.0),
                "ratio": 0.5,
                "same": True,
            }
        },
        "c02": {
            "explain": {
                "new": side({"named": ["a"]}, True, 3.0),
                "old": side({"named": []}, False, 4.0),
                "ratio": 0.75,
                "same": False,
            }
        },
        "c03": {
            "explain": {
                "new": side({"error": "x"}, None, None),
                "old": side({"named": []}, None, 4.0),
                "ratio": None,
                "same": False,
            }
        },
    }
    s = corpus_bench.summary(rows, "explain")
    assert (s["ratio"], s["records"], s["same"], s["judged"]) == (0.625, 3, 1, 2)
    assert (s["right_new"], s["right_old"]) == (2, 1)
    assert [d["record"] for d in s["differ"]] == ["c02", "c03"]
