"""Shared test fixtures.

Offers
------
REPO : path of the repository root.
workflow_copy(dest) : copy the workflow (Snakefile, rules, schemas, config, profiles,
    synthetic manifests) into `dest` so that it runs in a scratch working directory.
snakemake(args, cwd) : run the snakemake of this interpreter's environment, with the
    environment's ``bin`` (the ``shadowcam`` command) first on PATH.
write_manifest(path, doc) : write a capture manifest with the checksums of its files.
"""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import yaml

REPO = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
WORKFLOW_FILES = ("Snakefile", "workflow", "config", "profiles")
SYNTHETIC_MANIFESTS = ("synthetic_tiny.yaml", "synthetic_lab.yaml")


def workflow_copy(dest):
    """Copy the workflow and the synthetic manifests into `dest`; return `dest` as a Path."""
    dest = Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    for name in WORKFLOW_FILES:
        source = REPO / name
        if source.is_dir():
            shutil.copytree(source, dest / name, ignore=shutil.ignore_patterns("__pycache__"))
        else:
            shutil.copy2(source, dest / name)
    (dest / "data_manifest").mkdir(exist_ok=True)
    for name in SYNTHETIC_MANIFESTS:
        shutil.copy2(REPO / "data_manifest" / name, dest / "data_manifest" / name)
    return dest


def snakemake(args, cwd, *, timeout=600):
    """Run ``snakemake *args`` in `cwd`; return the CompletedProcess (stdout+stderr in .stdout)."""
    env = dict(os.environ, PATH=f"{BIN}{os.pathsep}{os.environ.get('PATH', '')}")
    return subprocess.run(
        [str(BIN / "snakemake"), *args], cwd=cwd, env=env, timeout=timeout,
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
    )


def write_manifest(path, doc):
    """Write manifest `doc` (a dict) to `path` with a ``checksums`` block of its files; return `path`."""
    from shadowcam.io.manifest import checksums_for

    path = Path(path)
    path.write_text(yaml.safe_dump(doc))
    path.write_text(yaml.safe_dump({**doc, "checksums": checksums_for(path)}))
    return path
