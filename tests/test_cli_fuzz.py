"""Fuzzing the command line: random arguments to `translate`, `stl`, `coord plan` and
`data` end in output or in `error: ...` with an exit code, never in a traceback."""

import random

import pytest
from typer.testing import CliRunner

from ara.cli import app

runner = CliRunner()
FORMULAS = ["F(a)", "G(!b) & F(a)", "a U b", "F[0,5](a)", "F(a & )", "((a)", "", "!" * 70 + "a",
            "G[5,2](a)", "F[0,99999](a)", "true", "X(a)", "a <-> b <-> c", "prop_1 -> F",
            "F(go_to_kitchen) & G(!wet)", "é", "a U[1,inf] b"]
WORDS = ["--json", "--aps", "a,b", "a", "", ",,", "1", "-1", "99999", "--shots", "--seed",
         "--max-bound", "0", "--at", "a=0,7", "a=1,1", "b=99,99", "a=x", "=", "--start",
         "0,0", "9,9", "--split", "paper", "nope", "--form", "grounded", "--timeout", "0.5",
         "--no-intervals", "--any-bound", "--samples", "0", "--temperature", "-3", "--repair",
         "--model", "no-such-model", "lora:missing.gguf", "--world", "/nonexistent"]
COMMANDS = [["stl", "parse"], ["stl", "explain"], ["stl", "equiv"], ["stl", "implies"],
            ["coord", "plan"], ["data", "stats"], ["data", "prepare"], ["translate"],
            ["eval", "translate"]]


def invocation(rng: random.Random) -> list[str]:
    command = rng.choice(COMMANDS)
    args = [rng.choice(FORMULAS) for _ in range(rng.randint(0, 2))]
    args += [rng.choice(WORDS) for _ in range(rng.randint(0, 5))]
    if command[-1] == "translate":
        # Never a valid model with valid propositions: that would load a model per case,
        # and the valid path has its own tests.
        args += ["--model", rng.choice(["no-such-model", "lora:missing.gguf"])]
    return command + args


@pytest.fixture(scope="module")
def data_dir(tmp_path_factory):
    """Splits the fuzz prepares (other seeds among them) go here, once for the module."""
    import os

    old = os.environ.get("ARA_DATA_DIR")
    os.environ["ARA_DATA_DIR"] = str(tmp_path_factory.mktemp("data"))
    yield
    if old is None:
        del os.environ["ARA_DATA_DIR"]
    else:
        os.environ["ARA_DATA_DIR"] = old


@pytest.mark.slow  # each command's errors have their own tests in test_cli.py
@pytest.mark.parametrize("seed", [0, 1])
def test_random_arguments_never_end_in_a_traceback(seed, data_dir):
    rng = random.Random(seed)
    for _ in range(60):
        args = invocation(rng)
        result = runner.invoke(app, args)
        assert result.exit_code in (0, 1, 2, 3), (args, result.output)
        if result.exception is not None:
            assert isinstance(result.exception, SystemExit), (args, result.exception)
        assert "Traceback" not in result.output, (args, result.output)
