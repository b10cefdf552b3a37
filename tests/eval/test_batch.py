"""Translating a file of instructions: `ara translate-file` and ara.eval.translate.batch."""

import json
from pathlib import Path

import pytest

from ara.errors import ConfigError
from ara.eval.translate.batch import (
    done_lines,
    same_settings,
    settings_path,
    summarize,
    summary_table,
)
from ara.eval.translate.request_file import FileRequest, read_requests
from ara.eval.translate.translator import TranslatorConfig

from conftest import needs_llama, run_ara


def _write(path: Path, *lines: str) -> Path:
    path.write_text("".join(line + "\n" for line in lines), encoding="utf-8")
    return path


def test_requests_are_read_with_their_line_numbers_and_references(tmp_path):
    """Tests the input format: aps as a list or as a comma string, blank lines skipped,
    a reference put in canonical form, an id kept."""
    path = _write(tmp_path / "in.jsonl",
                  '{"nl": "never enter the lab", "aps": ["enter_lab"]}',
                  "",
                  '{"nl": "go to ( prop_1 ) then ( prop_2 )", "aps": "prop_1, prop_2", '
                  '"stl": "F(prop_1 & F prop_2)", "id": 7}')
    assert read_requests(path, TranslatorConfig()) == [
        FileRequest(1, "never enter the lab", ("enter_lab",)),
        FileRequest(3, "go to ( prop_1 ) then ( prop_2 )", ("prop_1", "prop_2"),
                    "F(prop_1 & F(prop_2))", "7")]


def test_the_example_file_in_the_docs_reads():
    """Tests docs/examples/requests.jsonl, the file the README points users to."""
    path = Path(__file__).parents[2] / "docs" / "examples" / "requests.jsonl"
    requests = read_requests(path, TranslatorConfig())
    assert len(requests) == 8 and sum(r.reference is not None for r in requests) == 7


def test_every_bad_line_is_named_before_anything_is_translated(tmp_path):
    """Tests that one error lists each bad line with its number and what is wrong."""
    path = _write(tmp_path / "in.jsonl",
                  '{"nl": "never enter the lab", "aps": ["enter_lab"]}',
                  '{"nl": "never enter the lab", "aps": ["enter_lab"]',
                  '{"nl": "never enter the lab"}',
                  '{"nl": "never enter the lab", "aps": ["open_door"]}',
                  '{"nl": "never enter the lab", "aps": ["enter_lab"], "stl": "G(!enter_lab"}',
                  '{"nl": "never enter the lab", "aps": ["enter_lab"], "ref": "G(!enter_lab)"}',
                  '{"nl": "reach the dock within 5000 steps", "aps": ["dock"]}')
    with pytest.raises(ConfigError) as caught:
        read_requests(path, TranslatorConfig())
    message = str(caught.value)
    assert "has 6 bad line(s), nothing was translated" in message
    assert "line 2: not JSON" in message
    assert 'line 3: "aps" must be a non-empty list of proposition names' in message
    assert "line 4: the instruction 'never enter the lab' never mentions open_door" in message
    assert "line 5: " in message and "line 1:" not in message
    assert "line 6: unknown key(s) ref" in message
    assert "line 7: the instruction mentions 5000, above the grammar's largest" in message
    with pytest.raises(ConfigError, match="holds no request"):
        read_requests(_write(tmp_path / "empty.jsonl", ""), TranslatorConfig())


def test_a_run_cut_off_mid_line_resumes_after_its_last_whole_answer(tmp_path):
    """Tests what --resume keeps: whole lines of this input by this model; a line cut
    off by an interruption is dropped; another run's file or model is refused."""
    requests = [FileRequest(1, "never enter the lab", ("enter_lab",)),
                FileRequest(2, "always avoid the door", ("door",))]
    out = tmp_path / "out.jsonl"
    assert done_lines(out, requests, "m") == 0  # nothing yet
    whole = json.dumps({"line": 1, "nl": "never enter the lab", "model": "m"}) + "\n"
    out.write_text(whole + '{"line": 2, "nl": "alw', encoding="utf-8")
    assert done_lines(out, requests, "m") == 1
    assert out.read_text(encoding="utf-8") == whole
    with pytest.raises(ConfigError, match="was made by m, not other: pass that --model"):
        done_lines(out, requests, "other")
    with pytest.raises(ConfigError, match="answers line 1 'never enter the lab' where the "
                                          "input has line 1 'go'"):
        done_lines(out, [FileRequest(1, "go", ("go",))], "m")


