"""scripts/gap_precision.py: how often each check flags right answers, and wrong ones."""

import importlib.util
import json
from pathlib import Path

SCRIPT = Path(__file__).parents[2] / "scripts" / "gap_precision.py"
spec = importlib.util.spec_from_file_location("gap_precision", SCRIPT)
gap_precision = importlib.util.module_from_spec(spec)
spec.loader.exec_module(gap_precision)


def test_flagged_answers_are_counted_right_or_wrong_per_kind(tmp_path):
    rows = [  # "stay there" read as only going there: a claim left out, and wrong
        {"variant": "C", "nl": "Go to the dock and stay there.", "aps": ["at_dock"],
         "stl": "F(at_dock)", "equivalent": False},
        {"variant": "C", "nl": "Go to the dock and stay there.", "aps": ["at_dock"],
         "stl": "F(G(at_dock))", "equivalent": True},
        {"variant": "none", "nl": "Go to the dock and stay there.", "aps": ["at_dock"],
         "stl": "F(at_dock)", "equivalent": False}]  # another variant: not counted
    (tmp_path / "handwritten-grounded").mkdir()
    (tmp_path / "handwritten-grounded" / "samples.jsonl").write_text(
        "\n".join(json.dumps(r) for r in rows))
    counts = gap_precision.flagged_answers(tmp_path, "C")["handwritten-grounded"]
    assert counts["claims"] == {"wrong": 1} and not counts["order"]
