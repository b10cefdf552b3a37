"""What a run records of the code it ran."""

import shutil
import subprocess

import pytest

from ara import provenance


@pytest.mark.skipif(shutil.which("git") is None, reason="git is not installed")
def test_a_run_from_uncommitted_code_says_so(tmp_path, monkeypatch):
    """Tests that the commit a run records carries +dirty while a tracked file differs."""
    def git(*args):
        subprocess.run(["git", *args], cwd=tmp_path, check=True, capture_output=True)

    git("init", "-q")
    (tmp_path / "code.py").write_text("x = 1\n")
    git("add", "code.py")
    git("-c", "user.name=t", "-c", "user.email=t@t", "-c", "commit.gpgsign=false",
        "commit", "-q", "-m", "one")
    monkeypatch.setattr(provenance, "__file__", str(tmp_path / "provenance.py"))
    clean = provenance.git_commit()
    assert clean is not None and len(clean) == 40
    (tmp_path / "code.py").write_text("x = 2\n")
    assert provenance.git_commit() == clean + "+dirty"
