"""Logical checks through Spot: equivalence and implication of formulas, and the verdicts
on a model's answer against a reference (:func:`judge`).

Spot decides LTL over infinite words. Discrete-time STL intervals map onto Spot's
bounded operators (``F[a..b]``, ``G[a..b]``, ``X[n]``); Spot has no bounded until,
so it is expanded first:

.. math::

    p \\mathbin{U_{[a,b]}} q \\;\\equiv\\; G_{[0,a-1]}\\, p \\wedge F_{[a,b]}\\, q
        \\wedge X^{a} (p \\mathbin{U} q)

(the first conjunct is dropped for ``a = 0``; with ``b = inf`` the second is implied by
the third). ``tests/grammars/test_spot_bridge.py`` checks this expansion against a
brute-force evaluator on random lasso words.

Spot unrolls a bound ``n`` into ``n`` nested ``X``, so automata grow with the bounds.
Formulas whose intervals mention a number above :data:`SPOT_MAX_BOUND` are refused
with :class:`~ara.errors.BoundTooLargeError` rather than left to run for minutes.
"""

from __future__ import annotations

import multiprocessing
import os
import sys
from functools import lru_cache

from ara.errors import AraError, BoundTooLargeError
from ara.grammars.ast import (
    Always,
    And,
    Atom,
    Const,
    Eventually,
    Formula,
    Iff,
    Implies,
    Interval,
    Next,
    Not,
    Or,
    Until,
    max_bound,
)
from ara.grammars.parser import parse
from ara.grammars.printer import to_text

#: Largest interval bound the Spot checks accept (see ``bench/spot_bounds.py``).
SPOT_MAX_BOUND = 1000
#: Spot's own limit on ``X[n]``, ``F[a..b]``, ``G[a..b]``; larger bounds are chained.
SPOT_MAX_REPEAT = 254


def to_spot_text(formula: Formula) -> str:
    """The formula in Spot's syntax, every proposition double-quoted.

    Quoting keeps names such as ``Fa`` or ``X1`` from being read as operators.
    """
    if isinstance(formula, Atom):
        return f'"{formula.name}"'
    if isinstance(formula, Const):
        return "1" if formula.value else "0"
    if isinstance(formula, Not):
        return f"!({to_spot_text(formula.arg)})"
    if isinstance(formula, (And, Or)):
        op = " & " if isinstance(formula, And) else " | "
        return "(" + op.join(to_spot_text(a) for a in formula.args) + ")"
    if isinstance(formula, Implies):
        return f"({to_spot_text(formula.lhs)} -> {to_spot_text(formula.rhs)})"
    if isinstance(formula, Iff):
        return f"({to_spot_text(formula.lhs)} <-> {to_spot_text(formula.rhs)})"
    if isinstance(formula, Next):
        return f"X({to_spot_text(formula.arg)})"
    if isinstance(formula, (Eventually, Always)):
        op = "F" if isinstance(formula, Eventually) else "G"
        arg = to_spot_text(formula.arg)
        if formula.interval is None:
            return f"{op}({arg})"
        return _bounded(op, formula.interval.lo, formula.interval.hi, arg)
    if isinstance(formula, Until):
        return _until_text(formula.lhs, formula.rhs, formula.interval)
    raise TypeError(f"not a formula node: {formula!r}")


def _next(n: int, f: str) -> str:
    """``X^n f``, chained in pieces Spot accepts (it refuses repetitions above 254)."""
    while n > SPOT_MAX_REPEAT:
        f, n = f"X[{SPOT_MAX_REPEAT}]({f})", n - SPOT_MAX_REPEAT
    return f"X[{n}]({f})" if n else f


def _bounded(op: str, lo: int, hi: int | None, f: str) -> str:
    """``F[lo,hi] f`` or ``G[lo,hi] f`` with Spot's operators, any bound size.

    Past Spot's repetition limit the window is shifted with ``X`` and split:
    ``F[lo,hi] f = F[lo,254] f | X^255 F[0,hi-255] f`` (``&`` for ``G``).
    """
    if hi is None:
        return _next(lo, f"{op}({f})")
    if lo > SPOT_MAX_REPEAT:
        return _next(lo, _bounded(op, 0, hi - lo, f))
    if hi <= SPOT_MAX_REPEAT:
        return f"{op}[{lo}..{hi}]({f})"
    join = " | " if op == "F" else " & "
    rest = _next(SPOT_MAX_REPEAT + 1, _bounded(op, 0, hi - SPOT_MAX_REPEAT - 1, f))
    return f"({op}[{lo}..{SPOT_MAX_REPEAT}]({f}){join}{rest})"


