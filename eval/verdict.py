"""Whether a candidate adapter may replace the shipped one: the shipping rule, in one place.

``scripts/judge_candidate.sh`` answers every held-out set with both models side by side
into one folder; ``ara eval verdict FOLDER --judge SUITE`` reads it and checks, by
:class:`ShippingRule`:

1. the judge (the blind suite written before the change and kept for it): the candidate
   right on at least as many of its answers as the shipped file, greedy and as
   ``ara translate`` answers (repair 8);
2. every other held-out set, greedy, its lifted and grounded runs together: the
   candidate at most ``max_drop_points`` below the shipped file, so a gain on the judge
   cannot hide a loss elsewhere;
3. the help request (``bench/help_request_wordings.py``), which the coordination half
   depends on: at most ``help_misses`` fewer wordings equivalent to the template's spec;
4. the help request where it counts, in the paper's Experiment 2 with the candidate
   translating every request (``ara coord exp2 --model ... --wordings all``): no auction
   whose outcome differs from the one the template's spec gives, none left unanswered;
5. no more invalid answers than the shipped file (under the grammar, both give none).

Both models must have answered the same pairs of a set, else its check fails as not
measured: an interrupted run cannot pass. The folder's layout is the judge's:
``{shipped,candidate}-{greedy,repair8}/<set>-<form>/samples.jsonl``,
``help-request-wordings{,-shipped}.json`` and ``exp2-candidate/summary.json``; folders
named ``<set>-<form>@<version>`` hold runs on an earlier data version and are not read.
The paper split, whose test sentences are nearly all in training, is measured by the
judge for the candidate alone and not checked here.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from pathlib import Path

from ara.errors import ConfigError
from ara.run_store import read_samples

#: Test pairs ``scripts/eval_generalization.sh`` samples from each held-out set per form
#: (``$LIMIT`` overrides); a hand-written suite, at most :data:`SUITE_LIMIT`, runs whole.
#: The judge reuses a shipped run only where it was made with these.
HELD_OUT_LIMITS = {"compositional": 50, "timed": 100, "timed-unseen": 100, "paper": 100,
                   "disjoint": 100}
SUITE_LIMIT = 200

HELP_FILES = {"candidate": "help-request-wordings.json",
              "shipped": "help-request-wordings-shipped.json"}
MODELS = ("shipped", "candidate")


@dataclass(frozen=True)
class ShippingRule:
    """How much worse than the shipped file a candidate may be anywhere but the judge.

    Attributes:
        max_drop_points: Percentage points any other held-out set may fall (on a set of
            fewer than 100 pairs, below 1 point means not one answer).
        help_misses: Help requests the candidate may get wrong beyond the shipped file's.
    """

    max_drop_points: float = 1.0
    help_misses: int = 0

    def __post_init__(self) -> None:
        if not 0 <= self.max_drop_points <= 100:
            raise ConfigError(f"max_drop_points {self.max_drop_points}: a share in points, "
                              "0 to 100")
        if self.help_misses < 0:
            raise ConfigError(f"help_misses {self.help_misses}: at least 0")


@dataclass(frozen=True)
class Tally:
    """One model's answers on one set: which pairs, how many right, how many valid."""

    uids: frozenset[str]
    right: int
    valid: int

    @property
    def pairs(self) -> int:
        return len(self.uids)

    @property
    def points(self) -> float:
        return 100 * self.right / self.pairs

    def figure(self) -> str:
        return f"{self.right} of {self.pairs} ({self.points:.1f}%)"


@dataclass(frozen=True)
class Check:
    """One condition of the rule: both models' figures, and why it failed if it did."""

    name: str
    shipped: str
    candidate: str
    passed: bool
    why: str = ""


@dataclass(frozen=True)
class Verdict:
    """Every check of a judge's folder; the candidate ships when all pass."""

    folder: str
    judge: str
    rule: ShippingRule
    checks: tuple[Check, ...]

    @property
    def ships(self) -> bool:
        return all(check.passed for check in self.checks)

    def to_dict(self) -> dict:
        return {"ships": self.ships, "folder": self.folder, "judge": self.judge,
                "rule": asdict(self.rule), "checks": [asdict(check) for check in self.checks]}


def tallies(model_folder: Path) -> dict[str, Tally]:
    """Each set's tally in one model's folder, its forms' runs together."""
    found: dict[str, tuple[set[str], list[int]]] = {}
    for run in sorted(model_folder.glob("*/samples.jsonl")):
        name = run.parent.name
        if "@" in name or "-" not in name:
            continue
        uids, counts = found.setdefault(name.rsplit("-", 1)[0], (set(), [0, 0]))
        for sample in read_samples(run.parent):
            uids.add(f"{name}:{sample['uid']}")
            counts[0] += bool(sample.get("equivalent"))
            counts[1] += bool(sample.get("valid"))
    return {name: Tally(frozenset(uids), *counts) for name, (uids, counts) in found.items()
            if uids}


