"""Translate a file of instructions (:mod:`~ara.eval.translate.request_file` reads it):
one model load, one output line per instruction.

A line's reference (``stl``), if it gives one, judges its answer by Spot. Each answer
is written and flushed as soon as it is made (the line of ``ara translate --json``, with
the request), so an interrupted run keeps what it did and ``resume`` goes on from there;
the settings it answers with are kept beside the answers (:func:`settings_path`), so
that a resumed run answers as the run it goes on with.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path

from ara.errors import ConfigError
from ara.eval.translate.answering import AnswerConfig, answer, doubted
from ara.eval.translate.checks import Gaps
from ara.eval.translate.prompt import Shot
from ara.eval.translate.request_file import FileRequest
from ara.eval.translate.translator import Translator
from ara.grammars.spot_bridge import judge
from ara.provenance import differing
from ara.run_store import cut_partial_line, read_samples


def check_out(out: Path, resume: bool) -> None:
    """Refuse an ``out`` this run cannot write its answers to, before any model loads:
    a folder, a file in no folder, or another run's answers without ``resume``."""
    if out.is_dir():
        raise ConfigError(f"--out {out} is a folder: name the JSON Lines file to write")
    if not out.parent.is_dir():
        raise ConfigError(f"--out {out}: there is no folder {out.parent}")
    if out.exists() and out.stat().st_size and not resume:
        raise ConfigError(f"{out} exists: pass --resume to go on with it, or choose "
                          "another --out")


def done_lines(out: Path, requests: Sequence[FileRequest], model_id: str) -> int:
    """How many of ``requests`` ``out`` already answers, in order, by this model; a
    last line cut off by an interruption is dropped from the file.

    Raises:
        ConfigError: If ``out`` answers other requests or was made by another model.
    """
    if not out.exists():
        return 0
    cut_partial_line(out)  # cut off mid-write: that answer is made again
    rows = read_samples(out.parent, out.name)
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


#: Settings that earlier releases' translate-file took options for and this one fixes
#: (``ara eval ablation --data`` varies them).
NO_OPTION = frozenset({"answer.repair.by", "answer.repair.doubt", "answer.repair.temperature"})


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
            fix = ("translate-file no longer takes an option for it: finish the output with "
                   "the release that made it" if name in NO_OPTION else
                   "pass the options it was made with to resume it")
            raise ConfigError(
                f"{out} was made with {name} = {json.dumps(before)}, this run has "
                f"{json.dumps(after)} ({path}): {fix}, or choose another --out")


def translate_requests(translator: Translator, requests: Iterable[FileRequest], out: Path,
                       shots_for: Callable[[str, Sequence[str]], Sequence[Shot]],
                       config: AnswerConfig | None = None,
                       spot_timeout_s: float = 10.0) -> Iterable[dict]:
    """Answer each request, append its line to ``out`` (flushed at once), and yield it.

    ``shots_for(nl, aps)`` gives the worked examples for a request. A line is
    the request (``line``, ``id`` if any, ``nl``, ``aps``) and its answer's
    :meth:`~ara.eval.translate.answering.Answer.to_json`;
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
