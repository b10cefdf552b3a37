"""`ara demo` with a translator: the errand is translated as `ara translate` would."""

import json

import pytest

from ara.coordination.demos import ERRANDS, run_demo
from ara.eval.translate.checks import gaps
from ara.eval.translate.confidence import DOUBT
from ara.eval.translate.request import Request
from ara.eval.translate.translator import Translator
from ara.grammars import parse

from conftest import needs_llama


@needs_llama
@pytest.mark.slow  # the help request's real round trip runs by default in test_protocol
@pytest.mark.parametrize("name", ["kitting", "tool"])
def test_an_errand_is_translated_repaired_and_its_gaps_reported(name, tmp_path, finetuned):
    """Tests the demo's translation path: the formula it plans from is the repaired
    translation, a warning names anything it still leaves out, and a note follows a
    formula the model doubts."""
    lines = []
    result = run_demo(name, tmp_path, Translator(finetuned), lines.append)
    errand = ERRANDS[name]
    assert result["source"].startswith("translated by gguf:")
    assert any(line.startswith("[STL, translated by") for line in lines)
    left_out = gaps(Request.of(errand.nl, errand.places), parse(result["stl"]))
    assert any(line.startswith("warning:") for line in lines) == bool(left_out)
    assert 0 < result["confidence"] <= 1  # the model's probability of the formula planned
    assert any(line.startswith("note:") for line in lines) == (result["confidence"] < DOUBT)
    assert json.loads((tmp_path / f"{name}.json").read_text())["stl"] == result["stl"]
