"""A configuration error stops the dry run (DAG build) with the key at fault, no traceback.

Nested values given on the command line reach the workflow as strings; where the schema
wants a number they are read as YAML values, like the same text in config/config.yaml.
"""

import pytest

pytestmark = pytest.mark.slow


def _dry_run(snakemake, workdir, *config):
    return snakemake(["-n", "--cores", "1", "--config", "datasets=[synthetic_tiny]", *config], workdir)


def _assert_stops_with(result, *fragments):
    assert result.returncode != 0, result.stdout[-3000:]
    for fragment in fragments:
        assert fragment in result.stdout, result.stdout[-3000:]
    assert "Traceback" not in result.stdout and "Job stats" not in result.stdout, result.stdout[-3000:]


def test_wrong_method_and_type_name_their_keys(tmp_path, workflow_copy, snakemake):
    workdir = workflow_copy(tmp_path / "wf")
    result = _dry_run(snakemake, workdir, "shadow_time={method: bogus, params: {half_window: wide}}")
    _assert_stops_with(
        result,
        "error: the configuration (config/config.yaml and --configfile / --config) does not match",
        "key shadow_time.method: 'bogus' is not one of ['argmin_parabolic'",
        "key shadow_time.params.half_window: 'wide' is not of type 'integer'",
    )


def test_yaml_syntax_error_names_the_line(tmp_path, workflow_copy, snakemake):
    workdir = workflow_copy(tmp_path / "wf")
    path = workdir / "config" / "config.yaml"
    path.write_text("datasets: [synthetic_tiny\ndecode: {}\n")
    result = snakemake(["-n", "--cores", "1"], workdir)
    _assert_stops_with(result, "error: config file config/config.yaml is not valid YAML at line 2, column 7")


def test_nested_command_line_values_are_read_as_yaml(tmp_path, workflow_copy, snakemake):
    workdir = workflow_copy(tmp_path / "wf")
    result = _dry_run(snakemake, workdir, "decode={chunk_frames: 32, chunks_per_job: 2}",
                      "dual_view={width: null, params: {k: 4}, viewpoints: [centre, 0.25]}")
    assert result.returncode == 0, result.stdout[-3000:]
    assert "Job stats" in result.stdout
