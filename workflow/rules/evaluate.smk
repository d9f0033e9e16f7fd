# Stage: the simulation study (paper II-C, Fig. 5), not per dataset. Renders small
# synthetic scenes in memory (one factor varied at a time from a baseline) and measures
# the dual view against the reciprocal render; config section `evaluate`.
# Target: snakemake --profile profiles/local evaluate


rule evaluate:
    output:
        study="results/evaluate/study.nc",
        figures=report(
            directory("results/evaluate/figures"),
            patterns=["study_{factor}.png"],
            caption="../report/evaluate.rst",
            category="simulation study",
            labels={"factor": "{factor}"},
        ),
    log:
        "logs/evaluate/evaluate.log",
    benchmark:
        "benchmarks/evaluate/evaluate.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=4096,
        runtime=60,
    params:
        study=get_evaluate_params,
    shell:
        "shadowcam evaluate --params '{params.study}' --out {output.study}"
        " --figures {output.figures} > {log} 2>&1"