def test_resume_refuses_an_output_made_with_other_settings(tmp_path):
    """Tests that the settings are kept beside a new output, that the same settings
    resume it, and that other ones are refused naming the setting that differs; an
    output from before settings were kept resumes as it did."""
    out = tmp_path / "answers.jsonl"
    settings = {"model": "m", "answer": {"repair": {"samples": None, "by": "edits"}},
                "shots": (1, 2)}
    same_settings(out, settings)  # a new run keeps its settings
    assert settings_path(out) == tmp_path / "answers.settings.json"
    assert json.loads(settings_path(out).read_text())["answer"]["repair"]["by"] == "edits"
    out.write_text('{"line": 1}\n', encoding="utf-8")
    same_settings(out, settings)  # the same settings resume
    other = {**settings, "answer": {"repair": {"samples": 0, "by": "edits"}}}
    with pytest.raises(ConfigError, match=r"answers.jsonl was made with answer.repair.samples "
                                          r"= null, this run has 0 .*pass the options it "
                                          "was made with"):
        same_settings(out, other)
    doubted = {**settings, "answer": {"repair": {"samples": None, "by": "samples"}}}
    with pytest.raises(ConfigError, match="answer.repair.by .*no longer takes an option"):
        same_settings(out, doubted)  # made by a release whose translate-file had --repair-by
    settings_path(out).unlink()
    same_settings(out, other)  # an output from before settings were kept
    assert not settings_path(out).exists()


def test_the_summary_counts_doubted_answers_and_matches_apart():
    """Tests the summary of three answers, two with references: one right and sure,
    one wrong and doubted that nests operators unasked and leaves out an order, and one
    without a reference that leaves a bound out."""
    rows = [{"valid": True, "confidence": 0.97, "left_out": {"aps": [], "numbers": []},
             "reference": "G(!a)", "equivalent": True},
            {"valid": True, "confidence": 0.2,
             "left_out": {"aps": [], "numbers": [], "order": True},
             "unasked": ["F(G(b))"], "reference": "F(a & F(b))", "equivalent": False},
            {"valid": True, "confidence": None, "left_out": {"aps": [], "numbers": [5]}}]
    summary = summarize(rows)
    assert summary == {"answers": 3, "valid": 3, "doubted": 1, "left_out": 2, "unasked": 1,
                       "with_reference": 2, "equivalent": 1, "undecided": 0,
                       "undoubted_with_reference": 1, "undoubted_equivalent": 1}
    table = summary_table(summary)
    assert "| equivalent to the reference | 1 of 2 (50.0%) |" in table
    assert "| doubted (confidence below 0.5) | 1 of 3 (33.3%) |" in table


@needs_llama
def test_translate_file_answers_every_line_and_resumes_after_an_interruption(tmp_path):
    """Tests `ara translate-file` with the shipped fine-tune: one line out per request,
    each the `ara translate --json` object with the request; the line with a reference
    judged by Spot; an existing --out refused without --resume; and a run cut off
    after its first answer finishing with the same first answer."""
    requests = _write(tmp_path / "in.jsonl",
                      '{"nl": "at no time ( prop_1 )", "aps": ["prop_1"], "stl": "G(!prop_1)"}',
                      '{"nl": "Never enter the server room.", "aps": ["enter_server_room"], '
                      '"id": "lab-3"}')
    out = tmp_path / "out.jsonl"
    args = ["translate-file", str(requests), "--out", str(out), "--no-progress"]
    run = run_ara(*args, "--json")
    assert run.returncode == 0, run.stderr
    summary = json.loads(run.stdout)
    assert summary["answers"] == 2 and summary["valid"] == 2
    assert summary["with_reference"] == 1 and summary["equivalent"] == 1
    first, second = (json.loads(line) for line in out.read_text().splitlines())
    assert first["line"] == 1 and first["stl"] == "G(!prop_1)" and first["equivalent"] is True
    assert first["confidence"] > 0.9 and first["alternatives"] == []
    assert second["id"] == "lab-3" and second["stl"] == "G(!enter_server_room)"
    assert "reference" not in second

    refused = run_ara(*args)
    assert refused.returncode == 2 and "exists: pass --resume" in refused.stderr
    folder = run_ara(*args[:-3], "--out", str(tmp_path))
    assert folder.returncode == 2 and "is a folder: name the JSON Lines file" in folder.stderr
    out.write_text(out.read_text().splitlines(keepends=True)[0] + '{"line": 2, "n')
    resumed = run_ara(*args, "--resume")
    assert resumed.returncode == 0, resumed.stderr
    assert "resuming" in resumed.stderr
    assert "| equivalent to the reference | 1 of 1" in resumed.stdout
    lines = [json.loads(line) for line in out.read_text().splitlines()]
    assert lines[0] == first and lines[1]["stl"] == second["stl"]
