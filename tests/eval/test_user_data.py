"""The ablation on a user's own pairs: `ara eval ablation --data FILE [--examples FILE]`."""

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from ara.data.normalize import form_of
from ara.errors import ConfigError
from ara.eval.harness import AblationConfig, plan
from ara.eval.translate.request_file import read_pairs
from ara.eval.translate.translator import TranslatorConfig
from ara.eval.user_data import file_split

from conftest import needs_llama, run_ara

ARA = str(Path(sys.executable).with_name("ara"))

PAIRS = [
    {"nl": "Never enter the server room.", "aps": ["enter_server_room"],
     "stl": "G(!enter_server_room)"},
    {"nl": "Charge the robot, then go to the lab.", "aps": ["charge_robot", "go_to_lab"],
     "stl": "F(charge_robot & F go_to_lab)"},
    {"nl": "reach ( prop_1 ) within 12 steps", "aps": ["prop_1"], "stl": "F[0,12](prop_1)"},
]


def write(path: Path, rows) -> Path:
    path.write_text("".join(json.dumps(r) + "\n" for r in rows), encoding="utf-8")
    return path


def test_each_line_is_a_record_with_its_own_propositions_and_form(tmp_path):
    """Tests that a line keeps the propositions it lists (in order, a distractor too),
    its reference in canonical text, and a form read from the names."""
    rows = [*PAIRS, {"nl": "Never enter the lab or the office.", "aps": ["enter_office",
                     "enter_lab"], "stl": "G(!enter_lab)"}]
    records = read_pairs(write(tmp_path / "mine.jsonl", rows), TranslatorConfig())
    assert [r.stl for r in records] == ["G(!enter_server_room)", "F(charge_robot & F(go_to_lab))",
                                        "F[0,12](prop_1)", "G(!enter_lab)"]
    assert records[3].aps == ("enter_office", "enter_lab")
    assert [r.form for r in records] == ["grounded", "grounded", "lifted", "grounded"]
    assert len({r.uid for r in records}) == 4
    assert form_of(["prop_1", "prop_12"]) == "lifted" and form_of(["prop_x"]) == "grounded"


def test_the_example_pairs_in_the_docs_read():
    """Tests docs/examples/pairs.jsonl, the file docs/evaluation.md runs the ablation on."""
    path = Path(__file__).parents[2] / "docs" / "examples" / "pairs.jsonl"
    records = read_pairs(path, TranslatorConfig())
    assert len(records) == 12 and {r.form for r in records} == {"lifted", "grounded"}


def test_a_line_without_a_reference_is_named(tmp_path):
    """Tests that an evaluation refuses lines it could not judge, by number."""
    rows = [PAIRS[0], {"nl": "Patrol the hallway.", "aps": ["patrol_hallway"]}]
    with pytest.raises(ConfigError, match=r'reference on every line.*line\(s\) 2 '):
        read_pairs(write(tmp_path / "mine.jsonl", rows), TranslatorConfig())


def test_a_reference_must_use_only_the_listed_propositions(tmp_path):
    """Tests the check `ara translate-file` shares: the grammar over "aps" could never
    write a reference that names another proposition."""
    rows = [{"nl": "Never enter the lab.", "aps": ["enter_lab"], "stl": "G(!enter_office)"}]
    with pytest.raises(ConfigError, match='line 1: the reference names enter_office'):
        read_pairs(write(tmp_path / "mine.jsonl", rows), TranslatorConfig())


def test_worked_examples_never_show_a_test_sentence(tmp_path):
    """Tests that an examples file sharing lines with the tests loses those lines, and
    that one with nothing else is refused."""
    tests = write(tmp_path / "tests.jsonl", PAIRS[:2])
    examples = write(tmp_path / "examples.jsonl", PAIRS)
    split = file_split(tests, examples, TranslatorConfig())
    assert [r.nl for r in split.records("train")] == [PAIRS[2]["nl"]]
    assert [r.nl for r in split.records("test", "grounded")] == [p["nl"] for p in PAIRS[:2]]
    assert split.records("test", "lifted") == []
    with pytest.raises(ConfigError, match="would show the answers"):
        file_split(tests, tests, TranslatorConfig())
    # Nor the same sentence written another way (case, spacing, a full stop).
    shouted = [{**p, "nl": "  " + p["nl"].upper().rstrip(".")} for p in PAIRS[:2]]
    split = file_split(tests, write(tmp_path / "shouted.jsonl", [*shouted, PAIRS[2]]),
                       TranslatorConfig())
    assert [r.nl for r in split.records("train")] == [PAIRS[2]["nl"]]


def test_the_version_is_the_content_not_the_name(tmp_path):
    """Tests that a moved file is the same data and an edited one is not, so that a
    resumed run refuses an edited file."""
    first = write(tmp_path / "a.jsonl", PAIRS)
    moved = tmp_path / "elsewhere" / "b.jsonl"
    moved.parent.mkdir()
    shutil.copy(first, moved)
    edited = write(tmp_path / "c.jsonl", PAIRS[:2])
    version = file_split(first, None, TranslatorConfig()).version
    assert file_split(moved, None, TranslatorConfig()).version == version
    assert file_split(edited, None, TranslatorConfig()).version != version


