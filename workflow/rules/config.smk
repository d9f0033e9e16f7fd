# The workflow configuration: config/config.yaml (plus --configfile / --config), read,
# checked against workflow/schemas/config.schema.yaml and filled with its defaults when
# the workflow is parsed. Every problem stops `snakemake -n` before any job is planned,
# with one message naming the file or key and what to do, without a Python traceback:
#
# - a YAML syntax error in config/config.yaml names the line and column;
# - nested values given on the command line (`--config decode={chunk_frames: 32}`) reach
#   the workflow as strings; where the schema wants a number, boolean, null or list
#   they are read as YAML values, like the same text in a config file;
# - a schema violation is listed per key (`key shadow_time.method: ...`).
#
# Offers
# ------
# CONFIG_FILE, CONFIG_SCHEMA   paths of the config file and its schema
import sys
from pathlib import Path

import jsonschema
import yaml
from snakemake.exceptions import WorkflowError
from snakemake.utils import validate

CONFIG_FILE = "config/config.yaml"
CONFIG_SCHEMA = "workflow/schemas/config.schema.yaml"


def _check_config_file(path):
    """Stop with the line and column of a YAML syntax error in `path`."""
    try:
        yaml.safe_load(Path(path).read_text())
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(exc, "problem", None) or str(exc)
        sys.exit(
            f"error: config file {path} is not valid YAML{where}: {problem}; "
            f"fix the file (every key is described in {CONFIG_SCHEMA})"
        )


def _schema_types(schema):
    """JSON types a schema node allows (all of them if it does not say)."""
    types = schema.get("type")
    if types is None:
        return None
    return {types} if isinstance(types, str) else set(types)


def _takes_string(schema, value):
    """Whether `schema` (or one of its anyOf / oneOf alternatives) accepts string `value`."""
    for alternative in schema.get("anyOf") or schema.get("oneOf") or [schema]:
        types = _schema_types(alternative)
        if types is None or "string" in types:
            if "enum" not in alternative or value in alternative["enum"]:
                return True
    return False


def _from_command_line(value, schema):
    """`value` with command-line strings read as YAML where `schema` wants another type."""
    if isinstance(value, dict):
        properties = schema.get("properties", {})
        return {
            k: _from_command_line(v, properties.get(k, {})) for k, v in value.items()
        }
    if isinstance(value, list):
        items = schema.get("items", {})
        return [_from_command_line(v, items) for v in value]
    if isinstance(value, str) and not _takes_string(schema, value):
        try:
            parsed = yaml.safe_load(value)
        except yaml.YAMLError:
            return value
        return (
            _from_command_line(parsed, schema) if not isinstance(parsed, str) else value
        )
    return value


def _schema_messages(doc, schema):
    """One ``key A.B: message`` line per schema violation of `doc`."""
    validator = jsonschema.Draft202012Validator(schema)
    lines = []
    for error in sorted(
        validator.iter_errors(doc), key=lambda e: list(map(str, e.absolute_path))
    ):
        best = (
            jsonschema.exceptions.best_match(error.context) if error.context else error
        )
        where = ".".join(str(p) for p in best.absolute_path) or "(top level)"
        lines.append(f"  key {where}: {best.message}")
    return lines


def _check_config():
    """Read command-line values, validate and fill `config`; stop with the keys at fault."""
    schema_path = Path(workflow.basedir) / CONFIG_SCHEMA
    schema = yaml.safe_load(schema_path.read_text())
    for key, value in _from_command_line(dict(config), schema).items():
        config[key] = value
    lines = _schema_messages(config, schema)
    if not lines:
        try:
            validate(config, str(schema_path))  # fills in the defaults
        except WorkflowError as exc:
            lines = [f"  {exc}"]
    if lines:
        sys.exit(
            f"error: the configuration ({CONFIG_FILE} and --configfile / --config) does not "
            f"match {CONFIG_SCHEMA}:\n" + "\n".join(lines) + "\nFix these keys "
            f"(each is described in {CONFIG_FILE} and the schema)."
        )


_check_config_file(CONFIG_FILE)


configfile: CONFIG_FILE


_check_config()
