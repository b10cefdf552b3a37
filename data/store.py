"""Prepare, version, load and export the data splits.

``prepare("paper", seed=0)`` normalizes the vendored raw files, splits them, and
writes ``<root>/paper-s0-<version>/{train,test}.jsonl`` with a manifest. The version
is a content hash, so preparing changed contents makes a new folder and never
rewrites an old one. ``versions.json`` beside this module registers the versions
this release of the toolkit produces; ``load_split`` loads the registered one.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
import warnings
from dataclasses import dataclass
from pathlib import Path

from ara.data import manifest as mf
from ara.data.handwritten import SUITES, suite_records
from ara.data.mixture import compositional_split
from ara.data.normalize import (
    NORMALIZER_VERSION,
    TIMED_LABELS_VERSION,
    Record,
    RejectedRow,
    normalize_navi,
    normalize_timed,
    read_raw,
)
from ara.data.splits import disjoint_split, given_split, overlap_stats, paper_split
from ara.errors import ConfigError, DataVersionError, did_you_mean
from ara.provenance import sha256_file

RAW_DIR = Path(__file__).parent / "raw" / "nl2tl"
REGISTRY = Path(__file__).parent / "versions.json"
SPLITS = ("paper", "disjoint", "timed", "compositional", *SUITES)
FORMS = ("lifted", "grounded")
#: Splits fixed by their files, whatever the seed.
UNSEEDED = ("timed", *SUITES)


class DataVersionWarning(UserWarning):
    """Prepared contents differ from the version this toolkit release registered."""


def default_root() -> Path:
    """Where prepared splits live: ``$ARA_DATA_DIR``, else ``prepared/`` beside this module."""
    return Path(os.environ.get("ARA_DATA_DIR", Path(__file__).parent / "prepared"))


@dataclass(frozen=True)
class PreparedSplit:
    """A verified split on disk.

    Attributes:
        folder: The split's folder.
        manifest: Its manifest, already checked against the files.
    """

    folder: Path
    manifest: dict

    @property
    def version(self) -> str:
        return self.manifest["version"]

    def records(self, part: str, form: str | None = None) -> list[Record]:
        """The records of ``part`` (train or test), optionally of one form only."""
        if part not in mf.PARTS:
            raise ConfigError(f"unknown part {part!r}. {did_you_mean(part, mf.PARTS)}")
        if form is not None and form not in FORMS:
            raise ConfigError(f"unknown form {form!r}. {did_you_mean(form, FORMS)}")
        lines = (self.folder / f"{part}.jsonl").read_text().splitlines()
        records = [Record.from_json(line) for line in lines]
        return [r for r in records if form is None or r.form == form]


def build_split(split: str, seed: int) -> tuple[dict[str, list[Record]], list[RejectedRow], dict]:
    """Normalize the raw files and split them, without writing anything.

    Returns:
        ``(parts, rejected, sources)``: records by part, the rows that produced no
        record, and the sha256 of each raw file used.
    """
    if split not in SPLITS:
        raise ConfigError(f"unknown split {split!r}. {did_you_mean(split, SPLITS)}")
    if split == "compositional":
        return compositional_split(RAW_DIR, seed)
    if split in SUITES:
        # Test only: few-shot examples for it come from the compositional train side.
        return ({"train": [], "test": suite_records(split)}, [],
                {SUITES[split].name: sha256_file(SUITES[split])})
    if split == "timed":
        (train_rows, train_hash), (dev_rows, dev_hash) = (
            read_raw(RAW_DIR, "lifted_stl_train.jsonl"), read_raw(RAW_DIR, "lifted_stl_dev.jsonl"))
        train, rej_train = normalize_timed(train_rows, "nl2tl_timed_train")
        test, rej_test = normalize_timed(dev_rows, "nl2tl_timed_dev")
        parts, rejected = given_split(train, test), rej_train + rej_test
        sources = {"lifted_stl_train.jsonl": train_hash, "lifted_stl_dev.jsonl": dev_hash}
    else:
        rows, navi_hash = read_raw(RAW_DIR, "navi.jsonl")
        records, rejected = normalize_navi(rows)
        parts = (paper_split(records, len(rows), seed) if split == "paper"
                 else disjoint_split(records, seed))
        sources = {"navi.jsonl": navi_hash}
    if split == "timed":
        sources["timed_labels"] = TIMED_LABELS_VERSION
    return parts, rejected, sources


def prepare(split: str = "paper", seed: int = 0, root: Path | None = None) -> PreparedSplit:
    """Prepare one split and return it, reusing an identical earlier preparation.

    Args:
        split: ``paper`` (random 4,500/3,000 rows of navi), ``disjoint`` (no lifted
            formula on both sides), ``timed`` (NL2TL's own train/dev, seed unused) or
            ``compositional`` (the training mixture; test: held-out synthetic shapes
            and phrasings, see :mod:`ara.data.mixture`) or a hand-written suite of
            :data:`ara.data.handwritten.SUITES` (test only; seed unused).
        seed: Shuffle seed.
        root: Parent folder; :func:`default_root` by default.
    """
    root = root or default_root()
    parts, rejected, sources = build_split(split, seed)
    root.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{split}-", dir=root))
    try:
        for part in mf.PARTS:
            lines = "".join(r.to_json() + "\n" for r in parts[part])
            (staging / f"{part}.jsonl").write_text(lines)
        manifest = mf.write(staging, {
            "split": split,
            "seed": None if split in UNSEEDED else seed,
            "normalizer_version": NORMALIZER_VERSION,
            "sources": sources,
            "counts": {p: {f: sum(r.form == f for r in parts[p]) for f in FORMS}
                       for p in mf.PARTS},
            "overlap": overlap_stats(parts),
            "rejected": {"count": len(rejected),
                         "examples": [vars(r) for r in rejected[:10]]},
        })
        folder = root / f"{_key(split, manifest['seed'])}-{manifest['version']}"
        if folder.exists():
            try:
                mf.verify(folder)
            except DataVersionError as err:  # preparing is deterministic: write it anew
                warnings.warn(f"{err}; writing it anew", stacklevel=2)
                shutil.rmtree(folder)
                staging.rename(folder)
        else:
            staging.rename(folder)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    _warn_if_unregistered(split, manifest)
    return PreparedSplit(folder, mf.verify(folder))


def _key(split: str, seed: int | None) -> str:
    return split if seed is None else f"{split}-s{seed}"


def registered_versions() -> dict[str, str]:
    return json.loads(REGISTRY.read_text()) if REGISTRY.is_file() else {}


def registered_version(split: str, seed: int = 0) -> str | None:
    """The version of ``split`` this release registers (None where it registers none)."""
    return registered_versions().get(_key(split, None if split in UNSEEDED else seed))


def _warn_if_unregistered(split: str, manifest: dict) -> None:
    key = _key(split, manifest["seed"])
    known = registered_versions().get(key)
    if known is not None and known != manifest["version"]:
        warnings.warn(
            f"{key} prepared as version {manifest['version']}, but this release registers "
            f"{known} in {REGISTRY.name}: the normalizer or the raw data changed. If that "
            "is intended, bump NORMALIZER_VERSION and register the new version",
            DataVersionWarning, stacklevel=3,
        )


def load_split(split: str = "paper", seed: int = 0, root: Path | None = None,
               version: str | None = None) -> PreparedSplit:
    """Load a prepared split, verified against its manifest.

    Args:
        split: Split name.
        seed: Seed it was prepared with (ignored for ``timed``).
        root: Parent folder; :func:`default_root` by default.
        version: Version to load; by default the one ``versions.json`` registers.

    Raises:
        DataVersionError: If it was never prepared, or its files changed since.
    """
    if split not in SPLITS:
        raise ConfigError(f"unknown split {split!r}. {did_you_mean(split, SPLITS)}")
    root = root or default_root()
    key = _key(split, None if split in UNSEEDED else seed)
    registered = registered_version(split, seed)
    version = version or registered
    if version is None:
        found = sorted(root.glob(f"{key}-*"))
        if len(found) != 1:
            raise DataVersionError(
                f"no registered version of {key} and {len(found)} prepared in {root}; "
                f"pass version= (found: {[f.name for f in found]})"
            )
        folder = found[0]
    else:
        folder = root / f"{key}-{version}"
    if not folder.is_dir() and registered is not None and version != registered:
        raise DataVersionError(
            f"split {key} version {version} is not prepared in {root}, and this release "
            f"produces {registered}: prepare {version} with the release that registered it "
            f"(`git log -p data/versions.json`), or train on {registered}")
    if not folder.is_dir():
        raise DataVersionError(
            f"split {key} version {version} is not prepared in {root}; run "
            f"`ara data prepare --split {split}" + ("" if split in UNSEEDED else f" --seed {seed}")
            + "`"
        )
    return PreparedSplit(folder, mf.verify(folder))


class SplitPreparedNotice(UserWarning):
    """A split was prepared on first use (deterministic, versioned, seconds)."""


def load_or_prepare(split: str = "paper", seed: int = 0,
                    root: Path | None = None) -> PreparedSplit:
    """The registered version of a split, prepared first if this machine lacks it.

    Preparing is deterministic and takes seconds, so commands that need a split do
    not send the user to ``ara data prepare`` first; they say that they prepared it.
    """
    try:
        return load_split(split, seed, root)
    except DataVersionError:
        warnings.warn(f"preparing the {split} split on first use (`ara data prepare "
                      f"--split {split}`)", SplitPreparedNotice, stacklevel=2)
        return prepare(split, seed, root)


def to_hf(prepared: PreparedSplit, form: str | None = None):
    """The split as a ``datasets.DatasetDict`` with ``train`` and ``test``."""
    import datasets

    def columns(records: list[Record]) -> dict[str, list]:
        return {k: [getattr(r, k) if k != "aps" else list(r.aps) for r in records]
                for k in ("uid", "nl", "stl", "aps", "source", "form", "row")}

    return datasets.DatasetDict({
        part: datasets.Dataset.from_dict(columns(prepared.records(part, form)))
        for part in mf.PARTS
    })
