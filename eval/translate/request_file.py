"""The files of requests a user gives: ``ara translate-file``'s input, and a pairs file
(each line with its reference) as worked examples or as the test side of an evaluation.

JSON Lines, one request per line::

    {"nl": "Never enter the server room.", "aps": ["enter_server_room"]}
    {"nl": "go to ( prop_1 ) and after that ( prop_2 )", "aps": ["prop_1", "prop_2"],
     "stl": "F(prop_1 & F(prop_2))", "id": "seq-1"}

Every line is checked as ``ara translate`` checks one request, before anything is
translated, so a typo on line 90 costs nothing.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from ara.data import Record
from ara.data.normalize import UidMaker, form_of
from ara.errors import AraError, ConfigError
from ara.eval.translate.translator import TranslatorConfig, check_request
from ara.grammars import atoms, parse, to_text

#: Bad lines named in one error; the rest are counted.
MAX_REPORTED = 10
#: The split name of records read from a user's pairs file.
FILE_SPLIT = "file"


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
    (:func:`~ara.eval.translate.translator.check_request`); blank lines are skipped.

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


def read_pairs(path: Path, config: TranslatorConfig) -> list[Record]:
    """Every line of ``path`` as a record: the request's own propositions (in its order,
    distractors included) and its reference, which every line must give.

    Raises:
        ConfigError: If a line is bad as ``ara translate-file`` sees it, or gives no
            reference; every such line is named.
    """
    requests = read_requests(path, config)
    missing = [r.line for r in requests if r.reference is None]
    if missing:
        lines = ", ".join(map(str, missing[:10])) + (" ..." if len(missing) > 10 else "")
        raise ConfigError(
            f"{path}: an evaluation needs a reference on every line, as \"stl\"; without "
            f"one: line(s) {lines} (`ara translate-file` translates such lines)")
    uid = UidMaker()
    return [_record(uid, request) for request in requests]


def _record(uid: UidMaker, request: FileRequest) -> Record:
    form = form_of(request.aps)
    assert request.reference is not None
    return Record(uid(FILE_SPLIT, form, request.nl, request.reference), request.nl,
                  request.reference, request.aps, FILE_SPLIT, form, request.line - 1)
