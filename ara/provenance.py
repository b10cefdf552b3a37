"""What every artifact records about what produced it: file hashes, the git commit."""

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


def git_commit() -> str | None:
    """The commit of the checkout this code runs from, or ``None`` outside git."""
    try:
        out = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True,
                             cwd=Path(__file__).parent, timeout=10)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return out.stdout.strip() or None
