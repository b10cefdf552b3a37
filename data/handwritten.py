"""The hand-written suites: instructions written for this project as a user would, each
with its reference and the readings it must not be confused with. Test only: no
training mixture includes them, and mixtures drop any record that says one.

``handwritten/suite.yaml`` is the split ``handwritten``, ``suiteN.yaml`` the split
``handwrittenN``. Which suites are blind, when each was written and what each judged is
in docs/data.md ("The hand-written suites"); a suite waiting for the change it is to
judge is in ``WAITING``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import yaml

from ara.data.normalize import Record, UidMaker, form_of
from ara.errors import ConfigError
from ara.grammars import atoms, parse, to_text

FOLDER = Path(__file__).parent / "handwritten"
#: Each hand-written split and its file (``suite.yaml`` is ``handwritten``, ``suite2.yaml``
#: ``handwritten2``, ...); a split's records carry its name as source. A new suite is a
#: new file here, registered with ``ara data prepare --split NAME``.
_NAMED = sorted(filter(None, (re.fullmatch(r"suite([2-9]|[1-9]\d+)?", p.stem)
                              for p in FOLDER.glob("suite*.yaml"))),
                key=lambda m: int(m[1] or 1))
SUITES = {"handwritten" + (m[1] or ""): FOLDER / f"{m[0]}.yaml" for m in _NAMED}
#: Blind suites no model has answered yet, and the change each waits to judge: scripts
#: that run "every suite" by default leave them out until they are named.
WAITING = {"handwritten12": "the change after the recipe's run on generator 4.0"}


@dataclass(frozen=True)
class SuiteEntry:
    """One instruction of the suite.

    Attributes:
        nl: The instruction.
        stl: Its reference formula, canonical.
        confusions: Readings a translator could plausibly give instead (canonical).
        domain: ``lifted``, or the application the sentence comes from (``warehouse``,
            ``hospital``, ``ski``, ...; each suite's own in its file).
    """

    nl: str
    stl: str
    confusions: tuple[str, ...]
    domain: str

    @property
    def aps(self) -> tuple[str, ...]:
        return tuple(sorted(atoms(parse(self.stl))))

    @property
    def form(self) -> str:
        return form_of(self.aps)


def load_suite(path: Path = SUITES["handwritten"]) -> list[SuiteEntry]:
    """The suite's entries, with every formula parsed and printed canonically.

    Raises:
        ConfigError: If an entry lacks a field or a formula does not parse.
    """
    data = yaml.safe_load(path.read_text())
    entries = []
    for i, item in enumerate(data["entries"]):
        missing = {"nl", "stl", "not", "domain"} - set(item)
        if missing:
            raise ConfigError(f"{path.name} entry {i} lacks {sorted(missing)}: {item}")
        try:
            stl = to_text(parse(item["stl"]))
            confusions = tuple(to_text(parse(c)) for c in item["not"])
        except ValueError as err:
            raise ConfigError(f"{path.name} entry {i} ({item['nl']!r}): {err}") from err
        entries.append(SuiteEntry(item["nl"], stl, confusions, item["domain"]))
    return entries


def suite_records(split: str = "handwritten") -> list[Record]:
    """One suite as test records (row = position in the file)."""
    uid = UidMaker()
    return [Record(uid(split, e.form, e.nl, e.stl), e.nl, e.stl, e.aps, split, e.form, i)
            for i, e in enumerate(load_suite(SUITES[split]))]
