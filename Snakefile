# shadowcam workflow: shadow cameras from moving shadows.
# Run:    snakemake --profile profiles/local [--config datasets=[NAME]]
# Report: snakemake --report results/report.html
# Stages live in workflow/rules/*.smk; the configuration in config.smk, helpers in
# common.smk (capture plans, inputs), parts.smk (time parts, spans, strips), resources.smk (job sizes), targets.smk,
# lightfield_inputs.smk (light-field inputs and targets).
from snakemake.utils import min_version

min_version("9.0")


# config/config.yaml, read and validated against workflow/schemas/config.schema.yaml
include: "workflow/rules/config.smk"


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"
include: "workflow/rules/parts.smk"
include: "workflow/rules/resources.smk"
include: "workflow/rules/targets.smk"
include: "workflow/rules/lightfield_inputs.smk"
include: "workflow/rules/capture_inputs.smk"
include: "workflow/rules/render.smk"
include: "workflow/rules/decode.smk"
include: "workflow/rules/shadow_time.smk"
include: "workflow/rules/dual.smk"
include: "workflow/rules/viewpoints.smk"
include: "workflow/rules/array.smk"
include: "workflow/rules/lights.smk"
include: "workflow/rules/pushbroom.smk"
include: "workflow/rules/accuracy.smk"
include: "workflow/rules/report.smk"
include: "workflow/rules/evaluate.smk"
include: "workflow/rules/outdoor.smk"
include: "workflow/rules/methods.smk"
include: "workflow/rules/lightfield.smk"


localrules:
    all,


rule all:
    default_target: True
    input:
        get_final_targets,
