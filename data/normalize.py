"""Raw NL2TL rows -> normalized records with canonical STL.

Every row either becomes records or is reported as a :class:`RejectedRow`; none is
dropped silently. See ``raw/nl2tl/SOURCE.md`` for the raw fields.
"""

from __future__ import annotations

import errno
import gzip
import hashlib
import json
import re
from collections import Counter
from collections.abc import Iterable
from dataclasses import asdict, dataclass
from itertools import groupby
from pathlib import Path

from ara.errors import AraError
from ara.grammars import Formula, atoms, parse, to_text
from ara.grammars.ast import ASTError, rename_atoms

#: Bumped whenever the records produced from the same raw rows change.
NORMALIZER_VERSION = "1.0.0"
#: The timed files' label rule (:func:`lifted_from_grounded`); part of the version of
#: every split made from them, so navi-only splits keep theirs.
TIMED_LABELS_VERSION = "grounded-structure-1"

# NL2TL writes operators as words in the lifted timed data and as "-" for negation in
# navi; mapping tokens keeps one parser for everything.
_OPERATOR_WORDS = {
    "finally": "F", "globally": "G", "until": "U", "negation": "!", "-": "!",
    "and": "&", "or": "|", "imply": "->", "equal": "<->",
}
_POS_TAG = re.compile(r"_(v|n|a|adj|adv)$")
# The operator tokens of navi-style grounded formulas (``G ( - ( go_to_v house_n ) )``);
# a run of other tokens is one predicate name.
_NAVI_OPERATORS = frozenset({"G", "F", "U", "-", "&", "|", "->", "(", ")"})
_LIFTED_NAME = re.compile(r"prop_\d+")
_NUMBER = re.compile(r"-?\d+(\.\d+)?")


@dataclass(frozen=True)
class Record:
    """One NL/STL pair.

    Attributes:
        uid: Content hash (16 hex digits) of source, form, nl and stl; the k-th exact
            repeat of the same content gets ``#k`` hashed in, so uids are unique.
        nl: The sentence.
        stl: The formula in canonical form (:func:`ara.grammars.to_text`).
        aps: The atomic propositions of ``stl``, sorted.
        source: ``navi`` or ``nl2tl_timed``.
        form: ``lifted`` (prop_1, prop_2, ...) or ``grounded`` (named predicates).
        row: 0-based line of the raw file, for provenance.
    """

    uid: str
    nl: str
    stl: str
    aps: tuple[str, ...]
    source: str
    form: str
    row: int

    def to_json(self) -> str:
        data = asdict(self)
        data["aps"] = list(self.aps)
        return json.dumps(data, sort_keys=True)

    @classmethod
    def from_json(cls, line: str) -> Record:
        data = json.loads(line)
        data["aps"] = tuple(data["aps"])
        return cls(**data)

    @property
    def formula(self) -> Formula:
        return parse(self.stl)


@dataclass(frozen=True)
class RejectedRow:
    """A raw row that produced no record, and why."""

    source: str
    row: int
    form: str
    text: str
    error: str


class _RowError(AraError, ValueError):
    pass


def read_raw(raw_dir: Path, name: str) -> tuple[list[dict], str]:
    """The rows of the vendored file ``name`` and the sha256 of its text.

    The files are stored gzipped (``raw_dir/NAME.gz``) to keep the clone small; the hash
    is of the uncompressed bytes, the one ``SOURCE.md`` lists, so a data version does not
    depend on how the file is stored.
    """
    path = raw_dir / f"{name}.gz"
    if not path.is_file():
        raise FileNotFoundError(errno.ENOENT, "no vendored raw file", str(path))
    data = gzip.decompress(path.read_bytes())
    return _rows(data.decode()), hashlib.sha256(data).hexdigest()


def _rows(text: str) -> list[dict]:
    return [json.loads(line) for line in text.splitlines() if line.strip()]


def form_of(aps: Iterable[str]) -> str:
    """``lifted`` when every proposition is named ``prop_N``, else ``grounded``."""
    return "lifted" if all(_LIFTED_NAME.fullmatch(a) for a in aps) else "grounded"


def lifted_tokens_to_text(tokens: Iterable[str]) -> str:
    """NL2TL formula tokens (word or symbol operators) as surface syntax."""
    return " ".join(_OPERATOR_WORDS.get(t, t) for t in tokens)


def detokenize(tokens: Iterable[str]) -> str:
    """Join sentence tokens with the spacing a person would write."""
    text = " ".join(tokens)
    text = re.sub(r"\(\s+", "(", text)
    text = re.sub(r"\s+([),.;:!?])", r"\1", text)
    return text


def grounded_name(predicate_tokens: list[str]) -> str:
    """A proposition name from NL2TL predicate tokens: ``go_to_v house_n`` -> ``go_to_house``."""
    name = "_".join(_POS_TAG.sub("", t) for t in predicate_tokens)
    return re.sub(r"[^A-Za-z0-9_]", "_", name)