def _until_text(lhs: Formula, rhs: Formula, interval: Interval | None) -> str:
    p, q = to_spot_text(lhs), to_spot_text(rhs)
    untimed = f"({p} U {q})"
    if interval is None:
        return untimed
    a, b = interval.lo, interval.hi
    parts = []
    if a > 0:
        parts.append(_bounded("G", 0, a - 1, p))
    if b is not None:
        parts.append(_bounded("F", a, b, q))
    parts.append(_next(a, untimed))
    return "(" + " & ".join(parts) + ")"


def _short(text: str, most: int = 60) -> str:
    """Spot's unrolled windows run to pages: enough of one to recognize it."""
    return text if len(text) <= most else text[:most - 3] + "..."


def _check_bounds(*formulas: Formula) -> None:
    for f in formulas:
        bound = max_bound(f)
        if bound > SPOT_MAX_BOUND:
            raise BoundTooLargeError(
                f"time bound {bound} in {to_text(f)!r} exceeds SPOT_MAX_BOUND={SPOT_MAX_BOUND}: "
                "Spot unrolls bounds into nested X and the check would not finish in "
                "reasonable time; rescale the time unit (from Python, "
                "ara.grammars.spot_bridge.SPOT_MAX_BOUND may be raised at your own cost)"
            )


def to_spot(formula: Formula):
    """The formula as a ``spot.formula``.

    Raises:
        BoundTooLargeError: If an interval bound exceeds :data:`SPOT_MAX_BOUND`.
    """
    _check_bounds(formula)
    return _spot_formula(to_spot_text(formula))


@lru_cache(maxsize=4096)
def _spot_formula(text: str):
    import spot  # imported lazily: importing spot costs ~0.3 s

    return spot.formula(text)


class SpotTimeoutError(AraError, TimeoutError):
    """A Spot check that did not finish within its time limit."""


class SpotWorkerError(AraError, RuntimeError):
    """The process that runs time-limited Spot checks ended without an answer."""


def equivalent(a: Formula, b: Formula, timeout_s: float | None = None) -> bool:
    """Whether ``a`` and ``b`` hold on exactly the same (infinite, discrete-time) traces.

    Args:
        a: First formula.
        b: Second formula.
        timeout_s: Time limit in seconds; ``None`` decides in this process, however
            long it takes. Some shapes are exponential in the window width under
            ``G`` (``G(a -> F[8,16] G(c))`` takes seconds), so pass a limit when the
            formulas come from a model.

    Raises:
        BoundTooLargeError: If an interval bound exceeds :data:`SPOT_MAX_BOUND`.
        SpotTimeoutError: If ``timeout_s`` passed first.
    """
    _check_bounds(a, b)
    return _decide("equivalent", to_spot_text(a), to_spot_text(b), timeout_s)


def implies(a: Formula, b: Formula, timeout_s: float | None = None) -> bool:
    """Whether every trace satisfying ``a`` satisfies ``b`` (``a => b``).

    ``spot.contains(x, y)`` asks whether the language of ``y`` is contained in that
    of ``x``, so ``a => b`` is ``spot.contains(b, a)``. Arguments and errors as in
    :func:`equivalent`.
    """
    _check_bounds(a, b)
    return _decide("implies", to_spot_text(a), to_spot_text(b), timeout_s)


def judge(reference: str, output: str | None, timeout_s: float) -> dict:
    """Spot's verdicts on a model's ``output`` (a formula's text, or ``None`` when it gave
    none): equivalent to, and implying, the ``reference``; ``spot`` says how it was
    decided (``same`` text, ``ok``, or why not: ``invalid``, ``timeout``, ``bound``)."""
    if output is None:
        return {"equivalent": None, "implies": None, "spot": "invalid"}
    if output == reference:  # one canonical text is one tree: equal, without Spot
        return {"equivalent": True, "implies": True, "spot": "same"}
    ref, out = parse(reference), parse(output)
    try:
        eq = equivalent(out, ref, timeout_s=timeout_s)
        imp = True if eq else implies(out, ref, timeout_s=timeout_s)
        return {"equivalent": eq, "implies": imp, "spot": "ok"}
    except SpotTimeoutError:
        return {"equivalent": None, "implies": None, "spot": "timeout"}
    except BoundTooLargeError:
        return {"equivalent": None, "implies": None, "spot": "bound"}


def same_meaning(a: str, b: str, timeout_s: float | None) -> bool | None:
    """Whether two formulas' texts mean the same: equal texts without Spot, else Spot's
    verdict; None where Spot cannot tell (``timeout_s`` passed, or a bound is beyond
    :data:`SPOT_MAX_BOUND`), which each caller weighs as its purpose needs."""
    if a == b:  # one canonical text is one tree
        return True
    try:
        return equivalent(parse(a), parse(b), timeout_s=timeout_s)
    except (SpotTimeoutError, BoundTooLargeError):
        return None


