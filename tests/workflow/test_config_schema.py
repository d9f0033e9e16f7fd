"""The config schema gives every ``params`` block the keys and types the library accepts.

A wrong method or option name, or a wrong type, is refused when the workflow is parsed
(``snakemake -n``), not by a job after decode and tracking have run.
"""

import inspect

import jsonschema
import pytest
import yaml

from shadowcam.cameras.dual_coords import CALIBRATION_OPTIONS, DUAL_COORD_MODELS, UNIFORM_OPTIONS
from shadowcam.cameras.dual_view import DUAL_VIEW_METHODS
from shadowcam.cameras.intrinsics import INTRINSICS_OPTIONS, coords_to_intrinsics
from shadowcam.lab.shadow_time import SHADOW_TIME_METHODS, classify_dips


@pytest.fixture(scope="module")
def schema(repo):
    return yaml.safe_load((repo / "workflow" / "schemas" / "config.schema.yaml").read_text())


def _options(function, skip=()):
    parameters = inspect.signature(function).parameters.values()
    return {p.name for p in parameters if p.kind is p.KEYWORD_ONLY and p.name not in skip}


def _block(schema, *path):
    for key in path:
        schema = schema["properties"][key]
    return schema


def test_params_blocks_name_the_library_options(schema):
    assert set(_block(schema, "shadow_time", "method")["enum"]) == set(SHADOW_TIME_METHODS)
    assert set(_block(schema, "evaluate", "method")["enum"]) == set(SHADOW_TIME_METHODS)
    method_params = set().union(*(_options(f) for f in SHADOW_TIME_METHODS.values()))
    assert set(_block(schema, "shadow_time", "params", "method_params")["properties"]) == method_params
    classify = _options(classify_dips, skip=("saturated", "site_level", "site_colour", "interval"))
    assert set(_block(schema, "shadow_time", "params", "classify_params")["properties"]) == classify
    dual_coords = _block(schema, "dual_coords", "params")
    assert set(dual_coords["properties"]) == {"min_confidence", *UNIFORM_OPTIONS, *CALIBRATION_OPTIONS}
    assert set(dual_coords["properties"]["models"]["items"]["enum"]) == set(DUAL_COORD_MODELS)
    assert set(_block(schema, "dual_view", "method")["enum"]) == set(DUAL_VIEW_METHODS)
    resampling = set().union(*(_options(f, skip=("valid", "shape", "eps")) for f in DUAL_VIEW_METHODS.values()))
    assert set(_block(schema, "dual_view", "params")["properties"]) == resampling
    assert set(_block(schema, "dual_view", "intrinsics")["properties"]) == set(INTRINSICS_OPTIONS)
    assert _options(coords_to_intrinsics) == set(INTRINSICS_OPTIONS)


def _errors(schema, doc):
    validator = jsonschema.Draft202012Validator(schema)
    return sorted(f"{'.'.join(map(str, e.absolute_path))}: {e.message}" for e in validator.iter_errors(doc))


@pytest.mark.parametrize("doc, expected", [
    ({"shadow_time": {"method": "bogus"}}, "shadow_time.method: 'bogus' is not one of"),
    ({"shadow_time": {"params": {"half_window": "wide"}}}, "shadow_time.params.half_window: 'wide' is not of type"),
    ({"shadow_time": {"params": {"half_widow": 4}}}, "shadow_time.params: Additional properties are not allowed"),
    ({"dual_coords": {"params": {"min_confidence": 5}}},
     "dual_coords.params.min_confidence: 5 is greater than the maximum of 1"),
    ({"dual_view": {"params": {"max_edge": "long"}}}, "dual_view.params.max_edge: 'long' is not of type"),
    ({"min_coverage": 2}, "min_coverage: 2 is greater than the maximum of 1"),
    ({"dual_view": {"intrinsics": {"skew": 10}}}, "dual_view.intrinsics: Additional properties"),
])
def test_a_wrong_option_names_its_key(schema, doc, expected):
    errors = _errors(schema, {"datasets": ["synthetic_tiny"], **doc})
    assert len(errors) == 1 and errors[0].startswith(expected), errors


def test_the_shipped_config_is_valid(schema, repo):
    assert _errors(schema, yaml.safe_load((repo / "config" / "config.yaml").read_text())) == []
