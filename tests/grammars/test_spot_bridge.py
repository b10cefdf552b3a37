"""Spot checks: hand-checked verdicts, the direction of implication, bounded until."""

import random
import subprocess
import sys
import time

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ara.errors import BoundTooLargeError
from ara.grammars import Interval, Until, parse
from ara.grammars.semantics import Lasso, holds
from ara.grammars.spot_bridge import (
    SPOT_MAX_BOUND,
    accepts_word,
    equivalent,
    implies,
    same_meaning,
    to_spot_text,
)


@pytest.mark.parametrize(
    ("a", "b", "expected"),
    [
        ("F(a | F(b))", "F(a) | F(b)", True),  # F distributes over |, FF = F
        ("G(a & b)", "G(a) & G(b)", True),  # G distributes over &
        ("!F(a)", "G(!a)", True),  # duality
        ("a -> b", "!a | b", True),
        ("G(!a | b)", "G(!a) | b", False),  # NL2TL's noisy pair: not the same
        ("F(a)", "G(a)", False),
        ("F[0,3](a)", "a | X(a) | X(X(a)) | X(X(X(a)))", True),  # bounded F unrolls
        ("G[1,2](a)", "X(a) & X(X(a))", True),
        ("F[2,5](a)", "F[2,6](a)", False),
        ("a U[0,inf] b", "a U b", True),  # [0,inf] is the untimed operator
    ],
)
def test_equivalent_on_hand_checked_pairs(a, b, expected):
    """Tests equivalence verdicts worked out by hand."""
    assert equivalent(parse(a), parse(b)) is expected


@pytest.mark.parametrize(
    ("a", "b", "a_implies_b", "b_implies_a"),
    [
        ("G(a)", "F(a)", True, False),  # always implies eventually, not back
        ("a & b", "a", True, False),
        ("F(a)", "F(a) | F(b)", True, False),
        ("F[2,3](a)", "F[1,5](a)", True, False),  # a tighter window implies a wider one
        ("G[1,5](a)", "G[2,3](a)", True, False),
        ("F(a)", "G(b)", False, False),  # unrelated
        ("a U b", "F(b)", True, False),  # strong until promises b
    ],
)
def test_implies_follows_the_direction_of_the_arrow(a, b, a_implies_b, b_implies_a):
    """Tests implies(A, B) means A => B (spot.contains takes its arguments the other way)."""
    fa, fb = parse(a), parse(b)
    assert implies(fa, fb) is a_implies_b
    assert implies(fb, fa) is b_implies_a


def test_propositions_that_look_like_operators_are_quoted():
    """Tests that 'Fa' and 'X1' stay propositions in Spot instead of F(a) or X(1)."""
    assert to_spot_text(parse("Fa & X1")) == '("Fa" & "X1")'
    assert not equivalent(parse("Fa"), parse("F(a)"))


def test_bounds_past_the_limit_raise_a_clear_error():
    """Tests that a huge bound fails fast with BoundTooLargeError naming the limit."""
    big = parse(f"F[0,{SPOT_MAX_BOUND + 1}](a)")
    with pytest.raises(BoundTooLargeError, match="SPOT_MAX_BOUND"):
        equivalent(big, parse("F(a)"))
    with pytest.raises(BoundTooLargeError):
        implies(parse("a"), big)


def test_same_meaning_says_none_where_spot_cannot_tell():
    """Tests the one comparison repair, the ceiling and the help protocol share: a
    bound past Spot's limit is undecided, not an error after the model has answered."""
    assert same_meaning("F(a)", "F(a)", timeout_s=10) is True
    assert same_meaning("G(F(a))", "F(G(a))", timeout_s=10) is False
    assert same_meaning("a & b", "b & a", timeout_s=10) is True
    assert same_meaning(f"F[0,{SPOT_MAX_BOUND + 500}](a)", "F(a)", timeout_s=10) is None


letters = st.frozensets(st.sampled_from(["a", "b"]))
lassos = st.builds(Lasso, st.lists(letters, max_size=5).map(tuple),
                   st.lists(letters, min_size=1, max_size=3).map(tuple))
operands = st.sampled_from(["a", "!a", "a | b", "true", "F(b)"]).map(parse)


@settings(max_examples=150, deadline=None)
@given(lhs=operands, rhs=st.sampled_from(["b", "a & b", "!b", "false"]).map(parse),
       lo=st.integers(0, 4), width=st.integers(0, 4), unbounded=st.booleans(), word=lassos)
def test_bounded_until_expansion_matches_brute_force(lhs, rhs, lo, width, unbounded, word):
    """Tests Spot's expansion of p U[a,b] q against the definition on random lasso words."""
    f = Until(lhs, rhs, Interval(lo, None if unbounded else lo + width))
    assert accepts_word(f, list(word.prefix), list(word.loop), ("a", "b")) == holds(f, word)


