"""A user's own pairs as the test side of an ablation (and, optionally, its worked examples).

The files are those ``ara translate-file`` reads (:mod:`ara.eval.translate.request_file`), with the
reference ``stl`` required on every line::

    {"nl": "Never enter the server room.", "aps": ["enter_server_room"],
     "stl": "G(!enter_server_room)"}

A :class:`FileSplit` answers what the ablation asks a prepared split (its records by
part and form, a version, a manifest), so a run on a user's file is planned, logged,
resumed and reported as a run on one of the project's splits. Its version is the hash
of the files' bytes: editing a file and resuming is refused, as for a new data version.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from pathlib import Path

from ara.data import Record
from ara.data.mixture import sentence_key
from ara.errors import ConfigError
from ara.eval.translate.request_file import read_pairs
from ara.eval.translate.translator import TranslatorConfig


@dataclass(frozen=True)
class FileSplit:
    """Pairs read from a user's JSON Lines files, each line a record.

    Attributes:
        test: The pairs to translate, in file order.
        train: Where worked examples come from (empty: the compositional train side).
        files: Each file read (as named), with the sha256 of its bytes.
    """

    test: tuple[Record, ...]
    train: tuple[Record, ...]
    files: dict[str, str]

    @property
    def version(self) -> str:
        """The files' contents, not their names: a run resumed from another folder, or
        with the file moved, is the same run."""
        joined = "\n".join(self.files.values())
        return hashlib.sha256(joined.encode()).hexdigest()[:12]

    @property
    def manifest(self) -> dict:
        return {"version": self.version, "files": dict(self.files)}

    def records(self, part: str, form: str | None = None) -> list[Record]:
        """The records of ``part`` (train or test), optionally of one form only."""
        if part not in ("train", "test"):
            raise ConfigError(f"unknown part {part!r}: train or test")
        records = self.test if part == "test" else self.train
        return [r for r in records if form is None or r.form == form]


def file_split(data: Path, examples: Path | None, config: TranslatorConfig) -> FileSplit:
    """The pairs of ``data`` to test on, and of ``examples`` (if given) to draw worked
    examples from, less any example whose sentence is one of the tests."""
    tests = read_pairs(data, config)
    files = {str(data): _sha256(data)}
    train: list[Record] = []
    if examples is not None:
        sentences = {sentence_key(r.nl) for r in tests}  # "Go." is the test "go"
        train = [r for r in read_pairs(examples, config) if sentence_key(r.nl) not in sentences]
        files[str(examples)] = _sha256(examples)
        if not train:
            raise ConfigError(f"{examples} holds no pair whose sentence is not also in {data}: "
                              "worked examples that are the tests would show the answers")
    return FileSplit(tuple(tests), tuple(train), files)


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()