def test_the_config_says_which_data_it_reads():
    """Tests that split 'file' needs a file, that a named split takes none, and that
    'every form' is for files only."""
    config = AblationConfig(split="file", data="mine.jsonl", form=None, variants=("C",))
    assert config.to_dict()["data"] == "mine.jsonl"
    assert AblationConfig.from_dict(config.to_dict()) == config
    assert "data" not in AblationConfig(split="paper").to_dict()  # older runs resume
    with pytest.raises(ConfigError, match="name the file"):
        AblationConfig(split="file")
    with pytest.raises(ConfigError, match="has its own"):
        AblationConfig(split="paper", data="mine.jsonl")
    with pytest.raises(ConfigError, match="unknown form None"):
        AblationConfig(split="paper", form=None)


def test_plan_draws_examples_from_the_users_file_or_the_compositional_side(tmp_path):
    """Tests where F's worked examples come from: the examples file when given, else
    the compositional train side in the form most test lines have."""
    from ara.data import load_or_prepare

    tests = write(tmp_path / "tests.jsonl", PAIRS)
    config = AblationConfig(split="file", data=str(tests), form=None, variants=("C", "F+C"),
                            shots=(1,), reruns=1)
    own = file_split(tests, write(tmp_path / "ex.jsonl", [
        {"nl": "Always avoid the stairs.", "aps": ["at_stairs"], "stl": "G(!at_stairs)"}]),
        config.translator)
    jobs = list(plan(config, own))
    assert len(jobs) == 6 and {j.record.nl for j in jobs} == {p["nl"] for p in PAIRS}
    assert {s.nl for j in jobs for s in j.examples} == {"Always avoid the stairs."}

    borrowed = {s.nl for j in plan(config, file_split(tests, None, config.translator))
                for s in j.examples}
    grounded = {r.nl for r in load_or_prepare("compositional").records("train", "grounded")}
    assert len(borrowed) == 1 and borrowed <= grounded


def test_cli_refuses_a_split_and_a_file_together(tmp_path):
    """Tests the messages for --split with --data, and --examples without --data."""
    data = write(tmp_path / "mine.jsonl", PAIRS)
    both = run_ara("eval", "ablation", "--split", "paper", "--data", str(data),
                   "--out", str(tmp_path / "a"))
    assert both.returncode == 2 and "--split or --data" in both.stderr
    alone = run_ara("eval", "ablation", "--examples", str(data), "--out", str(tmp_path / "b"))
    assert alone.returncode == 2 and "--examples goes with --data" in alone.stderr


def test_cli_names_what_cannot_be_planned_before_loading_a_model(tmp_path):
    """Tests the messages for a form none of the lines has, and for more worked
    examples than the examples file holds (each before a model would load)."""
    data = write(tmp_path / "mine.jsonl", PAIRS[:2])
    examples = write(tmp_path / "ex.jsonl", PAIRS[2:])
    base = ["eval", "ablation", "--data", str(data), "--out", str(tmp_path / "run")]
    form = run_ara(*base, "--form", "lifted")
    assert form.returncode == 2 and "mine.jsonl has no lifted lines" in form.stderr
    shots = run_ara(*base, "--examples", str(examples), "--variants", "F+C", "--shots", "5")
    assert shots.returncode == 2 and "5 worked examples asked for" in shots.stderr
    assert "only 1 to draw them from" in shots.stderr
    assert not (tmp_path / "run").exists()


# The default tier's real ablation, end to end in a subprocess (test_resume_after_kill,
# in the slow tier, kills and resumes one); reading and planning your own file are
# tested above without a model.
@needs_llama
def test_an_ablation_on_ones_own_file_is_judged_reported_and_resumed(tmp_path):
    """Tests a real run on a user's file: every line translated under C and zero-shot
    unconstrained, judged by Spot, the report naming the file; an edited file does not
    resume the run."""
    data = write(tmp_path / "mine.jsonl", PAIRS)
    args = [ARA, "eval", "ablation", "--data", str(data), "--variants", "C,none",
            "--reruns", "1", "--model", "finetuned", "--no-progress",
            "--out", str(tmp_path / "run")]
    done = subprocess.run(args, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert "data `mine.jsonl`" in done.stdout and "(every form)" in done.stdout
    samples = [json.loads(line) for line in (tmp_path / "run" / "samples.jsonl").open()]
    assert sorted((s["variant"], s["nl"]) for s in samples) == sorted(
        (v, p["nl"]) for v in ("C", "none") for p in PAIRS)
    assert all(s["spot"] in {"same", "ok"} for s in samples if s["valid"])
    assert all(s["valid"] for s in samples if s["variant"] == "C")

    write(data, PAIRS[:2])
    resumed = run_ara(*args[1:], "--resume")
    assert resumed.returncode == 2 and "different data" in resumed.stderr


def test_the_tables_name_the_test_file_not_the_examples_file():
    """Tests the data a run's tables name: the file under test, even where the worked
    examples' file sorts before it among the files the run read."""
    from ara.eval.report import data_name

    meta = {"config": {"data": "data/examples/lab-test.jsonl",
                       "examples": "data/examples/lab-pairs.jsonl"},
            "data_files": {"data/examples/lab-pairs.jsonl": "bb",
                           "data/examples/lab-test.jsonl": "77"},
            "data": {"split": "file"}}
    assert data_name(meta) == "lab-test.jsonl"
    assert data_name({"config": {}, "data": {"split": "paper"}}) == "paper"
