# Stage: several lights under the wire sweeps (datasets whose manifest has a top-level
# lights block, captured, or synthetic.lights, rendered): a rendered capture is written as
# a capture folder (frame files of the u and v sweeps, reference, capture.json,
# ground_truth.nc); each sweep's minima are assigned to the lights from the capture's
# files (one shadow-time map and one dual view per light), then scored against the
# per-light ground truth (accuracy.json) and drawn beside it (lights.png).


rule lights_render:
    input:
        "data_manifest/{ds}.yaml",
    output:
        capture="results/{ds}/lights/capture/capture.json",
        truth="results/{ds}/lights/capture/ground_truth.nc",
    log:
        "logs/{ds}/lights_render.log",
    benchmark:
        "benchmarks/{ds}/lights_render.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_light_set_mem_mb,
        runtime=30,
    shell:
        "shadowcam render-lights --manifest {input} --out results/{wildcards.ds}/lights/capture"
        " > {log} 2>&1"


rule light_views:
    input:
        capture_manifest("lights"),
    output:
        "results/{ds}/lights/light_views.nc",
    log:
        "logs/{ds}/light_views.log",
    benchmark:
        "benchmarks/{ds}/light_views.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_light_set_mem_mb,
        runtime=30,
    shell:
        "shadowcam light-views --manifest {input} --out {output} > {log} 2>&1"


rule light_accuracy:
    input:
        truth=capture_ground_truth("lights", "light_set"),
        views="results/{ds}/lights/light_views.nc",
    output:
        json="results/{ds}/lights/accuracy.json",
        png=report(
            "results/{ds}/lights/lights.png",
            caption="../report/light_set.rst",
            category="Several lights",
        ),
    log:
        "logs/{ds}/light_accuracy.log",
    benchmark:
        "benchmarks/{ds}/light_accuracy.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_light_set_mem_mb,
        runtime=15,
    shell:
        "shadowcam light-accuracy --ground-truth {input.truth} --views {input.views}"
        " --out-json {output.json} --out-png {output.png} > {log} 2>&1"


# On request (not part of `all`: it reruns every method; needs ground truth): speed against
# error of the timing methods of several minima, results/<ds>/lights/methods/speed_vs_error.png.
rule light_methods:
    input:
        manifest=capture_manifest("lights"),
        truth=capture_ground_truth("lights", "light_set"),
    output:
        dataset="results/{ds}/lights/methods/methods.nc",
        csv=report(
            "results/{ds}/lights/methods/methods.csv",
            caption="../report/methods.rst",
            category="Several lights",
            labels={"dataset": "{ds}", "table": "methods (CSV)"},
        ),
        figure=report(
            "results/{ds}/lights/methods/speed_vs_error.png",
            caption="../report/methods.rst",
            category="Several lights",
            labels={"dataset": "{ds}", "figure": "speed against error"},
        ),
    log:
        "logs/{ds}/light_methods.log",
    benchmark:
        "benchmarks/{ds}/light_methods.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_light_set_mem_mb,
        runtime=30,
    shell:
        "shadowcam light-methods --manifest {input.manifest} --dataset {wildcards.ds}"
        " --out {output.dataset} --csv {output.csv} --figure {output.figure} > {log} 2>&1"
