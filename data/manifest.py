"""Manifests: what a prepared split holds, hashed so that any change is a new version.

A split folder holds ``train.jsonl``, ``test.jsonl`` and ``manifest.json``. The
manifest's ``version`` is a hash of everything that determines the contents (schema,
normalizer version, source hashes, seed, file hashes, uid list), so a changed file is
a new version by construction. :func:`verify` recomputes the hashes on load and
refuses a mismatch.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

from ara.errors import DataVersionError
from ara.provenance import sha256_file

#: Bumped when the manifest's own layout changes.
SCHEMA_VERSION = 1
MANIFEST = "manifest.json"
PARTS = ("train", "test")


def uid_list_sha256(uids: list[str]) -> str:
    return hashlib.sha256("\n".join(uids).encode()).hexdigest()


def content_version(manifest: dict) -> str:
    """The version: a short hash of the manifest's content-determining fields."""
    keys = ("schema_version", "normalizer_version", "split", "seed", "sources", "files")
    payload = json.dumps({k: manifest[k] for k in keys}, sort_keys=True)
    return hashlib.sha256(payload.encode()).hexdigest()[:12]


def describe_files(folder: Path) -> dict[str, dict]:
    """Hash, row count and uid-list hash of each part file in ``folder``."""
    files = {}
    for part in PARTS:
        path = folder / f"{part}.jsonl"
        uids = [json.loads(line)["uid"] for line in path.read_text().splitlines()]
        files[f"{part}.jsonl"] = {
            "sha256": sha256_file(path),
            "records": len(uids),
            "uid_list_sha256": uid_list_sha256(uids),
        }
    return files


def write(folder: Path, manifest: dict) -> dict:
    """Complete ``manifest`` with file hashes and version, and write it into ``folder``."""
    manifest = dict(manifest, schema_version=SCHEMA_VERSION, files=describe_files(folder))
    manifest["version"] = content_version(manifest)
    (folder / MANIFEST).write_text(json.dumps(manifest, indent=2, sort_keys=True) + "\n")
    return manifest


def read(folder: Path) -> dict:
    path = folder / MANIFEST
    if not path.is_file():
        raise DataVersionError(
            f"no {MANIFEST} in {folder}: this is not a prepared split; "
            "run `ara data prepare` to create one"
        )
    return json.loads(path.read_text())


def verify(folder: Path) -> dict:
    """Check the files in ``folder`` against its manifest.

    Returns:
        The manifest.

    Raises:
        DataVersionError: Naming the file whose contents changed.
    """
    manifest = read(folder)
    if manifest.get("schema_version") != SCHEMA_VERSION:
        raise DataVersionError(
            f"{folder} has manifest schema {manifest.get('schema_version')}, this toolkit "
            f"reads schema {SCHEMA_VERSION}; prepare the split again with `ara data prepare`"
        )
    for name, expected in manifest["files"].items():
        # The hash alone, before any line is parsed: a torn or edited file is named, not
        # a JSON error; its counts and uids follow from its bytes.
        if sha256_file(folder / name) != expected["sha256"]:
            raise DataVersionError(
                f"{folder / name} does not match its manifest for version "
                f"{manifest['version']}: prepared files are never edited in place. Restore "
                f"the file, or write it anew with `ara data prepare --split "
                f"{manifest['split']}`"
            )
    if content_version(manifest) != manifest["version"]:
        raise DataVersionError(f"{folder / MANIFEST} was edited: its version hash does not match")
    return manifest
