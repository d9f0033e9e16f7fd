"""A new user can enter the environment: the README says how, ``make shell`` does it."""

import os
import shutil
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).parents[2]


def test_readme_gives_the_line_that_enters_the_environment():
    readme = (REPO / "README.md").read_text()
    assert "source .venv/bin/activate" in readme
    assert "make shell" in readme


@pytest.mark.skipif(shutil.which("make") is None or not (REPO / ".venv" / "bin" / "shadowcam").exists(),
                    reason="needs make and an installed .venv")
def test_make_shell_puts_shadowcam_and_snakemake_on_the_path():
    env = {k: v for k, v in os.environ.items() if k not in ("VIRTUAL_ENV", "MAKEFLAGS", "MAKELEVEL")}
    env["PATH"] = "/usr/bin:/bin"  # a fresh shell: nothing of the project on PATH
    run = subprocess.run(["make", "-s", "-o", ".venv/.installed", "shell",
                          "CMD=command -v shadowcam && command -v snakemake"],
                         cwd=REPO, env=env, capture_output=True, text=True, check=True)
    found = run.stdout.split()
    assert [Path(p).name for p in found[-2:]] == ["shadowcam", "snakemake"], run.stdout
    assert all(Path(p).parent.parent.resolve() == (REPO / ".venv").resolve() for p in found[-2:]), run.stdout