def _compare(name: str, shipped: Tally | None, candidate: Tally | None,
             allowed_drop: float | None) -> Check:
    """The candidate against the shipped file on one set: no fewer right answers
    (``allowed_drop`` None), or at most that many points below."""
    figures = tuple("-" if t is None else t.figure() for t in (shipped, candidate))
    if shipped is None or candidate is None:
        return Check(name, *figures, False, "not measured")
    if shipped.uids != candidate.uids:
        return Check(name, *figures, False, "not measured: the two runs answered other pairs "
                                            "(one interrupted?)")
    if allowed_drop is None:
        passed = candidate.right >= shipped.right
        return Check(name, *figures, passed, "" if passed else
                     f"{shipped.right - candidate.right} fewer right")
    drop = shipped.points - candidate.points
    passed = drop <= allowed_drop + 1e-9
    return Check(name, *figures, passed, "" if passed else
                 f"{drop:.2f} points below ({shipped.right - candidate.right} fewer right)")


def _help(folder: Path, model: str) -> int | None:
    path = folder / HELP_FILES[model]
    return json.loads(path.read_text())["equivalent"] if path.is_file() else None


def _auctions(summary: Path) -> Check:
    """Experiment 2 with the candidate translating: every auction as the template's."""
    name = "help requests in Experiment 2"
    if not summary.is_file():
        return Check(name, "", "-", False, "not measured")
    translation = json.loads(summary.read_text()).get("translation")
    if translation is None:
        return Check(name, "", "-", False, "not measured: a run without a translator")
    changed, trials = translation["wrong_formula_changed_delta"], translation["trials"]
    figure = (f"{trials - changed} of {trials} auctions as the template's "
              f"({translation['equivalent_to_template']} formulas equivalent)")
    return Check(name, "", figure, changed == 0,
                 "" if not changed else f"{changed} auctions differ or go unanswered")


def verdict(folder: Path, judge: str, rule: ShippingRule = ShippingRule()) -> Verdict:
    """Check a judge's results against ``rule``.

    Args:
        folder: What ``scripts/judge_candidate.sh`` wrote (``runs/generalization/judge-...``).
        judge: The blind suite that judged the change.
        rule: How much worse the candidate may be elsewhere.

    Returns:
        Every check; a set or figure missing for either model fails as not measured.

    Raises:
        ConfigError: ``folder`` holds no runs, or none of ``judge``.
    """
    runs = {f"{model}-{kind}": tallies(folder / f"{model}-{kind}")
            for model in MODELS for kind in ("greedy", "repair8")}
    answered = sorted(set().union(*runs.values()))
    if not answered:
        raise ConfigError(f"no evaluation runs in {folder}: run scripts/judge_candidate.sh "
                          "first")
    if judge not in answered:
        raise ConfigError(f"{folder} has no runs of {judge}; it has {', '.join(answered)}")
    checks = [_compare(f"{judge} (the judge), {kind}", runs[f"shipped-{kind}"].get(judge),
                       runs[f"candidate-{kind}"].get(judge), None)
              for kind in ("greedy", "repair8")]
    greedy = {model: runs[f"{model}-greedy"] for model in MODELS}
    checks += [_compare(f"{name}, greedy", greedy["shipped"].get(name),
                        greedy["candidate"].get(name), rule.max_drop_points)
               for name in sorted(set(greedy["shipped"]) | set(greedy["candidate"]))
               if name != judge]
    shipped_help, candidate_help = (_help(folder, model) for model in MODELS)
    figures = tuple("-" if n is None else str(n) for n in (shipped_help, candidate_help))
    if shipped_help is None or candidate_help is None:
        checks.append(Check("help request", *figures, False, "not measured"))
    else:
        passed = candidate_help >= shipped_help - rule.help_misses
        checks.append(Check("help request", *figures, passed,
                            "" if passed else f"{shipped_help - candidate_help} fewer"))
    checks.append(_auctions(folder / "exp2-candidate" / "summary.json"))
    invalid = {model: sum(t.pairs - t.valid for kind in ("greedy", "repair8")
                          for t in runs[f"{model}-{kind}"].values()) for model in MODELS}
    passed = invalid["candidate"] <= invalid["shipped"]
    checks.append(Check("invalid answers", str(invalid["shipped"]), str(invalid["candidate"]),
                        passed, "" if passed else "more invalid answers"))
    return Verdict(folder.name, judge, rule, tuple(checks))


def verdict_markdown(result: dict) -> str:
    lines = ["| check | shipped | candidate | passed |", "|---|---:|---:|---|"]
    lines += [f"| {c['name']} | {c['shipped']} | {c['candidate']} | "
              f"{'yes' if c['passed'] else 'no: ' + c['why']} |" for c in result["checks"]]
    rule = result["rule"]
    lines += ["", f"rule: the judge at least as good; no other set more than "
              f"{rule['max_drop_points']:g} points below; at most {rule['help_misses']} help "
              "requests fewer; every auction of Experiment 2 as the template's; no more invalid "
              "answers",
              f"verdict: {'ships' if result['ships'] else 'does not ship'}"]
    return "\n".join(lines)
