"""What every artifact records about what produced it (file hashes, the git commit), and
how a record is written whole."""

from __future__ import annotations

import hashlib
import os
import subprocess
from functools import lru_cache
from pathlib import Path


def cache_root() -> Path:
    """Where converted models, tools and indexes are kept: ``$ARA_CACHE``, else
    ``~/.cache/ara``."""
    return Path(os.environ.get("ARA_CACHE", Path.home() / ".cache" / "ara"))


def write_atomic(path: str | Path, text: str) -> None:
    """Replace ``path`` whole: a kill, or a reader at that moment, sees the old file or
    the new one, never half of one."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")
    tmp.write_text(text)
    tmp.replace(path)


def sha256_file(path: str | Path) -> str:
    """Hex sha256 of a file's bytes; cached while its size and mtime stay the same."""
    stat = os.stat(path)
    return _sha256(str(path), stat.st_size, stat.st_mtime_ns)


@lru_cache(maxsize=64)
def _sha256(path: str, size: int, mtime_ns: int) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 22), b""):
            digest.update(block)
    return digest.hexdigest()


def differing(saved: dict, now: dict) -> dict[str, tuple]:
    """The settings whose values differ between two nested dicts, by dotted name in
    sorted order (``{"optim": {"lr": 1}}`` holds ``optim.lr``), each with its value in
    ``saved`` and in ``now`` (``None`` where one lacks it): what a resumed run checks
    against the record of the run it goes on with."""
    before, after = _flat(saved), _flat(now)
    return {k: (before.get(k), after.get(k)) for k in sorted(before.keys() | after.keys())
            if before.get(k) != after.get(k)}


def _flat(d: dict, prefix: str = "") -> dict:
    out = {}
    for k, v in d.items():
        out.update(_flat(v, f"{prefix}{k}.") if isinstance(v, dict) else {f"{prefix}{k}": v})
    return out


def git_commit() -> str | None:
    """The commit of the checkout this code runs from, with ``+dirty`` where a tracked
    file differs from it (an untracked new file does not count), or ``None`` outside git."""
    def git(*args: str) -> subprocess.CompletedProcess:
        return subprocess.run(["git", *args], capture_output=True, text=True,
                              cwd=Path(__file__).parent, timeout=10)

    try:
        commit = git("rev-parse", "HEAD").stdout.strip()
        dirty = commit and git("diff", "--quiet", "HEAD").returncode == 1
    except (OSError, subprocess.TimeoutExpired):
        return None
    return (commit + "+dirty" if dirty else commit) or None
