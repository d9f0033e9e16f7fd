"""A manifest that does not match the schema stops the dry run (DAG build), not a job.

The workflow reads the capture plan of every configured dataset when it is parsed, so
``snakemake -n`` fails with the schema message naming the manifest and the key, the
same message every ``shadowcam`` step gives, and without a Python traceback.
"""

import numpy as np
import pytest
import yaml

pytestmark = pytest.mark.slow


@pytest.fixture
def dry_run(snakemake):
    def run(workdir, ds):
        return snakemake(["-n", "--cores", "1", "--config", f"datasets=[{ds}]"], workdir)

    return run


def assert_stops_with(result, *fragments):
    assert result.returncode != 0, result.stdout[-3000:]
    for fragment in fragments:
        assert fragment in result.stdout, result.stdout[-3000:]
    assert "Traceback" not in result.stdout, result.stdout[-3000:]
    assert "Job stats" not in result.stdout  # no job was planned


def test_capture_without_timing_stops_the_dry_run(tmp_path, workflow_copy, write_image, write_manifest, dry_run):
    workdir = workflow_copy(tmp_path / "wf")
    rng = np.random.default_rng(11)
    for sweep in ("u", "v"):
        for index in range(3):
            path = workdir / "data" / sweep / f"f{index}.png"
            path.parent.mkdir(parents=True, exist_ok=True)
            write_image(path, rng.integers(0, 65536, (6, 8, 3)).astype(np.uint16))
    doc = {
        "name": "notiming",
        "kind": "lab",
        "light": "point",
        "root": "../data",
        "sweeps": {"u": {"files": "u/*.png"}, "v": {"files": "v/*.png"}},
        "timing": {"source": "rate", "rate_hz": 1.0},
    }
    path = write_manifest(workdir / "data_manifest" / "notiming.yaml", doc)
    written = yaml.safe_load(path.read_text())
    del written["timing"]
    path.write_text(yaml.safe_dump(written))
    assert_stops_with(
        dry_run(workdir, "notiming"),
        f"error: manifest {path} does not match the schema manifest.schema.yaml",
        "key (top level): 'timing' is a dependency of 'sweeps'",
    )


def test_rendered_capture_missing_a_key_stops_the_dry_run(tmp_path, workflow_copy, dry_run):
    workdir = workflow_copy(tmp_path / "wf")
    path = workdir / "data_manifest" / "synthetic_tiny.yaml"
    doc = yaml.safe_load(path.read_text())
    del doc["synthetic"]["frames"]
    path.write_text(yaml.safe_dump(doc))
    assert_stops_with(
        dry_run(workdir, "synthetic_tiny"),
        f"error: manifest {path} does not match the schema",
        "key synthetic: 'frames' is a required property",
    )


def test_unknown_dataset_names_the_config_key(tmp_path, workflow_copy, dry_run):
    workdir = workflow_copy(tmp_path / "wf")
    assert_stops_with(
        dry_run(workdir, "nosuch"),
        "error: dataset 'nosuch' (config key 'datasets'): data_manifest/nosuch.yaml does not exist",
    )


def _lab_capture(workdir, write_image, write_manifest, *, v_shape=(6, 8)):
    rng = np.random.default_rng(12)
    for sweep, shape in (("u", (6, 8)), ("v", v_shape)):
        for index in range(4):
            path = workdir / "data" / sweep / f"f{index:03d}.png"
            path.parent.mkdir(parents=True, exist_ok=True)
            write_image(path, rng.integers(0, 65536, shape + (3,)).astype(np.uint16))
    doc = {"name": "cap", "kind": "lab", "light": "point", "root": "../data",
           "sweeps": {"u": {"files": "u/*.png"}, "v": {"files": "v/*.png"}},
           "timing": {"source": "rate", "rate_hz": 1.0}}
    return write_manifest(workdir / "data_manifest" / "cap.yaml", doc)


def test_deleted_frame_and_odd_sweep_size_stop_the_dry_run(tmp_path, workflow_copy, write_image, write_manifest,
                                                           dry_run):
    workdir = workflow_copy(tmp_path / "wf")
    _lab_capture(workdir, write_image, write_manifest)
    (workdir / "data" / "u" / "f002.png").unlink()
    assert_stops_with(dry_run(workdir, "cap"), "file(s) listed in checksums are missing: u/f002.png")
    workdir = workflow_copy(tmp_path / "wf2")
    _lab_capture(workdir, write_image, write_manifest, v_shape=(6, 10))
    assert_stops_with(dry_run(workdir, "cap"), "v/f000.png is 6x10", "u/f000.png is 6x8")