def _decide(op: str, a: str, b: str, timeout_s: float | None) -> bool:
    if timeout_s is None:
        return (_equivalent if op == "equivalent" else _implies)(a, b)
    return _Worker.get().ask(op, a, b, timeout_s)


class _Worker:
    """A Spot process that can be killed when a check runs past its limit.

    Spot's C++ cannot be interrupted from Python, so limited checks run here; on a
    timeout the process is killed and replaced (about half a second).
    """

    _instance: _Worker | None = None

    def __init__(self) -> None:
        ctx = multiprocessing.get_context("spawn")  # no fork: the parent may hold threads
        self.conn, child = ctx.Pipe()
        self.proc = ctx.Process(target=_serve, args=(child, os.getpid()), daemon=True)
        self.proc.start()
        self.cache: dict[tuple[str, str, str], bool] = {}

    @classmethod
    def get(cls) -> _Worker:
        if cls._instance is None or not cls._instance.proc.is_alive():
            cls._instance = cls()
        return cls._instance

    def ask(self, op: str, a: str, b: str, timeout_s: float) -> bool:
        key = (op, a, b)
        if key not in self.cache:
            self.conn.send(key)
            if not self.conn.poll(timeout_s):
                self.proc.kill()
                self.proc.join()
                _Worker._instance = None
                raise SpotTimeoutError(
                    f"Spot did not decide {op}({_short(a)}, {_short(b)}) within "
                    f"{timeout_s:g} s; the check is exponential in the width of windows "
                    "nested under G (give it longer: timeout_s, or --timeout, --spot-timeout)"
                )
            try:
                self.cache[key] = self.conn.recv()
            except (EOFError, OSError):  # it died (killed, out of memory): say so, once
                self.proc.join()
                _Worker._instance = None
                raise SpotWorkerError(
                    f"Spot's worker process ended (exit code {self.proc.exitcode}) while "
                    f"deciding {op}({_short(a)}, {_short(b)}); the next check starts another"
                ) from None
        return self.cache[key]


def _serve(conn, parent: int) -> None:
    _die_with(parent)
    while True:
        try:
            op, a, b = conn.recv()
        except EOFError:  # the parent closed its end: nothing more to decide
            return
        conn.send(_equivalent(a, b) if op == "equivalent" else _implies(a, b))


def _die_with(parent: int) -> None:
    """Have Linux kill this worker when the process that started it dies.

    ``daemon=True`` only covers a parent that exits normally; a run killed by a signal
    would leave a check running in Spot's C++, which holds the GIL and can take an hour
    and gigabytes. Linux ties the signal to the thread that started the worker: if
    that thread ends first, a check in flight fails and the next one starts a new
    worker (checks run on the thread that judges, the main one, in this project).
    """
    if sys.platform != "linux":
        return
    import ctypes
    import signal

    pr_set_pdeathsig = 1
    ctypes.CDLL(None, use_errno=True).prctl(pr_set_pdeathsig, signal.SIGKILL)
    if os.getppid() != parent:  # it died before the line above took effect
        os._exit(0)


@lru_cache(maxsize=65536)
def _equivalent(a: str, b: str) -> bool:
    import spot

    return bool(spot.are_equivalent(_spot_formula(a), _spot_formula(b)))


@lru_cache(maxsize=65536)
def _implies(a: str, b: str) -> bool:
    import spot

    return bool(spot.contains(_spot_formula(b), _spot_formula(a)))


def accepts_word(formula: Formula, prefix: list[frozenset[str]], loop: list[frozenset[str]],
                 aps: tuple[str, ...]) -> bool:
    """Whether Spot's automaton for ``formula`` accepts the lasso word ``prefix loop^ω``.

    Args:
        formula: The formula.
        prefix: Letters before the loop; each letter is the set of true propositions.
        loop: The non-empty repeated part.
        aps: Every proposition that letters may mention (absent ones are false).
    """
    import spot

    def letter(true: frozenset[str]) -> str:
        return " & ".join(f'"{p}"' if p in true else f'!"{p}"' for p in aps) or "1"

    head = "; ".join(letter(s) for s in prefix)
    text = (head + "; " if head else "") + "cycle{" + "; ".join(letter(s) for s in loop) + "}"
    automaton = spot.translate(to_spot(formula))
    word = spot.parse_word(text, automaton.get_dict())
    return bool(automaton.intersects(word.as_automaton()))
