"""Translate a file of instructions: one model load, one output line per instruction.

The input is JSON Lines, one request per line::

    {"nl": "Never enter the server room.", "aps": ["enter_server_room"]}
    {"nl": "go to ( prop_1 ) and after that ( prop_2 )", "aps": ["prop_1", "prop_2"],
     "stl": "F(prop_1 & F(prop_2))", "id": "seq-1"}

``stl`` (optional) is a reference: the answer is then judged by Spot. Every line is
checked before the first is translated, so a typo on line 90 costs nothing. Each
answer is written and flushed as soon as it is made (the line of ``ara translate
--json``, with the request), so an interrupted run keeps what it did and ``resume``
goes on from there; the settings it answers with are kept beside the answers
(:func:`settings_path`), so that a resumed run answers as the run it goes on with.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

from ara.errors import AraError, ConfigError
from ara.eval.answering import AnswerConfig, answer, doubted
from ara.eval.checks import Gaps
from ara.eval.harness import judge
from ara.eval.prompt import Shot
from ara.eval.translator import Translator, TranslatorConfig, check_request
from ara.grammars import atoms, parse, to_text
from ara.provenance import differing

#: Bad lines named in one error; the rest are counted.
MAX_REPORTED = 10


@dataclass(frozen=True)
class FileRequest:
    """One line of the input file.

    Attributes:
        line: Its 1-based line number.
        nl: The instruction.
        aps: Its atomic propositions.
        reference: A reference formula in canonical text, if the line gives one.
        id: The line's own ``id``, if any.
    """

    line: int
    nl: str
    aps: tuple[str, ...]
    reference: str | None = None
    id: str | None = None


def read_requests(path: Path, config: TranslatorConfig) -> list[FileRequest]:
    """Every request of a JSON Lines file, each checked as ``ara translate`` checks one
    (:func:`~ara.eval.translator.check_request`); blank lines are skipped.

    Raises:
        ConfigError: If the file cannot be read, holds no request, or has bad lines;
            the message names each (up to :data:`MAX_REPORTED`) with its line number.
    """
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as err:
        raise ConfigError(f"cannot read {path}: {err}") from None
    requests, bad = [], []
    for number, text in enumerate(lines, start=1):
        if not text.strip():
            continue
        try:
            requests.append(_request(number, text, config))
        except AraError as err:  # a bad row, a request check, a reference that won't parse
            bad.append(f"line {number}: {err}")
    if bad:
        more = len(bad) - MAX_REPORTED
        raise ConfigError(f"{path} has {len(bad)} bad line(s), nothing was translated:\n  "
                          + "\n  ".join(bad[:MAX_REPORTED])
                          + (f"\n  ... and {more} more" if more > 0 else ""))
    if not requests:
        raise ConfigError(f"{path} holds no request: write one JSON object per line, e.g. "
                          '{"nl": "never enter the lab", "aps": ["enter_lab"]}')
    return requests


def _request(number: int, text: str, config: TranslatorConfig) -> FileRequest:
    try:
        row = json.loads(text)
    except json.JSONDecodeError as err:
        raise ConfigError(f"not JSON ({err.msg} at column {err.colno})") from None
    if not isinstance(row, dict):
        raise ConfigError('expected an object like {"nl": "...", "aps": ["..."]}')
    unknown = sorted(set(row) - {"nl", "aps", "stl", "id"})
    if unknown:
        raise ConfigError(f"unknown key(s) {', '.join(unknown)}: a line has nl, aps and "
                          "optionally stl (a reference) and id")
    nl, aps = row.get("nl"), row.get("aps")
    if not isinstance(nl, str):
        raise ConfigError('"nl" must be the instruction, a string')
    if isinstance(aps, str):  # "a, b" as on the command line
        aps = [a.strip() for a in aps.split(",") if a.strip()]
    if not isinstance(aps, list) or not aps or not all(isinstance(a, str) for a in aps):
        raise ConfigError('"aps" must be a non-empty list of proposition names')
    check_request(nl, aps, config)
    reference = row.get("stl")
    if reference is not None:
        if not isinstance(reference, str):
            raise ConfigError('"stl" must be a formula, a string')
        formula = parse(reference)
        foreign = sorted(atoms(formula) - set(aps))
        if foreign:  # the grammar over aps could never write it
            raise ConfigError(f'the reference names {", ".join(foreign)}, which "aps" does '
                              "not list")
        reference = to_text(formula)
    ident = row.get("id")
    return FileRequest(number, nl, tuple(aps), reference,
                       None if ident is None else str(ident))


def done_lines(out: Path, requests: Sequence[FileRequest], model_id: str) -> int:
    """How many of ``requests`` ``out`` already answers, in order, by this model; a
    last line cut off by an interruption is dropped from the file.

    Raises:
        ConfigError: If ``out`` answers other requests or was made by another model.
    """
    if not out.exists():
        return 0
    text = out.read_text(encoding="utf-8")
    rows, kept = [], 0
    for line in text.splitlines(keepends=True):
        try:
            rows.append(json.loads(line))
        except json.JSONDecodeError:
            break  # cut off mid-write: the rest is redone
        kept += len(line)
    if kept < len(text):
        out.write_text(text[:kept], encoding="utf-8")
    if len(rows) > len(requests):
        raise ConfigError(f"{out} has {len(rows)} answers for {len(requests)} requests: "
                          "it is another run's; choose another --out")
    for row, request in zip(rows, requests, strict=False):
        if (row.get("line"), row.get("nl")) != (request.line, request.nl):
            raise ConfigError(f"{out} answers line {row.get('line')} {row.get('nl')!r} where "
                              f"the input has line {request.line} {request.nl!r}: it is "
                              "another run's; choose another --out")
        if row.get("model") != model_id:
            raise ConfigError(f"{out} was made by {row.get('model')}, not {model_id}: pass "
                              "that --model to resume it, or choose another --out")
    return len(rows)


def settings_path(out: Path) -> Path:
    """Where the settings of the run that writes ``out`` are kept: ``answers.jsonl`` ->
    ``answers.settings.json``, so that ``out`` stays one answer per line."""
    return out.with_suffix(".settings.json")


def same_settings(out: Path, settings: dict) -> None:
    """Keep ``settings`` (names to JSON values, nested) beside a new ``out``; for one a run
    already wrote to, check they are those it was made with.

    Raises:
        ConfigError: If ``out`` was made with other settings, naming the first that differs.
    """
    path = settings_path(out)
    if not out.exists() or not out.stat().st_size:
        path.write_text(json.dumps(settings, indent=1, sort_keys=True) + "\n", encoding="utf-8")
    elif path.exists():  # outputs from before settings were kept resume as they did
        changed = differing(json.loads(path.read_text(encoding="utf-8")),
                            json.loads(json.dumps(settings)))  # tuples as the lists saved
        if changed:
            name, (before, after) = next(iter(changed.items()))
            raise ConfigError(
                f"{out} was made with {name} = {json.dumps(before)}, this run has "
                f"{json.dumps(after)} ({path}): pass the options it was made with "
                "to resume it, or choose another --out")


def translate_requests(translator: Translator, requests: Iterable[FileRequest], out: Path,
                       shots_for: Callable[[str, Sequence[str]], Sequence[Shot]],
                       config: AnswerConfig | None = None,
                       spot_timeout_s: float = 10.0) -> Iterable[dict]:
    """Answer each request, append its line to ``out`` (flushed at once), and yield it.

    ``shots_for(nl, aps)`` gives the worked examples for a request. A line is
    the request (``line``, ``id`` if any, ``nl``, ``aps``) and its answer's
    :meth:`~ara.eval.answering.Answer.to_json`;
    with a reference, also ``reference`` and Spot's ``equivalent`` (``None``:
    undecided in ``spot_timeout_s``).
    """
    out.parent.mkdir(parents=True, exist_ok=True)
    with out.open("a", encoding="utf-8") as sink:
        for request in requests:
            row: dict = {"line": request.line}
            if request.id is not None:
                row["id"] = request.id
            row |= {"nl": request.nl, "aps": list(request.aps)}
            shown = shots_for(request.nl, request.aps)
            answered = answer(translator, request.nl, request.aps, shown, config)
            row |= answered.to_json()
            if request.reference is not None:
                row["reference"] = request.reference
                row["equivalent"] = judge(request.reference, answered.stl,
                                          spot_timeout_s)["equivalent"]
            sink.write(json.dumps(row) + "\n")
            sink.flush()
            yield row


def summarize(rows: Sequence[dict]) -> dict:
    """Counts over a run's lines: answers, valid, doubted, leaving something out, nesting
    operators unasked; and where lines
    have references, how many the answers match (also among the undoubted)."""
    summary = {"answers": len(rows), "valid": sum(r["valid"] for r in rows),
               "doubted": sum(doubted(r["confidence"]) for r in rows),
               "left_out": sum(any(k != "unasked" for k in Gaps.from_json(r).kinds())
                               for r in rows),
               "unasked": sum(bool(Gaps.from_json(r).unasked) for r in rows)}
    judged = [r for r in rows if "reference" in r]
    if judged:
        sure = [r for r in judged if not doubted(r["confidence"])]
        summary |= {"with_reference": len(judged),
                    "equivalent": sum(r["equivalent"] is True for r in judged),
                    "undecided": sum(r["equivalent"] is None for r in judged),
                    "undoubted_with_reference": len(sure),
                    "undoubted_equivalent": sum(r["equivalent"] is True for r in sure)}
    return summary


def summary_table(summary: dict) -> str:
    """The summary as a small Markdown table."""
    n = summary["answers"]

    def share(k: int, of: int) -> str:
        return f"{k} of {of} ({100 * k / of:.1f}%)" if of else "-"

    rows = [("valid", share(summary["valid"], n)),
            ("doubted (confidence below 0.5)", share(summary["doubted"], n)),
            ("leave out a listed proposition, a bound, an order or an operator",
             share(summary["left_out"], n)),
            ("nest operators the sentence never asks for", share(summary["unasked"], n))]
    if "with_reference" in summary:
        rows += [("equivalent to the reference", share(summary["equivalent"],
                                                       summary["with_reference"])),
                 ("equivalent, undoubted answers", share(summary["undoubted_equivalent"],
                                                         summary["undoubted_with_reference"]))]
        if summary["undecided"]:
            rows.append(("undecided by Spot (counted wrong)", str(summary["undecided"])))
    return "\n".join([f"| {n} answers | |", "|---|---:|", *(f"| {a} | {b} |" for a, b in rows)])