class UidMaker:
    """Content-hash uids, disambiguating exact repeats by their order of appearance."""

    def __init__(self) -> None:
        self.seen: Counter[str] = Counter()

    def __call__(self, source: str, form: str, nl: str, stl: str) -> str:
        content = "\x1f".join((source, form, nl, stl))
        k = self.seen[content]
        self.seen[content] += 1
        if k:
            content += f"#{k}"
        return hashlib.sha256(content.encode()).hexdigest()[:16]


def make_record(uid: UidMaker, source: str, form: str, row: int, nl: str,
                f: Formula) -> Record:
    """A record of ``f`` in canonical text, its uid from ``uid``."""
    stl = to_text(f)
    return Record(uid(source, form, nl, stl), nl, stl, tuple(sorted(atoms(f))), source, form, row)


def normalize_navi(rows: list[dict]) -> tuple[list[Record], list[RejectedRow]]:
    """The navigation data: a lifted and a grounded record per row.

    The lifted formula is the label; the grounded one renames each ``prop_i`` to the
    predicate that the row's ``propositions`` gives it.
    """
    uid = UidMaker()
    records: list[Record] = []
    rejected: list[RejectedRow] = []
    for i, row in enumerate(rows):
        text = lifted_tokens_to_text(row["logic_ltl"])
        try:
            lifted = parse(text)
            names = {p: grounded_name(v["prop"][0]) for p, v in row["propositions"].items()}
            missing = atoms(lifted) - names.keys()
            if missing:
                raise _RowError(f"propositions {sorted(missing)} have no grounding")
            grounded = rename_atoms(lifted, names)
        except (ValueError, ASTError, KeyError, IndexError) as err:
            rejected.append(RejectedRow("navi", i, "lifted", text, str(err).splitlines()[0]))
            continue
        records.append(make_record(uid, "navi", "lifted", i, detokenize(row["logic_sentence"]),
                                   lifted))
        records.append(make_record(uid, "navi", "grounded", i, detokenize(row["sentence"]),
                                   grounded))
    return records, rejected


def lifted_from_grounded(row: dict) -> Formula | None:
    """A timed-file row's lifted formula, with the structure of its own grounded ``ltl``.

    Most rows of NL2TL's lifted timed files come from navi's generator, and their lifted
    ``logic_ltl`` drops parentheses that their grounded ``ltl`` keeps: "at some time
    (prop_1) or (prop_2)" has ``finally ( prop_1 or prop_2 )`` beside
    ``F ( scoop_up_v pear_n ) | take_v apple_n``. The grounded formula agrees with
    navi's label for every sentence the two files share, so it is the label; its
    predicates are the lifted ``prop_i`` in the same order of occurrence.

    Returns:
        The formula, or None for a row whose ``ltl`` is not a navi-style formula
        (signal arithmetic, or empty): its ``logic_ltl`` stays the label.
    """
    tokens = row.get("ltl") or []
    if isinstance(tokens, str):
        tokens = tokens.split()
    lifted_atoms = [t for t in row["logic_ltl"] if _LIFTED_NAME.fullmatch(t)]
    if not tokens or any(t in ("<", ">", "<=", ">=", "==", "[", "rise", "fall") or
                         _NUMBER.fullmatch(t) for t in tokens):
        return None
    lifted: list[str] = []
    names = iter(lifted_atoms)
    for is_operator, run in groupby(tokens, key=_NAVI_OPERATORS.__contains__):
        if is_operator:
            lifted += run
            continue
        name = next(names, None)
        if name is None:
            return None  # more predicates than propositions: not the same formula
        lifted.append(name)
    if next(names, None) is not None:
        return None  # fewer predicates than propositions
    try:
        return parse(lifted_tokens_to_text(lifted))
    except ValueError:
        return None


def normalize_timed(rows: list[dict], source: str = "nl2tl_timed",
                    uid: UidMaker | None = None) -> tuple[list[Record], list[RejectedRow]]:
    """NL2TL's timed data: lifted records only (its grounded side is signal arithmetic
    or navi-style; see :func:`lifted_from_grounded` for how the latter is used)."""
    uid = uid or UidMaker()
    records: list[Record] = []
    rejected: list[RejectedRow] = []
    for i, row in enumerate(rows):
        text = lifted_tokens_to_text(row["logic_ltl"])
        try:
            formula = lifted_from_grounded(row) or parse(text)
        except ValueError as err:
            rejected.append(RejectedRow(source, i, "lifted", text, str(err).splitlines()[0]))
            continue
        nl = detokenize(row["logic_sentence"])
        records.append(make_record(uid, source, "lifted", i, nl, formula))
    return records, rejected
