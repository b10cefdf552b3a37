"""What a user clones: small, with docs that fit a read and links that resolve."""

import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[1]
MB = 1_000_000

def tracked() -> list[Path]:
    try:
        names = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, check=True,
                               capture_output=True).stdout.decode().split("\0")
    except (OSError, subprocess.CalledProcessError):
        pytest.skip("not a git checkout")
    return [ROOT / n for n in names if n and (ROOT / n).is_file()]


def kept(path: Path) -> bool:
    name = path.relative_to(ROOT).as_posix()
    return not name.startswith("eval/models/")


def test_no_tracked_file_outside_the_shipped_models_is_over_1_mb():
    big = [f"{p.relative_to(ROOT)} ({p.stat().st_size / MB:.1f} MB)"
           for p in tracked() if kept(p) and p.stat().st_size > MB]
    assert not big, "keep runs under runs/ (ignored), not in git: " + ", ".join(big)


def test_the_tree_without_the_shipped_models_is_under_15_mb():
    total = sum(p.stat().st_size for p in tracked() if kept(p))
    assert total < 15 * MB, f"{total / MB:.1f} MB tracked outside eval/models/"


def test_readme_and_docs_read_in_minutes():
    """The README and every page a user reads through are short; docs/cli.md, every
    option of every command, is looked up, not read, and is generated."""
    assert len((ROOT / "README.md").read_text().splitlines()) <= 200
    long = {p.name: n for p in (ROOT / "docs").glob("*.md")
            if (n := len(p.read_text().splitlines())) > 350 and p.name != "cli.md"}
    assert not long, f"docs over 350 lines: {long}"


def test_every_relative_link_in_the_docs_resolves():
    pages = [ROOT / "README.md", *(ROOT / "docs").rglob("*.md"),
             *(ROOT / "eval" / "models").glob("*.md")]
    broken = []
    for page in pages:
        # Code is not prose: `F[0,30](a)` in a formula is no link.
        prose = re.sub(r"`[^`\n]*`", "", re.sub(r"```.*?```", "", page.read_text(), flags=re.S))
        for target in re.findall(r"\]\(([^)\s]+)\)", prose):
            path = target.split("#")[0]
            if not path or re.match(r"[a-z]+:", path):
                continue
            if not (page.parent / path).exists():
                broken.append(f"{page.relative_to(ROOT)} -> {target}")
    assert not broken, broken


def test_training_configs_are_few_and_read_nothing_from_docs():
    configs = sorted((ROOT / "training" / "configs").glob("*.yaml"))
    assert 1 <= len(configs) <= 6, [c.name for c in configs]
    assert not [c.name for c in configs if "docs/" in c.read_text()]