def test_brute_force_and_spot_agree_on_random_timed_formulas():
    """Tests the whole translation (every operator) against the brute-force evaluator."""
    from ara.grammars import Syntax, build_grammar

    grammar = build_grammar(Syntax(aps=("a", "b"), intervals=True, max_bound=4,
                                   allow_next=True, allow_inf=True, relaxed=True)).grammar
    rng = random.Random(7)
    for _ in range(60):
        f = parse(grammar.sample(rng, budget=12))
        for _ in range(3):
            word = Lasso(tuple(frozenset(x for x in "ab" if rng.random() < 0.5)
                               for _ in range(rng.randint(0, 4))),
                         tuple(frozenset(x for x in "ab" if rng.random() < 0.5)
                               for _ in range(rng.randint(1, 3))))
            assert accepts_word(f, list(word.prefix), list(word.loop), ("a", "b")) == holds(f, word)


@pytest.mark.parametrize("text", [  # the two slowest checks are in the slow tier
    pytest.param("F[250,520](a)", marks=pytest.mark.slow), "G[200,300](!a)",
    pytest.param("b U[240,260] a", marks=pytest.mark.slow), "F[600,inf](a)", "G[0,254](!a)"])
def test_bounds_past_spots_repetition_limit_stay_exact(text):
    """Tests the chained encoding of bounds above 254 against brute force, at the seams."""
    f = parse(text)
    for k in (0, 199, 200, 239, 240, 249, 250, 254, 255, 256, 260, 261, 300, 301, 520, 521, 600):
        # 'a' holds only at step k, 'b' before it
        word = Lasso(tuple(frozenset("b") for _ in range(k)) + (frozenset("a"),),
                     (frozenset(),))
        assert accepts_word(f, list(word.prefix), list(word.loop), ("a", "b")) == holds(f, word), k


def test_a_time_limit_turns_a_runaway_check_into_an_error():
    """Tests SpotTimeoutError on a shape exponential in its window, then recovery."""
    from ara.grammars.spot_bridge import SpotTimeoutError

    slow_a = parse("G(a -> F[20,40](G(c)))")
    slow_b = parse("G(a -> F[20,40](G(c))) & F[0,40](b)")
    with pytest.raises(SpotTimeoutError, match="within 1 s"):
        equivalent(slow_a, slow_b, timeout_s=1)
    # the worker is replaced and answers the next check
    assert implies(parse("G(a)"), parse("F(a)"), timeout_s=30) is True
    assert equivalent(parse("F(a | F(b))"), parse("F(a) | F(b)"), timeout_s=30) is True


def test_a_worker_that_dies_mid_check_is_a_clear_error_then_replaced():
    """Tests a worker killed from outside (the OOM killer, a user's kill) in the middle
    of a check: the check says so by name, and the next one gets a new worker."""
    import threading

    from ara.grammars.spot_bridge import SpotWorkerError, _Worker

    worker = _Worker.get()
    threading.Timer(1.0, worker.proc.kill).start()
    with pytest.raises(SpotWorkerError, match="worker process ended"):
        equivalent(parse("G(a -> F[20,40](G(c)))"),
                   parse("G(a -> F[20,40](G(c))) & F[0,40](b)"), timeout_s=60)
    assert equivalent(parse("F(a | F(b))"), parse("F(a) | F(b)"), timeout_s=30) is True


@pytest.mark.skipif(sys.platform != "linux", reason="the worker's tie to its parent is Linux's")
def test_a_check_does_not_outlive_a_killed_run(tmp_path):
    """Tests that killing a run in the middle of a long Spot check (as a user's Ctrl-\\ or
    a scheduler's SIGKILL would) also ends the worker doing the check, which would
    otherwise run on, for up to an hour and gigabytes."""
    script = tmp_path / "run.py"
    script.write_text(
        "from ara.grammars import parse\n"
        "from ara.grammars.spot_bridge import _Worker, equivalent\n"
        "if __name__ == '__main__':\n"
        "    print(_Worker.get().proc.pid, flush=True)\n"
        "    equivalent(parse('G(a -> F[20,40](G(c)))'),\n"
        "               parse('G(a -> F[20,40](G(c))) & F[0,40](b)'), timeout_s=600)\n")
    run = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True)
    worker = int(run.stdout.readline())
    time.sleep(1)  # the check is under way
    assert _alive(worker)
    run.kill()
    run.wait()
    deadline = time.monotonic() + 30
    while _alive(worker) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not _alive(worker)


def _alive(pid: int) -> bool:
    """Whether ``pid`` runs (a zombie, dead but not yet reaped, does not)."""
    try:
        with open(f"/proc/{pid}/stat") as stat:
            return stat.read().split(")")[-1].split()[0] != "Z"
    except FileNotFoundError:
        return False
