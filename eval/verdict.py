"""Whether a candidate adapter may replace the shipped one: the shipping rule, in one place.

``scripts/judge_candidate.sh`` answers every held-out set with both models side by side
into one folder; ``ara eval verdict FOLDER --judge SUITE`` reads it and checks, by
:class:`ShippingRule`:

1. the judge (the blind suite written before the change and kept for it): the candidate
   right on at least as many of its answers as the shipped file, greedy and as
   ``ara translate`` answers (repair 8);
2. every other held-out set, greedy: the candidate at most ``max_drop_points`` below the
   shipped file, so a gain on the judge cannot hide a loss elsewhere;
3. the help request (``bench/help_request_wordings.py``), which the coordination half
   depends on: at most ``help_misses`` fewer wordings equivalent to the template's spec;
4. every candidate answer a valid formula.

The folder's layout is the judge's: ``{shipped,candidate}-{greedy,repair8}/<set>-<form>/``
(``samples.jsonl``) and ``help-request-wordings{,-shipped}.json``. Folders named
``<set>-<form>@<version>`` hold runs on an earlier data version and are not read.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from pathlib import Path

from ara.errors import ConfigError
from ara.run_store import read_samples

HELP_FILES = {"candidate": "help-request-wordings.json",
              "shipped": "help-request-wordings-shipped.json"}


@dataclass(frozen=True)
class ShippingRule:
    """How much worse than the shipped file a candidate may be anywhere but the judge."""

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
    """Right answers of one model on one set (both forms together)."""

    right: int
    pairs: int
    valid: int

    @property
    def points(self) -> float:
        return 100 * self.right / self.pairs if self.pairs else 0.0


@dataclass(frozen=True)
class Check:
    """One condition of the rule, with both models' figures."""

    name: str
    shipped: str
    candidate: str
    passed: bool
    why: str = ""


@dataclass(frozen=True)
class Verdict:
    judge: str
    rule: ShippingRule
    checks: tuple[Check, ...]

    @property
    def ships(self) -> bool:
        return all(check.passed for check in self.checks)

    def to_dict(self) -> dict:
        return {"ships": self.ships, "judge": self.judge, "rule": asdict(self.rule),
                "checks": [asdict(check) for check in self.checks]}


def tallies(model_folder: Path) -> dict[str, Tally]:
    """Each set's tally in one model's folder: its forms' runs summed."""
    sums: dict[str, list[int]] = {}
    for run in sorted(model_folder.glob("*/samples.jsonl")):
        name = run.parent.name
        if "@" in name or "-" not in name:
            continue
        counts = sums.setdefault(name.rsplit("-", 1)[0], [0, 0, 0])
        for sample in read_samples(run.parent):
            counts[0] += bool(sample.get("equivalent"))
            counts[1] += 1
            counts[2] += bool(sample.get("valid"))
    return {name: Tally(*counts) for name, counts in sums.items()}


def _figure(tally: Tally | None) -> str:
    return "-" if tally is None else f"{tally.right} of {tally.pairs} ({tally.points:.1f}%)"


def _help(folder: Path, model: str) -> int | None:
    path = folder / HELP_FILES[model]
    return json.loads(path.read_text())["equivalent"] if path.is_file() else None


def verdict(folder: Path, judge: str, rule: ShippingRule = ShippingRule()) -> Verdict:
    """Check ``folder`` (a judge's results) against ``rule``; a set or figure the candidate
    lacks where the shipped file has it fails its check as not measured."""
    if not folder.is_dir():
        raise ConfigError(f"no folder {folder}: run scripts/judge_candidate.sh first")
    runs = {f"{model}-{kind}": tallies(folder / f"{model}-{kind}")
            for model in ("shipped", "candidate") for kind in ("greedy", "repair8")}
    checks = []
    for kind in ("greedy", "repair8"):
        shipped, candidate = (runs[f"{m}-{kind}"].get(judge) for m in ("shipped", "candidate"))
        if shipped is None or candidate is None:
            checks.append(Check(f"{judge} (the judge), {kind}", _figure(shipped),
                                _figure(candidate), False, "not measured"))
            continue
        checks.append(Check(f"{judge} (the judge), {kind}", _figure(shipped),
                            _figure(candidate), candidate.right >= shipped.right,
                            "" if candidate.right >= shipped.right else "fewer right"))
    for name, shipped in sorted(runs["shipped-greedy"].items()):
        if name == judge:
            continue
        candidate = runs["candidate-greedy"].get(name)
        drop = None if candidate is None else shipped.points - candidate.points
        passed = drop is not None and drop <= rule.max_drop_points + 1e-9
        why = ("not measured" if drop is None else "" if passed
               else f"{drop:.1f} points below")
        checks.append(Check(f"{name}, greedy", _figure(shipped), _figure(candidate), passed, why))
    shipped_help, candidate_help = _help(folder, "shipped"), _help(folder, "candidate")
    if shipped_help is None or candidate_help is None:
        checks.append(Check("help request", "-" if shipped_help is None else str(shipped_help),
                            "-" if candidate_help is None else str(candidate_help), False,
                            "not measured"))
    else:
        passed = candidate_help >= shipped_help - rule.help_misses
        checks.append(Check("help request", str(shipped_help), str(candidate_help), passed,
                            "" if passed else f"{shipped_help - candidate_help} fewer"))
    invalid = sum(t.pairs - t.valid for key, sets in runs.items() if key.startswith("candidate")
                  for t in sets.values())
    checks.append(Check("valid answers", "", "all" if not invalid else f"{invalid} invalid",
                        invalid == 0, "" if not invalid else "invalid answers"))
    return Verdict(judge, rule, tuple(checks))


def verdict_markdown(result: dict) -> str:
    lines = ["| check | shipped | candidate | passed |", "|---|---:|---:|---|"]
    lines += [f"| {c['name']} | {c['shipped']} | {c['candidate']} | "
              f"{'yes' if c['passed'] else 'no: ' + c['why']} |" for c in result["checks"]]
    rule = result["rule"]
    lines += ["", f"rule: the judge at least as good; no other set more than "
              f"{rule['max_drop_points']:g} points below; at most {rule['help_misses']} help "
              "requests fewer; every answer valid",
              f"verdict: {'ships' if result['ships'] else 'does not ship'}"]
    return "\n".join(lines)
